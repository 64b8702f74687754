//! Eight f32 lanes as a plain array whose every operation is a loop of eight: inlined into a
//! function compiled for AVX2 (`#[target_feature(enable = "avx2,fma")]`) each loop becomes
//! one 256-bit instruction where LLVM's vectorizer finds it, and in the baseline x86-64
//! build two SSE instructions, so one portable binary carries both (no `-C target-cpu`, no
//! nightly `std::simd`). The render kernel's AVX2 build uses the register lanes
//! [`F32x8Avx2`](super::F32x8Avx2) instead, which compute the same bits; this type is the
//! portable build's and the tests'. The transcendental functions are the shared
//! [`f32_polynomials`](super::f32_polynomials).

use super::array_lanes::{array_lanes, lanewise};
use super::f32_polynomials::{self, F32Lanes};
use super::real::{Mask, Real};
use super::U32x8;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Eight f32 lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct F32x8(pub [f32; 8]);

/// Eight lane booleans, all bits set or clear (the layout of an AVX compare).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct M32x8(pub [u32; 8]);

impl F32Lanes for F32x8 {
    type Bits = U32x8;
    #[inline(always)]
    fn to_bits(self) -> U32x8 {
        U32x8(self.bits())
    }
    #[inline(always)]
    fn from_bits(b: U32x8) -> Self {
        F32x8::from_bits(b.0)
    }
    #[inline(always)]
    fn from_i32(b: U32x8) -> Self {
        F32x8(lanewise!(b.0, |v| v as i32 as f32))
    }
    #[inline(always)]
    fn mask_from_bits(b: U32x8) -> M32x8 {
        M32x8(b.0)
    }
}

array_lanes!(
    F32x8,
    M32x8,
    f32,
    u32,
    8,
    tiny = 1e-30,
    cells = f32_cells,
    {
        f32_polynomials::polynomial_methods!();

        /// ⌊x⌋ lane by lane: one `vroundps` where compiled for AVX (SSE4.1 and up).
        #[inline(always)]
        fn floor(self) -> Self {
            F32x8(lanewise!(self.0, |a| a.floor()))
        }
    }
);

#[cfg(test)]
mod tests {
    use super::*;

    fn lanes(xs: &[f32]) -> Vec<F32x8> {
        xs.chunks(8)
            .map(|c| F32x8(std::array::from_fn(|i| c[i % c.len()])))
            .collect()
    }

    /// Largest error in ulps of f32 against the f64 function, over `xs`.
    fn max_ulps(xs: &[f32], f: impl Fn(F32x8) -> F32x8, g: impl Fn(f64) -> f64) -> f64 {
        let mut worst: f64 = 0.0;
        for v in lanes(xs) {
            let r = f(v);
            for i in 0..8 {
                let want = g(v.0[i] as f64);
                let got = r.0[i] as f64;
                let ulp = (want.abs() as f32).max(f32::MIN_POSITIVE);
                let ulp = (f32::from_bits(ulp.to_bits() + 1) - ulp) as f64;
                worst = worst.max((got - want).abs() / ulp);
            }
        }
        worst
    }

    fn grid(lo: f32, hi: f32, n: usize) -> Vec<f32> {
        (0..n)
            .map(|i| lo + (hi - lo) * i as f32 / (n - 1) as f32)
            .collect()
    }

    #[test]
    fn sin_cos_within_two_ulps_of_f64_on_the_models_range() {
        let xs = grid(-7.0, 7.0, 200_001);
        // Near zeros of sin/cos the absolute error matters, not the ulps of a tiny value.
        let abs_err = |f: fn(F32x8) -> F32x8, g: fn(f64) -> f64| {
            let mut worst: f64 = 0.0;
            for v in lanes(&xs) {
                let r = f(v);
                for i in 0..8 {
                    worst = worst.max((r.0[i] as f64 - g(v.0[i] as f64)).abs());
                }
            }
            worst
        };
        let s = abs_err(|v| v.sin_cos().0, f64::sin);
        let c = abs_err(|v| v.sin_cos().1, f64::cos);
        assert!(s < 1.2e-7 && c < 1.2e-7, "sin {s:e}, cos {c:e}");
        let xs = grid(0.05, 1.5, 10_001);
        assert!(max_ulps(&xs, |v| v.sin_cos().0, f64::sin) <= 2.0);
        assert!(max_ulps(&xs, |v| v.sin_cos().1, f64::cos) <= 2.0);
    }

    /// atan2 over the circle (every octant, both signs of zero on the axes) and across
    /// magnitudes: within 3e-7 absolute of the f64 function.
    #[test]
    fn atan2_within_3e_7_of_f64() {
        let mut pairs: Vec<(f32, f32)> = (0..20_000)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 20_000.0 - std::f64::consts::PI;
                let r = [1e-20, 1e-3, 1.0, 7.5, 1e20][k % 5];
                ((r * a.sin()) as f32, (r * a.cos()) as f32)
            })
            .collect();
        pairs.extend([
            (0.0, 1.0),
            (-0.0, 1.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (1.0, -0.0),
            (0.0, 0.0),
            (0.0, -0.0),
            (-0.0, -0.0),
            (1e-30, 1.0),
            (1.0, 1e-30),
        ]);
        let mut worst: f64 = 0.0;
        for c in pairs.chunks(8) {
            let y = F32x8(std::array::from_fn(|i| c[i % c.len()].0));
            let x = F32x8(std::array::from_fn(|i| c[i % c.len()].1));
            let a = y.atan2(x);
            for i in 0..8 {
                let want = (y.0[i] as f64).atan2(x.0[i] as f64);
                worst = worst.max((a.0[i] as f64 - want).abs());
            }
        }
        assert!(worst <= 3e-7, "{worst:e}");
    }

    #[test]
    fn exp_and_ln_within_two_ulps_of_f64() {
        let xs = grid(-80.0, 80.0, 100_001);
        let e = max_ulps(&xs, Real::exp, f64::exp);
        assert!(e <= 2.0, "exp: {e} ulps");
        let mut pos = grid(1e-6, 10.0, 100_001);
        pos.extend(grid(10.0, 1e30, 10_001));
        let l = max_ulps(&pos, Real::ln, f64::ln);
        assert!(l <= 2.0, "ln: {l} ulps");
        let special = F32x8([0.0, -1.0, f32::INFINITY, f32::NAN, 1.0, 0.5, 2.0, 1e-30]);
        let r = special.ln().0;
        assert_eq!(r[0], f32::NEG_INFINITY);
        assert!(r[1].is_nan() && r[3].is_nan());
        assert_eq!(r[2], f32::INFINITY);
        assert_eq!(r[4], 0.0);
        assert!(F32x8::splat(f64::NAN).exp().0[0].is_nan());
        assert!(F32x8::splat(-1000.0).exp().0[0] < 1e-37);
    }

    #[test]
    fn masks_select_and_compare_lane_by_lane() {
        let a = F32x8([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
        let b = F32x8::splat(3.5);
        let m = a.lt(b);
        assert_eq!(m.bits(), 0b0000_1111);
        assert!(m.any() && !m.all() && !(m & !m).any() && (m | !m).all());
        let s = F32x8::select(m, a, b);
        assert_eq!(s.0, [0.0, 1.0, 2.0, 3.0, 3.5, 3.5, 3.5, 3.5]);
        assert_eq!((-a).abs(), a);
        assert_eq!(a.min(b).0[5], 3.5);
        assert_eq!(a.max(b).0[5], 5.0);
        let inf = F32x8([
            1.0,
            f32::INFINITY,
            f32::NAN,
            -f32::INFINITY,
            0.0,
            1e38,
            -1e-38,
            2.0,
        ]);
        assert_eq!(inf.is_finite().bits(), 0b1111_0001);
    }
}
