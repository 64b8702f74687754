//! The mutation fuzzer behind `tests/fuzz_readers.rs`: deterministic (a fixed seed per
//! target, so a failure replays exactly), on stable Rust, with no dependency. A case is a
//! corpus file with a few mutations stacked: byte flips, interesting bytes, chunks deleted,
//! duplicated or swapped in from another corpus file, truncation, and — the ones that reach
//! past the syntax — a number replaced by an extreme one (0, −1, 2^32, 2^64, 1e308, NaN,
//! 1e−320 …).

// Each test binary uses what it needs.
#![allow(dead_code)]

/// SplitMix64: small, fast and bit-stable, enough to choose mutations.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in 0..n (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Numbers that break size arithmetic, ranges and finiteness, as text.
pub const EXTREME_NUMBERS: &[&str] = &[
    "0",
    "-1",
    "1e308",
    "-1e308",
    "1e-320",
    "nan",
    "inf",
    "-inf",
    "4294967296",
    "18446744073709551615",
    "100000000000000000000",
    "65536",
    "2147483647",
    "0.01",
    "1e9",
    "-0",
];

/// Bytes that end strings, open tables or change a number's sign.
const INTERESTING_BYTES: &[u8] = b"\0\xff\x7f\x80\"'[]{}<>=/$\\\n-.e9";

/// `input` with 1 to 4 mutations; `others` are the rest of the corpus (for splicing).
pub fn mutate(rng: &mut Rng, input: &[u8], others: &[Vec<u8>]) -> Vec<u8> {
    let mut v = input.to_vec();
    for _ in 0..1 + rng.below(4) {
        let n = v.len();
        match rng.below(9) {
            0 if n > 0 => {
                let i = rng.below(n);
                v[i] ^= 1 << rng.below(8);
            }
            1 if n > 0 => {
                let i = rng.below(n);
                v[i] = INTERESTING_BYTES[rng.below(INTERESTING_BYTES.len())];
            }
            2 if n > 0 => {
                let a = rng.below(n);
                let len = 1 + rng.below((n - a).min(64));
                v.drain(a..a + len);
            }
            3 if n > 0 => {
                let a = rng.below(n);
                let len = 1 + rng.below((n - a).min(256));
                let chunk = v[a..a + len].to_vec();
                let at = rng.below(n + 1);
                v.splice(at..at, chunk);
            }
            4 if !others.is_empty() => {
                let o = &others[rng.below(others.len())];
                if !o.is_empty() {
                    let a = rng.below(o.len());
                    let len = 1 + rng.below((o.len() - a).min(256));
                    let at = rng.below(n + 1);
                    v.splice(at..at, o[a..a + len].iter().copied());
                }
            }
            5 if n > 0 => v.truncate(rng.below(n)),
            // Number replacement is the most useful mutation for text formats: weighted.
            _ => replace_number(rng, &mut v),
        }
    }
    v
}

/// Replaces one run of ASCII digits (with its sign, point and exponent) by an extreme
/// number.
fn replace_number(rng: &mut Rng, v: &mut Vec<u8>) {
    let starts: Vec<usize> = (0..v.len())
        .filter(|&i| v[i].is_ascii_digit() && (i == 0 || !v[i - 1].is_ascii_alphanumeric()))
        .collect();
    if starts.is_empty() {
        return;
    }
    let a = starts[rng.below(starts.len())];
    let mut b = a;
    while b < v.len() && (v[b].is_ascii_digit() || matches!(v[b], b'.' | b'e' | b'E' | b'_')) {
        b += 1;
    }
    let a = if a > 0 && v[a - 1] == b'-' { a - 1 } else { a };
    let n = EXTREME_NUMBERS[rng.below(EXTREME_NUMBERS.len())];
    v.splice(a..b, n.bytes());
}

/// How many cases each target runs: `FACETTE_FUZZ_CASES`, or `default` (sized so that
/// the whole suite stays under a minute on two loaded cores).
pub fn cases(default: usize) -> usize {
    std::env::var("FACETTE_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// What a refusal message must name: the file, and for text formats the line too.
#[derive(Clone, Copy)]
pub enum Culprit<'a> {
    /// The file's name.
    File(&'a str),
    /// `name:LINE`, the file and the line of the error (text formats, where every error
    /// has a place).
    FileLine(&'a str),
    /// `name:LINE`, except for the listed errors about the whole file (an OBJ file with no
    /// triangle has no line to blame).
    FileLineOrWhole(&'a str, &'a [&'a str]),
}

impl Culprit<'_> {
    fn named_by(&self, message: &str) -> bool {
        match *self {
            Culprit::File(f) => message.contains(f),
            Culprit::FileLine(f) => message.match_indices(f).any(|(i, _)| {
                let rest = &message[i + f.len()..];
                rest.strip_prefix(':')
                    .is_some_and(|r| r.starts_with(|c: char| c.is_ascii_digit()))
            }),
            Culprit::FileLineOrWhole(f, whole) => {
                Culprit::FileLine(f).named_by(message)
                    || (message.contains(f) && whole.iter().any(|w| message.ends_with(w)))
            }
        }
    }
}

/// Runs `cases` mutated inputs through `target`, which returns `Err(message)` for a
/// refused input. A panic fails the test with the seed and case number that replay it
/// (the input is saved under the system temp directory); so does an error with an empty
/// message or a Rust Debug dump in it, one that does not name its `culprit`, or a case
/// slower than `max_seconds`.
pub fn run(
    name: &str,
    seed: u64,
    corpus: &[Vec<u8>],
    cases: usize,
    max_seconds: f64,
    culprit: Culprit,
    target: &dyn Fn(&[u8]) -> Result<(), String>,
) -> (usize, usize) {
    assert!(!corpus.is_empty(), "{name}: empty corpus");
    let mut rng = Rng::new(seed);
    let (mut accepted, mut refused) = (0, 0);
    // The seeds themselves first: the corpus must be valid.
    for (k, input) in corpus.iter().enumerate() {
        if let Err(e) = target(input) {
            panic!("{name}: corpus entry {k} is refused: {e}");
        }
    }
    for case in 0..cases {
        let base = &corpus[rng.below(corpus.len())];
        let input = mutate(&mut rng, base, corpus);
        let start = std::time::Instant::now();
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| target(&input)));
        let secs = start.elapsed().as_secs_f64();
        let keep = || {
            let p = std::env::temp_dir().join(format!("facette-fuzz-{name}-{seed}-{case}"));
            let _ = std::fs::write(&p, &input);
            p
        };
        match result {
            Err(_) => panic!(
                "{name}: case {case} (seed {seed}) panicked; input saved to {}",
                keep().display()
            ),
            Ok(Ok(())) => accepted += 1,
            Ok(Err(e)) => {
                refused += 1;
                let dump = ["Error {", "ParseError", "Couln't", "panicked"];
                if e.trim().is_empty() || dump.iter().any(|d| e.contains(d)) {
                    panic!(
                        "{name}: case {case} gave an unclear message `{e}`; input saved to {}",
                        keep().display()
                    );
                }
                if !culprit.named_by(&e) {
                    if std::env::var_os("FACETTE_FUZZ_SURVEY").is_some() {
                        println!("{name}: case {case} does not name its culprit: {e}");
                        continue;
                    }
                    panic!(
                        "{name}: case {case}: the message does not name its culprit (the file{}): `{e}`; input saved to {}",
                        if matches!(culprit, Culprit::File(_)) { "" } else { " and line" },
                        keep().display()
                    );
                }
            }
        }
        assert!(
            secs < max_seconds,
            "{name}: case {case} took {secs:.1} s; input saved to {}",
            keep().display()
        );
    }
    (accepted, refused)
}
