//! The checks every register lane type passes (the AVX2 lanes, the f32 and f64 SSE2 lanes):
//! each of their operations gives the array lanes' bits ([`F32x8`], [`F64x8`], [`U32x8`], the
//! references written lane by lane), on edge values and pseudo-random ones. Written once over
//! the lane traits; each type's test module calls them.

use super::f32_polynomials::F32Lanes;
use super::{Bits32, CellTable, F32x8, F64x8, Mask, Real, U32x8};

/// Values with every kind of edge: signed zeros, subnormals, infinities, NaN, integers
/// and halves, the Cephes functions' ranges, the f32 and f64 floors' thresholds (2²³, 2⁵²),
/// and pseudo-random f32 bits and numbers.
fn values() -> Vec<f64> {
    let f32_edges = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.5,
        -0.5,
        1.5,
        -2.5,
        1e-40,
        -1e-40,
        1e-30,
        f32::MIN_POSITIVE,
        f32::MAX,
        f32::MIN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        3.0e7,
        -88.0,
        89.0,
        6.2,
        100.0,
        8_388_607.5,
        -8_388_607.5,
        8_388_608.0,
        -8_388_608.0,
        -8_388_609.0,
        2_147_483_648.0,
        -2_147_483_904.0,
    ];
    let mut v: Vec<f64> = f32_edges.iter().map(|&x: &f32| x as f64).collect();
    v.extend([
        4_503_599_627_370_495.5,
        -4_503_599_627_370_495.5,
        4_503_599_627_370_496.0,
        -4_503_599_627_370_497.0,
        1e300,
        -1e-310,
    ]);
    let mut state = 0x2545_f491_4f6c_dd1du64;
    for k in 0..4000 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let bits = (state >> 32) as u32;
        v.push(match k % 3 {
            0 => f32::from_bits(bits) as f64,
            1 => (bits >> 8) as f64 / 16_777_216.0 * 20.0 - 10.0,
            _ => (bits >> 8) as f64 / 16_777_216.0 * 200.0 - 100.0,
        });
    }
    v
}

fn chunks(v: &[f64]) -> Vec<[f64; 8]> {
    v.chunks(8)
        .map(|c| std::array::from_fn(|i| c[i % c.len()]))
        .collect()
}

/// The lanes of `x`, each rounded to `P`'s precision.
fn of<P: Real>(x: [f64; 8]) -> P {
    P::from_fn(|i| x[i])
}

/// The lanes as f64 (exact: an f32 lane's f64 has the f32's bits in it).
fn array<P: Real>(p: P) -> [f64; 8] {
    std::array::from_fn(|i| p.lane(i))
}

fn bits_of<B: Bits32>(x: [u32; 8]) -> B {
    B::from_fn(|i| x[i])
}

fn bits_array<B: Bits32>(b: B) -> [u32; 8] {
    std::array::from_fn(|i| b.lane(i))
}

fn same<A: Real, P: Real>(a: A, b: P, what: &str, x: [f64; 8]) {
    let (a, b) = (array(a), array(b));
    for i in 0..8 {
        // NaN payloads may differ between the scalar and vector forms of an operation.
        let ok = a[i].to_bits() == b[i].to_bits() || (a[i].is_nan() && b[i].is_nan());
        assert!(
            ok,
            "{what} of {:e}: array {:e}, register {:e}",
            x[i], a[i], b[i]
        );
    }
}

/// Every floating-point and mask operation of `P` gives the bits of the array lanes `A` of
/// the same precision ([`F32x8`] or [`F64x8`]), in pairs of values shifted against each
/// other.
pub(super) fn float_operations_compute_the_array_lanes_bits<A: Real, P: Real>() {
    let v = values();
    let xs = chunks(&v);
    let ys = chunks(&v[3..]);
    for (x, y) in xs.iter().zip(&ys) {
        let (a, b) = (of::<A>(*x), of::<A>(*y));
        let (p, q) = (of::<P>(*x), of::<P>(*y));
        same(a + b, p + q, "add", *x);
        same(a - b, p - q, "sub", *x);
        same(a * b, p * q, "mul", *x);
        same(a / b, p / q, "div", *x);
        same(-a, -p, "neg", *x);
        same(a.sqrt(), p.sqrt(), "sqrt", *x);
        same(a.abs(), p.abs(), "abs", *x);
        same(a.min(b), p.min(q), "min", *x);
        same(a.max(b), p.max(q), "max", *x);
        same(a.floor(), p.floor(), "floor", *x);
        same(a.exp(), p.exp(), "exp", *x);
        same(a.ln(), p.ln(), "ln", *x);
        let (s, c) = a.sin_cos();
        let (s2, c2) = p.sin_cos();
        same(s, s2, "sin", *x);
        same(c, c2, "cos", *x);
        same(a.atan2(b), p.atan2(q), "atan2", *x);
        same(a.clamp(-2.0, 3.0), p.clamp(-2.0, 3.0), "clamp", *x);
        for (m, n, what) in [
            (a.lt(b), p.lt(q), "lt"),
            (a.le(b), p.le(q), "le"),
            (a.gt(b), p.gt(q), "gt"),
            (a.ge(b), p.ge(q), "ge"),
            (a.eq(b), p.eq(q), "eq"),
            (a.is_finite(), p.is_finite(), "is_finite"),
        ] {
            assert_eq!(m.lane_bits(), n.lane_bits(), "{what} of {x:?}, {y:?}");
            same(A::select(m, a, b), P::select(n, p, q), what, *x);
            assert_eq!((!m).lane_bits(), (!n).lane_bits());
            let other = a.lt(A::zero());
            let other2 = p.lt(P::zero());
            assert_eq!((m & other).lane_bits(), (n & other2).lane_bits());
            assert_eq!((m | other).lane_bits(), (n | other2).lane_bits());
            assert_eq!(
                P::Mask::from_lane_bits(n.lane_bits()).lane_bits(),
                n.lane_bits()
            );
            for i in 0..8 {
                assert_eq!(m.lane(i), n.lane(i));
            }
        }
    }
    assert!(P::Mask::splat(true).all() && P::Mask::splat(false).none());
    assert_eq!(P::Mask::from_fn(|i| i % 3 == 0).lane_bits(), 0b0100_1001);
    let mut p = P::splat(1.0);
    p.set_lane(5, 7.0);
    assert_eq!(array(p), [1.0, 1.0, 1.0, 1.0, 1.0, 7.0, 1.0, 1.0]);
    assert_eq!(P::from_fn(|i| i as f64).lane(6), 6.0);
}

/// Every integer operation of `P::Bits` gives the array integers' bits, and its fractions
/// are theirs in `P`'s precision and in f64.
pub(super) fn integer_operations_compute_the_array_integers_bits<P: F32Lanes>() {
    let v: Vec<u32> = values().iter().map(|&x| (x as f32).to_bits()).collect();
    for (x, y) in v.chunks_exact(8).zip(v[5..].chunks_exact(8)) {
        let x: [u32; 8] = x.try_into().unwrap();
        let y: [u32; 8] = y.try_into().unwrap();
        let (a, b) = (U32x8(x), U32x8(y));
        let (p, q) = (bits_of::<P::Bits>(x), bits_of::<P::Bits>(y));
        let pairs = [
            (a.wrapping_add(b), p.wrapping_add(q)),
            (a.wrapping_sub(b), p.wrapping_sub(q)),
            (a.wrapping_mul(b), p.wrapping_mul(q)),
            (a & b, p & q),
            (a | b, p | q),
            (a ^ b, p ^ q),
            (a.shl(7), p.shl(7)),
            (a.shr(13), p.shr(13)),
            (a.shr_lanes(b), p.shr_lanes(q)),
            (a.reverse(), p.reverse()),
        ];
        for (k, (r, s)) in pairs.iter().enumerate() {
            assert_eq!(r.0, bits_array(*s), "operation {k} of {x:?}, {y:?}");
        }
        same(
            a.unit::<F32x8>(),
            p.unit::<P>(),
            "unit",
            x.map(|b| b as f64),
        );
        assert_eq!(a.unit::<F64x8>().0, p.unit::<F64x8>().0, "unit of {x:?}");
        let (f, g) = (<F32x8 as F32Lanes>::from_bits(a), P::from_bits(p));
        same(f, g, "from_bits", x.map(|b| f32::from_bits(b) as f64));
        same(
            F32x8::from_i32(a),
            P::from_i32(p),
            "from_i32",
            x.map(|b| b as f64),
        );
        assert_eq!(bits_array(g.to_bits()), x);
    }
}

/// The permutations and the bit-mask blend move the same lanes as the array lanes' (and as
/// the definition: lane i takes lane from[i]), with repeated and identity indices.
pub(super) fn permutes_and_blends_move_the_array_lanes<P: F32Lanes>() {
    let x: [u32; 8] = [11, 22, 33, 44, 55, 66, 77, 88];
    let y: [u32; 8] = [1, 2, 3, 4, 5, 6, 7, 8];
    let f = x.map(|v| v as f64 * 0.5);
    for from in [
        [0u8, 1, 2, 3, 4, 5, 6, 7],
        [7, 6, 5, 4, 3, 2, 1, 0],
        [3, 3, 0, 7, 1, 1, 6, 2],
    ] {
        let want: [u32; 8] = std::array::from_fn(|i| x[from[i] as usize]);
        assert_eq!(U32x8(x).permute(&from).0, want);
        assert_eq!(bits_array(bits_of::<P::Bits>(x).permute(&from)), want);
        let wantf: [f64; 8] = std::array::from_fn(|i| f[from[i] as usize]);
        assert_eq!(array(of::<F32x8>(f).permute(&from)), wantf);
        assert_eq!(array(of::<P>(f).permute(&from)), wantf);
    }
    for set in [0u8, 0xff, 0b1010_0110, 0b0000_0001, 0b1000_0000] {
        let want: [u32; 8] = std::array::from_fn(|i| if (set >> i) & 1 != 0 { x[i] } else { y[i] });
        assert_eq!(U32x8::blend_bits(set, U32x8(x), U32x8(y)).0, want);
        let p = P::Bits::blend_bits(set, bits_of(x), bits_of(y));
        assert_eq!(bits_array(p), want, "set {set:08b}");
    }
}

/// `B`'s 64-bit hash is `mix_seed`, bit for bit, on edge and random pairs.
pub(super) fn mix_seeds_is_mix_seed<B: Bits32>() {
    let mut rng = crate::math::rng::Pcg32::new(7, 3);
    let mut next = || ((rng.next_u32() as u64) << 32) | rng.next_u32() as u64;
    let edges = [
        0,
        1,
        u64::MAX,
        1 << 32,
        (1 << 32) - 1,
        1 << 63,
        0x9E37_79B9_7F4A_7C15,
    ];
    for round in 0..64 {
        let a: [u64; 8] = std::array::from_fn(|i| match round {
            0 => edges[i % edges.len()],
            _ => next(),
        });
        let b: [u64; 8] = std::array::from_fn(|i| match round {
            0 => edges[(i + 3) % edges.len()],
            _ => next(),
        });
        let want: [u64; 8] = std::array::from_fn(|i| crate::math::rng::mix_seed(a[i], b[i]));
        assert_eq!(B::mix_seeds(&a, &b), want, "{a:?} {b:?}");
        assert_eq!(U32x8::mix_seeds(&a, &b), want);
    }
}

/// The lanes above a value, as bits, agree with the array lanes and with the definition,
/// across the unsigned range (the sign bit included) and at both ends of `v`.
pub(super) fn lanes_above_a_value_are_the_definitions<B: Bits32>() {
    let lanes = [0, 1, 7, 8, 1 << 31, u32::MAX, u32::MAX - 1, 5];
    for v in [
        0,
        1,
        5,
        7,
        8,
        (1 << 31) - 1,
        1 << 31,
        u32::MAX - 1,
        u32::MAX,
    ] {
        let want = (0..8).fold(0u8, |s, i| s | ((lanes[i] > v) as u8) << i);
        assert_eq!(bits_of::<B>(lanes).above_bits(v), want, "{v}");
        assert_eq!(U32x8(lanes).above_bits(v), want, "{v}");
    }
    for (i, &l) in lanes.iter().enumerate() {
        assert_eq!(l.above_bits(4) != 0, l > 4, "{i}");
    }
}

/// The integer gather reads each lane's entry, the array lanes' and one `u32`'s, and an
/// index outside the table (by one, with the sign bit, in an empty table) panics before
/// anything is read.
pub(super) fn integer_gather_reads_each_lanes_entry<B: Bits32>() {
    let table: Vec<u32> = (0..300u32).map(|k| k.wrapping_mul(0x9e37_79b9)).collect();
    for idx in [[0, 299, 1, 298, 150, 7, 7, 0], [5, 6, 7, 8, 9, 10, 11, 12]] {
        let a = U32x8(idx).gather(&table);
        let p = bits_of::<B>(idx).gather(&table);
        assert_eq!(a.0, bits_array(p));
        for i in 0..8 {
            assert_eq!(a.0[i], table[idx[i] as usize]);
            assert_eq!(idx[i].gather(&table), a.0[i]);
        }
    }
    let seven = bits_of::<B>([0, 1, 2, 3, 4, 5, 6, 7]);
    assert!(seven.all_below(8) && !seven.all_below(7) && !seven.all_below(0));
    for (bad, len) in [(300, 300), (1 << 31, 300), (u32::MAX, 300), (0, 0)] {
        let idx = bits_of::<B>([0, 1, 2, bad, 4, 5, 6, 7]);
        let array = U32x8([0, 1, 2, bad, 4, 5, 6, 7]);
        assert!(!idx.all_below(len as u32) && !array.all_below(len as u32));
        let out =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| idx.gather(&table[..len])));
        assert!(
            out.is_err(),
            "index {bad} of a table of {len} must not be read"
        );
    }
}

/// The cell gather reads the same cells as the array lanes `A`' and transposes them; a
/// negative cell index panics (and, in the f32 register lanes, a NaN one: `nan_panics`).
pub(super) fn gather_reads_each_lanes_cell<A: Real, P: Real>(nan_panics: bool) {
    let table = CellTable::new(
        (0..50)
            .map(|k| std::array::from_fn(|j| (k * 4 + j) as f64 + 0.25))
            .collect(),
    );
    let cells = [0.0, 49.0, 3.7, 12.2, 7.0, 48.9, 0.5, 25.0];
    let a = A::gather4(&table, of::<A>(cells));
    let p = P::gather4(&table, of::<P>(cells));
    for k in 0..4 {
        assert_eq!(array(a[k]), array(p[k]), "number {k}");
    }
    assert_eq!(p[2].lane(1), (49 * 4 + 2) as f64 + 0.25);
    let mut bad = vec![-1.0];
    if nan_panics {
        bad.push(f64::NAN);
    }
    for cell in bad {
        let out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            P::gather4(&table, P::splat(cell));
        }));
        assert!(out.is_err(), "cell index {cell} must not read a cell");
    }
}
