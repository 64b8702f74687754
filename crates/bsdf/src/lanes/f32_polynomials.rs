//! The single-precision transcendental functions of the f32 lane types, written once over
//! [`F32Lanes`] (the array lanes [`F32x8`](super::F32x8) and, on x86-64, the AVX2 register
//! lanes [`F32x8Avx2`](super::F32x8Avx2)), so that both compute the same bits. They are the
//! branch-free Cephes polynomials (Moshier, *Cephes Math Library*, `sinf`/`cosf`/`expf`/
//! `logf`), about 1 ulp on the ranges the models use, with the exponent and quadrant
//! arithmetic in the lanes' 32-bit integer form.

use super::{Bits32, Real};

/// An f32 lane type with its 32-bit integer view.
pub trait F32Lanes: Real {
    /// The integer lanes of the same width.
    type Bits: Bits32;
    /// The IEEE bits of each lane.
    fn to_bits(self) -> Self::Bits;
    /// The lanes with IEEE bits `b`.
    fn from_bits(b: Self::Bits) -> Self;
    /// Each lane's bits read as an `i32` and converted to the nearest f32.
    fn from_i32(b: Self::Bits) -> Self;
    /// The mask whose lanes are `b`'s (each lane all bits set or all clear).
    fn mask_from_bits(b: Self::Bits) -> Self::Mask;
}

/// The four [`Real`] methods every f32 lane type takes from this module (`sin_cos`, `atan2`,
/// `exp`, `ln`), written out once for the `impl Real` blocks of the array, SSE2 and AVX2
/// lanes.
macro_rules! polynomial_methods {
    () => {
        #[inline(always)]
        fn sin_cos(self) -> (Self, Self) {
            $crate::lanes::f32_polynomials::sin_cos(self)
        }
        #[inline(always)]
        fn atan2(self, x: Self) -> Self {
            $crate::lanes::f32_polynomials::atan2(self, x)
        }
        #[inline(always)]
        fn exp(self) -> Self {
            $crate::lanes::f32_polynomials::exp(self)
        }
        #[inline(always)]
        fn ln(self) -> Self {
            $crate::lanes::f32_polynomials::ln(self)
        }
    };
}
pub(crate) use polynomial_methods;

/// 1.5 · 2²³: adding it rounds an f32 below 2²² to the nearest integer, which its low
/// mantissa bits then hold (the branch-free rounding of vectorized libms).
const ROUND_MAGIC: f32 = 12_582_912.0;

/// (round(x), round(x) as i32 bits) for |x| < 2²².
#[inline(always)]
fn round_with_int<L: F32Lanes>(x: L) -> (L, L::Bits) {
    let shifted = x + L::splat(ROUND_MAGIC as f64);
    let r = shifted - L::splat(ROUND_MAGIC as f64);
    let n = shifted
        .to_bits()
        .wrapping_sub(L::Bits::splat(ROUND_MAGIC.to_bits()));
    (r, n)
}

/// Cephes `sinf`/`cosf`: the quadrant k = round(x·2/π), the remainder z = |x| − kπ/2 in
/// three parts, and the two minimax polynomials on [−π/4, π/4]. Accurate to about 1 ulp
/// for |x| < 2¹³ (the models pass angles in [0, 2π]).
#[inline(always)]
pub fn sin_cos<L: F32Lanes>(x: L) -> (L, L) {
    let ax = x.abs();
    let (k, ki) = round_with_int(ax * L::splat(std::f64::consts::FRAC_2_PI));
    let z = ((ax - k * L::splat(1.570_312_5)) - k * L::splat(4.837_512_969_970_703e-4))
        - k * L::splat(7.549_789_954_891_882e-8);
    let zz = z * z;
    let cos_p = ((L::splat(2.443_315_711_809_948e-5) * zz - L::splat(1.388_731_625_493_765e-3))
        * zz
        + L::splat(4.166_664_568_298_827e-2))
        * zz
        * zz
        - L::splat(0.5) * zz
        + L::one();
    let sin_p = ((L::splat(-1.951_529_589_1e-4) * zz + L::splat(8.332_160_873_6e-3)) * zz
        - L::splat(1.666_665_461_1e-1))
        * zz
        * z
        + z;
    // Odd quadrants swap the polynomials: all bits set where k is odd.
    let swap = L::mask_from_bits(L::Bits::splat(0).wrapping_sub(ki & L::Bits::splat(1)));
    let s = L::select(swap, cos_p, sin_p);
    let c = L::select(swap, sin_p, cos_p);
    // Sign bits: sin is negative in quadrants 2 and 3 (and odd in x), cos in 1 and 2.
    let sign = L::Bits::splat(0x8000_0000);
    let s_sign = (ki & L::Bits::splat(2)).shl(30) ^ (x.to_bits() & sign);
    let c_sign = (ki.wrapping_add(L::Bits::splat(1)) & L::Bits::splat(2)).shl(30);
    (
        L::from_bits(s.to_bits() ^ s_sign),
        L::from_bits(c.to_bits() ^ c_sign),
    )
}

/// atan2(y, x) from Cephes `atanf` (its polynomial on [−tan π/8, tan π/8], about 2e-7
/// relative) applied to r = min(|x|, |y|) / max(|x|, |y|) ∈ [0, 1], reduced above tan π/8 by
/// atan r = π/4 + atan((r − 1)/(r + 1)); then the octant (π/2 − a where |y| > |x|, π − a
/// where x has its sign bit set, as libm: atan2(±0, −0) = ±π) and the sign of y; within
/// 3e-7 absolute of the f64 function (tested). Unlike libm, atan2(±∞, ±∞) and a NaN x give
/// NaN and a NaN y gives ±0 (the renderer passes finite directions).
#[inline(always)]
pub fn atan2<L: F32Lanes>(y: L, x: L) -> L {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    let (ax, ay) = (x.abs(), y.abs());
    let (small, big) = (ax.min(ay), ax.max(ay));
    let r = L::select(big.gt(L::zero()), small / big, L::zero());
    let reduce = r.gt(L::splat(0.414_213_562_373_095_1));
    let t = L::select(reduce, (r - L::one()) / (r + L::one()), r);
    let z = t * t;
    let p = (((L::splat(8.053_744_495_38e-2) * z - L::splat(1.387_768_560_32e-1)) * z
        + L::splat(1.997_771_064_78e-1))
        * z
        - L::splat(3.333_294_915_39e-1))
        * z
        * t
        + t;
    let a = p + L::select(reduce, L::splat(FRAC_PI_4), L::zero());
    let a = L::select(ay.gt(ax), L::splat(FRAC_PI_2) - a, a);
    let sign = L::Bits::splat(0x8000_0000);
    let x_negative = L::mask_from_bits(L::Bits::splat(0).wrapping_sub(x.to_bits().shr(31)));
    let a = L::select(x_negative, L::splat(PI) - a, a);
    L::from_bits(a.to_bits() ^ (y.to_bits() & sign))
}

/// Cephes `expf`: e^x = 2ⁿ e^r with n = round(x/ln 2), r in [−ln2/2, ln2/2], and a
/// degree-6 polynomial; x is clamped to [−87.3, 88.37] (the normal f32 range).
#[inline(always)]
pub fn exp<L: F32Lanes>(x_in: L) -> L {
    let x = x_in.clamp(-87.3, 88.37);
    let (n, ni) = round_with_int(x * L::splat(std::f64::consts::LOG2_E));
    let r = x - n * L::splat(0.693_359_375) - n * L::splat(-2.121_944_4e-4);
    let mut p = L::splat(1.987_569_150_0e-4);
    for c in [
        1.398_199_950_7e-3,
        8.333_451_907_3e-3,
        4.166_579_589_4e-2,
        1.666_666_545_9e-1,
        5.000_000_120_1e-1,
    ] {
        p = p * r + L::splat(c);
    }
    let y = p * r * r + r + L::one();
    // 2ⁿ from its exponent bits (|n| ≤ 127 here; wrapping, as the lanes' integers are).
    let scale = L::from_bits(ni.wrapping_add(L::Bits::splat(127)).shl(23));
    let out = y * scale;
    // A NaN input stays NaN (the clamp above would have turned it into a number).
    L::select(x_in.eq(x_in), out, x_in)
}

/// Cephes `logf`: x = m·2ᵉ with m in [√½, √2), ln x = e ln 2 + ln m by a degree-8
/// polynomial. ln 0 = −∞, ln of a negative or NaN is NaN, ln ∞ = ∞; subnormal inputs are
/// not handled (the models take logarithms of numbers ≥ 1e-30).
#[inline(always)]
pub fn ln<L: F32Lanes>(x_in: L) -> L {
    let b = x_in.to_bits();
    let e = (b.shr(23) & L::Bits::splat(0xFF)).wrapping_sub(L::Bits::splat(126));
    let m = L::from_bits((b & L::Bits::splat(0x807F_FFFF)) | L::Bits::splat(0x3F00_0000));
    // m in [0.5, 1): fold below √½ into [√½, √2) by doubling.
    let small = m.lt(L::splat(std::f64::consts::FRAC_1_SQRT_2));
    let ef = L::from_i32(e) - L::select(small, L::one(), L::zero());
    let x = L::select(small, m + m, m) - L::one();
    let z = x * x;
    let mut y = L::splat(7.037_683_629_2e-2);
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
        y = y * x + L::splat(c);
    }
    let y = y * x * z + ef * L::splat(-2.121_944_4e-4) - L::splat(0.5) * z;
    let out = x + y + ef * L::splat(0.693_359_375);
    let inf = L::splat(f64::INFINITY);
    let out = L::select(x_in.eq(inf), inf, out);
    let out = L::select(x_in.eq(L::zero()), -inf, out);
    L::select(x_in.ge(L::zero()), out, L::splat(f64::NAN))
}
