//! The lane trait: the number type the microfacet core and the vectorized models are
//! written over once. `f64` is the lab's instantiation (validation, `eval`, `albedo`, `fit`,
//! Python), `f32` a scalar renderer lane, and [`F32x8`](super::F32x8) eight renderer paths
//! at a time. A choice between two values is written as both values and a
//! [`select`](Real::select) on a mask, so the same source serves one lane and eight; an
//! expensive branch is guarded by [`Mask::any`], which is a plain `if` for one lane.

use super::CellTable;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// A lane-wise boolean: `bool` for one lane, a bit mask for several.
pub trait Mask: Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self> {
    fn splat(b: bool) -> Self;
    /// Whether some lane is set.
    fn any(self) -> bool;
    /// Whether every lane is set.
    fn all(self) -> bool;
    /// Whether no lane is set.
    #[inline(always)]
    fn none(self) -> bool {
        !self.any()
    }
    fn lane(self, i: usize) -> bool;
    fn from_fn(f: impl FnMut(usize) -> bool) -> Self;
    /// One bit per lane, lane `i` in bit `i` (AVX's `movemask`).
    #[inline(always)]
    fn lane_bits(self) -> u32 {
        (0..Self::width()).fold(0, |b, i| b | ((self.lane(i) as u32) << i))
    }
    /// The mask with lane `i` set where bit `i` of `bits` is.
    #[inline(always)]
    fn from_lane_bits(bits: u32) -> Self {
        Self::from_fn(|i| bits & (1 << i) != 0)
    }
    /// Lanes per mask.
    fn width() -> usize;
}

impl Mask for bool {
    #[inline(always)]
    fn splat(b: bool) -> Self {
        b
    }
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
    #[inline(always)]
    fn all(self) -> bool {
        self
    }
    #[inline(always)]
    fn lane(self, _: usize) -> bool {
        self
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> bool) -> Self {
        f(0)
    }
    #[inline(always)]
    fn width() -> usize {
        1
    }
}

/// A real number per lane.
pub trait Real:
    Copy
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    type Mask: Mask;
    /// Lanes per value.
    const LANES: usize;
    /// The smallest value a guard against underflow may use: 1e-300 in f64, 1e-30 in f32.
    const TINY: f64;
    /// Significand bits of a lane (53 for f64, 24 for f32).
    const DIGITS: u32;

    fn splat(v: f64) -> Self;
    /// Lane `i` as f64.
    fn lane(self, i: usize) -> f64;
    fn from_fn(f: impl FnMut(usize) -> f64) -> Self;
    /// Sets lane `i` to `v` (rounded to the lane's precision).
    #[inline(always)]
    fn set_lane(&mut self, i: usize, v: f64) {
        let old = *self;
        *self = Self::from_fn(|j| if j == i { v } else { old.lane(j) });
    }

    /// Lane `i` takes lane `from[i]` of `self` (each index below `LANES`; the first
    /// `LANES` entries are read): the render kernel's refill moves camera rays into the
    /// free lanes of its paths with it.
    #[inline(always)]
    fn permute(self, from: &[u8; 8]) -> Self {
        Self::from_fn(|i| self.lane(from[i] as usize))
    }

    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    fn min(self, o: Self) -> Self;
    fn max(self, o: Self) -> Self;
    fn lt(self, o: Self) -> Self::Mask;
    fn le(self, o: Self) -> Self::Mask;
    fn gt(self, o: Self) -> Self::Mask;
    fn ge(self, o: Self) -> Self::Mask;
    fn eq(self, o: Self) -> Self::Mask;
    /// Lane-wise `if m { a } else { b }`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// The largest integer not above each lane.
    fn floor(self) -> Self;
    fn sin_cos(self) -> (Self, Self);
    /// The angle of the point (x, self) from the +x axis, in [−π, π] (`atan2(self, x)`).
    fn atan2(self, x: Self) -> Self;
    fn exp(self) -> Self;
    fn ln(self) -> Self;
    /// Whether each lane is neither infinite nor NaN.
    fn is_finite(self) -> Self::Mask;

    /// The four numbers of cell `cell` of `table` in each lane (`cell` holds a cell index,
    /// an integer below `table.len()`): the table's f64 cells for f64 lanes, its f32 cells
    /// for f32 lanes.
    fn gather4(table: &CellTable, cell: Self) -> [Self; 4];

    /// A scalar function applied lane by lane: the fallback for what does not vectorize
    /// (table lookups, the Beckmann visible-slope inversion).
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        Self::from_fn(|i| f(self.lane(i)))
    }
    #[inline(always)]
    fn zero() -> Self {
        Self::splat(0.0)
    }
    #[inline(always)]
    fn one() -> Self {
        Self::splat(1.0)
    }
    /// `a` where `m`, else zero.
    #[inline(always)]
    fn masked(m: Self::Mask, a: Self) -> Self {
        Self::select(m, a, Self::zero())
    }
    /// 1 with the sign of `self` (+1 for ±0).
    #[inline(always)]
    fn sign_or_one(self) -> Self {
        Self::select(self.lt(Self::zero()), -Self::one(), Self::one())
    }
    /// Clamped to [lo, hi].
    #[inline(always)]
    fn clamp(self, lo: f64, hi: f64) -> Self {
        self.max(Self::splat(lo)).min(Self::splat(hi))
    }
}

macro_rules! scalar_real {
    ($t:ty, $tiny:expr, $cells:ident, $sin_cos:path) => {
        impl Real for $t {
            type Mask = bool;
            const LANES: usize = 1;
            const TINY: f64 = $tiny;
            const DIGITS: u32 = <$t>::MANTISSA_DIGITS;
            #[inline(always)]
            fn splat(v: f64) -> Self {
                v as $t
            }
            #[inline(always)]
            fn lane(self, _: usize) -> f64 {
                self as f64
            }
            #[inline(always)]
            fn from_fn(mut f: impl FnMut(usize) -> f64) -> Self {
                f(0) as $t
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                <$t>::abs(self)
            }
            #[inline(always)]
            fn min(self, o: Self) -> Self {
                <$t>::min(self, o)
            }
            #[inline(always)]
            fn max(self, o: Self) -> Self {
                <$t>::max(self, o)
            }
            #[inline(always)]
            fn lt(self, o: Self) -> bool {
                self < o
            }
            #[inline(always)]
            fn le(self, o: Self) -> bool {
                self <= o
            }
            #[inline(always)]
            fn gt(self, o: Self) -> bool {
                self > o
            }
            #[inline(always)]
            fn ge(self, o: Self) -> bool {
                self >= o
            }
            #[inline(always)]
            fn eq(self, o: Self) -> bool {
                self == o
            }
            #[inline(always)]
            fn select(m: bool, a: Self, b: Self) -> Self {
                if m {
                    a
                } else {
                    b
                }
            }
            /// `floor` without the library call that baseline x86-64 (SSE2, no `roundsd`)
            /// compiles it to: truncation through an integer, one step down for negative
            /// non-integers. Bit for bit `floor`'s result: |x| ≥ 2^(digits − 1) is already
            /// integral (and ±∞, NaN pass through), and the sign of a zero is kept.
            #[inline(always)]
            fn floor(self) -> Self {
                const INTEGRAL: $t = (1u64 << (<$t>::MANTISSA_DIGITS - 1)) as $t;
                if self.abs() < INTEGRAL {
                    let t = self as i64 as $t;
                    if t > self {
                        t - 1.0
                    } else {
                        t.copysign(self)
                    }
                } else {
                    self
                }
            }
            #[inline(always)]
            fn sin_cos(self) -> (Self, Self) {
                $sin_cos(self)
            }
            #[inline(always)]
            fn atan2(self, x: Self) -> Self {
                <$t>::atan2(self, x)
            }
            #[inline(always)]
            fn exp(self) -> Self {
                <$t>::exp(self)
            }
            #[inline(always)]
            fn ln(self) -> Self {
                <$t>::ln(self)
            }
            #[inline(always)]
            fn is_finite(self) -> bool {
                <$t>::is_finite(self)
            }
            #[inline(always)]
            fn gather4(table: &CellTable, cell: Self) -> [Self; 4] {
                // Through i64: one truncating conversion where `as usize` from a float
                // is a dozen instructions of saturation on x86-64.
                table.$cells()[cell as i64 as usize]
            }
            /// The native clamp, which keeps a NaN a NaN (the strict finite guard then
            /// names the model that made it).
            #[inline(always)]
            fn clamp(self, lo: f64, hi: f64) -> Self {
                <$t>::clamp(self, lo as $t, hi as $t)
            }
        }
    };
}

scalar_real!(f64, 1e-300, f64_cells, crate::math::sin_cos::sin_cos);
scalar_real!(f32, 1e-30, f32_cells, f32::sin_cos);

#[cfg(test)]
mod tests {
    use super::Real;

    /// The scalar `floor` is the library's, bit for bit: signed zeros, halves, values next
    /// to integers, the integral range's edge, infinities and NaN.
    #[test]
    fn scalar_floor_is_the_library_floor() {
        let mut xs = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            2.5,
            -2.5,
            1e-300,
            -1e-300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MAX,
            f64::MIN,
        ];
        for k in [1u32, 10, 23, 24, 30, 51, 52, 53, 60, 63, 64] {
            let p = 2f64.powi(k as i32);
            for x in [p, -p] {
                xs.extend([x, x.next_up(), x.next_down()]);
            }
        }
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..10_000 {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let x = f64::from_bits(state);
            xs.extend([x, (state >> 11) as f64 * 2f64.powi(-40) - 4096.0]);
        }
        for &x in &xs {
            assert_eq!(Real::floor(x).to_bits(), x.floor().to_bits(), "f64 {x:e}");
            let y = x as f32;
            assert_eq!(Real::floor(y).to_bits(), y.floor().to_bits(), "f32 {y:e}");
        }
    }
}
