//! Hash-driven randomization shared by the samplers: every random choice a sampler makes
//! (a scramble, a permutation, a jitter) is a hash of the seed, the pixel, the sample index
//! and the dimension, never a draw from a generator with state. That is what makes a
//! camera sample's numbers a pure function of its coordinates, so the parts of a split
//! render and the passes of a progressive one reproduce a single render exactly.
//!
//! - `hash_unit`: a 64-bit hash as a uniform number in [0, 1).
//! - `owen_scramble`: the hash-based nested uniform (Owen) scramble of Burley 2020.
//! - `permute`: a hash-keyed permutation of [0, n) (Kensler 2013).
//! - `pcg4d`: a counter-based hash of four 32-bit words (the independent sampler's values).
//!
//! The hashes the render kernel evaluates eight samples at a time are written once over
//! [`Bits32`] (`u32` for one sample, `U32x8` for eight).
//!
//! The 64-bit mixing itself is [`mix_seed`](facette_bsdf::math::rng::mix_seed) (the
//! SplitMix64 finalizer), which the rest of the renderer already uses to derive seeds.

use facette_bsdf::lanes::Bits32;

/// The largest `f64` below 1 (1 − 2⁻⁵³): values computed as `(k + u) / n` may round up to
/// 1.0 and are clamped to it.
pub(crate) const ONE_MINUS_EPSILON: f64 = 1.0 - f64::EPSILON / 2.0;

/// The top 53 bits of a hash as a uniform number in [0, 1) (never 1).
#[inline]
pub(crate) fn hash_unit(h: u64) -> f64 {
    (h >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Owen's nested uniform scramble of a 32-bit fixed-point value in [0, 1), keyed by `seed`:
/// each bit is flipped or not by a random function of all the bits above it, so two values
/// that share their leading k bits still share them after the scramble (the dyadic
/// intervals are permuted as whole blocks) — the property that keeps a (t, m, s)-net a net
/// while making the point set a random one whose estimates are unbiased.
///
/// Burley 2020, "Practical Hash-based Owen Scrambling" (JCGT 9(4)): a Laine–Karras style
/// hash — additions and `x ^= x·even`, whose every output bit depends only on the input
/// bits below it — applied to the bit-reversed value, then reversed back, so that each bit
/// depends only on the more significant bits. The multipliers are Burley's.
#[inline]
pub(crate) fn owen_scramble(v: u32, seed: u32) -> u32 {
    laine_karras(v.reverse_bits(), seed).reverse_bits()
}

/// The Laine–Karras style hash of [`owen_scramble`] on the bit-reversed value: each output
/// bit depends only on the input bits below it. `owen_scramble(v.reverse_bits(), s)` is
/// `laine_karras(v, s).reverse_bits()`, which the Sobol sampler uses to skip two
/// reversals for its first dimension (the radical inverse is itself a reversal).
#[inline]
pub(crate) fn laine_karras(x: u32, seed: u32) -> u32 {
    laine_karras_lanes(x, seed)
}

/// [`laine_karras`] over lanes.
#[inline(always)]
pub(crate) fn laine_karras_lanes<B: Bits32>(x: B, seed: B) -> B {
    let mul = |v: B, c: u32| v.wrapping_mul(B::splat(c));
    let mut x = x.wrapping_add(seed);
    x = x ^ mul(x, 0x6c50_b47c);
    x = x ^ mul(x, 0xb82f_1e52);
    x = x ^ mul(x, 0xc7af_e638);
    x = x ^ mul(x, 0x8d22_f6e6);
    x
}

/// A hash of four 32-bit words into four: Jarzynski & Olano 2020, "Hash Functions for GPU
/// Rendering" (JCGT 9(3)), `pcg4d` — one LCG step per word, two rounds of cross-word
/// multiply-adds around an xor-shift; among the fastest hashes of their survey with
/// full-quality output, and it needs only 32-bit multiplies, which AVX2 does eight at a
/// time. The samplers' chi-square tests check its marginals and neighbouring dimensions.
#[inline(always)]
pub(crate) fn pcg4d<B: Bits32>(v: [B; 4]) -> [B; 4] {
    // Loops and a function rather than `map` and a closure, so that everything inlines
    // into the renderer's AVX2 kernel (closures and `map` may be left out of line, compiled
    // for the baseline CPU).
    #[inline(always)]
    fn round<B: Bits32>(v: &mut [B; 4]) {
        v[0] = v[0].wrapping_add(v[1].wrapping_mul(v[3]));
        v[1] = v[1].wrapping_add(v[2].wrapping_mul(v[0]));
        v[2] = v[2].wrapping_add(v[0].wrapping_mul(v[1]));
        v[3] = v[3].wrapping_add(v[1].wrapping_mul(v[2]));
    }
    let mut v = v;
    for c in &mut v {
        *c = c
            .wrapping_mul(B::splat(1_664_525))
            .wrapping_add(B::splat(1_013_904_223));
    }
    round(&mut v);
    for c in &mut v {
        *c = *c ^ c.shr(16);
    }
    round(&mut v);
    v
}

/// Element `i` of a pseudo-random permutation of [0, n) chosen by `key`, in O(1) memory:
/// the permutation is never stored, so each sample finds its stratum on its own.
///
/// Kensler 2013, "Correlated Multi-Jittered Sampling" (Pixar Technical Memo 13-01), §3:
/// a hash that is a bijection on the w-bit integers, w the bit width of n − 1 (xor with
/// the key, multiplication by odd constants and xor-shifts, all restricted to the low w
/// bits), iterated ("cycle walking") until it lands in [0, n), then rotated by the key.
/// Requires `i < n` and `1 ≤ n ≤ 2³²`.
pub(crate) fn permute(i: u32, n: u64, key: u32) -> u32 {
    debug_assert!((1..=1 << 32).contains(&n) && (i as u64) < n);
    if n <= 1 {
        return 0;
    }
    let last = (n - 1) as u32;
    // All the bits up to the highest bit of n − 1.
    let w = u32::MAX >> last.leading_zeros();
    let p = key;
    let mut i = i;
    loop {
        // Every step maps the low w bits to themselves bijectively (xor, multiplication
        // by an odd number, and xor with a right shift of the masked value), so the
        // masked result is a permutation of [0, 2^w) and the walk returns to [0, n).
        i ^= p;
        i = i.wrapping_mul(0xe170_893d);
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | (p >> 27));
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^= i >> 5;
        if i <= last {
            break;
        }
    }
    ((i as u64 + p as u64) % n) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampler_hash_unit_is_in_range() {
        assert_eq!(hash_unit(0), 0.0);
        assert!(hash_unit(u64::MAX) < 1.0);
        assert_eq!(ONE_MINUS_EPSILON, f64::from_bits(1.0f64.to_bits() - 1));
    }

    #[test]
    fn sampler_kensler_permute_is_a_bijection() {
        for n in (1u64..=70).chain([100, 255, 256, 257, 1000, 4096, 5000]) {
            for key in [0u32, 1, 0xdead_beef, 0x1234_5678, u32::MAX] {
                let mut seen = vec![false; n as usize];
                for i in 0..n as u32 {
                    let j = permute(i, n, key) as usize;
                    assert!(j < n as usize, "n {n}: {i} -> {j}");
                    assert!(!seen[j], "n {n} key {key:#x}: {j} hit twice");
                    seen[j] = true;
                }
            }
        }
        // Different keys give different permutations.
        let a: Vec<u32> = (0..64).map(|i| permute(i, 64, 1)).collect();
        let b: Vec<u32> = (0..64).map(|i| permute(i, 64, 2)).collect();
        assert_ne!(a, b);
        // The largest supported n.
        assert!(permute(u32::MAX, 1 << 32, 7) as u64 <= u32::MAX as u64);
    }

    #[test]
    fn sampler_owen_scramble_is_nested() {
        // Values sharing their top k bits still share them after the scramble, and the
        // 2^k aligned intervals are permuted (a bijection on each prefix length).
        for seed in [0u32, 1, 0x9e37_79b9, 0xffff_ffff] {
            for k in [1u32, 2, 4, 8] {
                let mut seen = vec![false; 1 << k];
                for top in 0..1u32 << k {
                    let base = top << (32 - k);
                    let s0 = owen_scramble(base, seed) >> (32 - k);
                    for low in [1u32, 0x1234, (1 << (32 - k)) - 1] {
                        let s = owen_scramble(base | low, seed) >> (32 - k);
                        assert_eq!(s, s0, "seed {seed:#x} k {k}");
                    }
                    assert!(!seen[s0 as usize]);
                    seen[s0 as usize] = true;
                }
            }
        }
        // It is a bijection on 32-bit values and depends on the seed.
        let mut v: Vec<u32> = (0..1u32 << 16).map(|i| owen_scramble(i << 16, 5)).collect();
        v.sort_unstable();
        v.dedup();
        assert_eq!(v.len(), 1 << 16);
        assert_ne!(owen_scramble(0x8000_0000, 1), owen_scramble(0x8000_0000, 2));
    }
}
