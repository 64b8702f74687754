//! Eight f32 lanes as a plain array whose every operation is a loop of eight: inlined into a
//! function compiled for AVX2 (`#[target_feature(enable = "avx2,fma")]`, chosen at run
//! time by the renderer) each loop becomes one 256-bit instruction, and into the baseline
//! x86-64 build two SSE instructions, so one portable binary carries both (no
//! `-C target-cpu`, no nightly `std::simd`). The transcendental functions are branch-free
//! Cephes polynomials (Moshier, *Cephes Math Library*, `sinf`/`cosf`/`expf`/`logf`),
//! about 1 ulp on the ranges the models use, so that they vectorize too.

use super::array_lanes::{array_lanes, lanewise};
use super::real::{Mask, Real};
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Eight f32 lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct F32x8(pub [f32; 8]);

/// Eight lane booleans, all bits set or clear (the layout of an AVX compare).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct M32x8(pub [u32; 8]);

/// Eight i32 lanes, for the exponent and quadrant arithmetic of the polynomials.
#[derive(Clone, Copy)]
#[repr(C, align(32))]
struct I32x8([i32; 8]);

/// 1.5 · 2²³: adding it rounds an f32 below 2²² to the nearest integer, which its low
/// mantissa bits then hold (the branch-free rounding of vectorized libms).
const ROUND_MAGIC: f32 = 12_582_912.0;

impl F32x8 {
    /// (round(x) as f32, round(x) as i32) for |x| < 2²².
    #[inline(always)]
    fn round_with_int(self) -> (F32x8, I32x8) {
        let shifted = self + F32x8::splat(ROUND_MAGIC as f64);
        let r = shifted - F32x8::splat(ROUND_MAGIC as f64);
        let n = lanewise!(shifted.bits(), |b| (b as i32)
            .wrapping_sub(ROUND_MAGIC.to_bits() as i32));
        (r, I32x8(n))
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
        /// Cephes `sinf`/`cosf`: the quadrant k = round(x·2/π), the remainder
        /// z = |x| − kπ/2 in three parts, and the two minimax polynomials on [−π/4, π/4].
        /// Accurate to about 1 ulp for |x| < 2¹³ (the models pass angles in [0, 2π]).
        #[inline(always)]
        fn sin_cos(self) -> (Self, Self) {
            let ax = self.abs();
            let (k, ki) = (ax * F32x8::splat(std::f64::consts::FRAC_2_PI)).round_with_int();
            let z = ((ax - k * F32x8::splat(1.570_312_5))
                - k * F32x8::splat(4.837_512_969_970_703e-4))
                - k * F32x8::splat(7.549_789_954_891_882e-8);
            let zz = z * z;
            let cos_p = ((F32x8::splat(2.443_315_711_809_948e-5) * zz
                - F32x8::splat(1.388_731_625_493_765e-3))
                * zz
                + F32x8::splat(4.166_664_568_298_827e-2))
                * zz
                * zz
                - F32x8::splat(0.5) * zz
                + F32x8::one();
            let sin_p =
                ((F32x8::splat(-1.951_529_589_1e-4) * zz + F32x8::splat(8.332_160_873_6e-3)) * zz
                    - F32x8::splat(1.666_665_461_1e-1))
                    * zz
                    * z
                    + z;
            let swap = M32x8(lanewise!(ki.0, |q| if q & 1 != 0 { !0u32 } else { 0 }));
            let s = Self::select(swap, cos_p, sin_p);
            let c = Self::select(swap, sin_p, cos_p);
            // Sign bits: sin is negative in quadrants 2 and 3 (and odd in x), cos in 1 and 2.
            let neg = self.bits();
            let mut sb = s.bits();
            let mut cb = c.bits();
            for i in 0..8 {
                let q = ki.0[i] as u32;
                sb[i] ^= ((q & 2) << 30) ^ (neg[i] & 0x8000_0000);
                cb[i] ^= (q.wrapping_add(1) & 2) << 30;
            }
            (Self::from_bits(sb), Self::from_bits(cb))
        }

        /// ⌊x⌋ lane by lane: one `vroundps` where compiled for AVX (SSE4.1 and up).
        #[inline(always)]
        fn floor(self) -> Self {
            F32x8(lanewise!(self.0, |a| a.floor()))
        }

        /// Cephes `expf`: e^x = 2ⁿ e^r with n = round(x/ln 2), r in [−ln2/2, ln2/2], and a
        /// degree-6 polynomial; x is clamped to [−87.3, 88.37] (the normal f32 range).
        #[inline(always)]
        fn exp(self) -> Self {
            let x = self.clamp(-87.3, 88.37);
            let (n, ni) = (x * F32x8::splat(std::f64::consts::LOG2_E)).round_with_int();
            let r = x - n * F32x8::splat(0.693_359_375) - n * F32x8::splat(-2.121_944_4e-4);
            let mut p = F32x8::splat(1.987_569_150_0e-4);
            for c in [
                1.398_199_950_7e-3,
                8.333_451_907_3e-3,
                4.166_579_589_4e-2,
                1.666_666_545_9e-1,
                5.000_000_120_1e-1,
            ] {
                p = p * r + F32x8::splat(c);
            }
            let y = p * r * r + r + F32x8::one();
            // Wrapping: the release profile checks overflow, and a checked add per lane is a
            // branch per lane that keeps the loop from vectorizing (|n| ≤ 127 here).
            let scale = Self::from_bits(lanewise!(ni.0, |e| (e.wrapping_add(127) as u32) << 23));
            let out = y * scale;
            // A NaN input stays NaN (the clamp above would have turned it into a number).
            Self::select(self.eq(self), out, self)
        }

        /// Cephes `logf`: x = m·2ᵉ with m in [√½, √2), ln x = e ln 2 + ln m by a degree-8
        /// polynomial. ln 0 = −∞, ln of a negative or NaN is NaN, ln ∞ = ∞; subnormal inputs
        /// are not handled (the models take logarithms of numbers ≥ 1e-30).
        #[inline(always)]
        fn ln(self) -> Self {
            let b = self.bits();
            let e = lanewise!(b, |v| (((v >> 23) & 0xFF) as i32).wrapping_sub(126));
            let m = Self::from_bits(lanewise!(b, |v| (v & 0x807F_FFFF) | 0x3F00_0000));
            // m in [0.5, 1): fold below √½ into [√½, √2) by doubling.
            let small = m.lt(F32x8::splat(std::f64::consts::FRAC_1_SQRT_2));
            let ef = F32x8(lanewise!(e, |v| v as f32))
                - Self::select(small, F32x8::one(), F32x8::zero());
            let x = Self::select(small, m + m, m) - F32x8::one();
            let z = x * x;
            let mut y = F32x8::splat(7.037_683_629_2e-2);
            for c in [
                -1.151_461_031_0e-1,
                1.167_699_874_0e-1,
                -1.242_014_084_6e-1,
                1.424_932_278_7e-1,
                -1.666_805_766_5e-1,
                2.000_071_476_5e-1,
                -2.499_999_399_3e-1,
                3.333_333_117_4e-1,
            ] {
                y = y * x + F32x8::splat(c);
            }
            let y = y * x * z + ef * F32x8::splat(-2.121_944_4e-4) - F32x8::splat(0.5) * z;
            let out = x + y + ef * F32x8::splat(0.693_359_375);
            let inf = F32x8::splat(f64::INFINITY);
            let out = Self::select(self.eq(inf), inf, out);
            let out = Self::select(self.eq(F32x8::zero()), -inf, out);
            Self::select(self.ge(F32x8::zero()), out, F32x8::splat(f64::NAN))
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
