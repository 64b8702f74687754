//! Eight f64 lanes as a plain array (two 256-bit AVX registers per operation): the render
//! kernel's geometry — its rays, hit points and normals — eight paths at a time at the
//! precision of the scalar renderer. The shapes' ray tests, the camera and the spawning
//! rule are written once over [`Real`] and instantiated with `f64` for one ray and `F64x8`
//! for eight, so the two give the same bits (no fused multiply-add is ever formed: Rust
//! does not contract `a * b + c`, and the transcendental functions below are the scalar
//! libm ones lane by lane).

use super::array_lanes::{array_lanes, lanewise};
use super::real::{Mask, Real};
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Eight f64 lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct F64x8(pub [f64; 8]);

/// Eight lane booleans, all bits set or clear.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(64))]
pub struct M64x8(pub [u64; 8]);

array_lanes!(
    F64x8,
    M64x8,
    f64,
    u64,
    8,
    tiny = 1e-300,
    cells = f64_cells,
    {
        #[inline(always)]
        fn sin_cos(self) -> (Self, Self) {
            let sc = lanewise!(self.0, |a| crate::math::sin_cos::sin_cos(a));
            (F64x8(sc.map(|p| p.0)), F64x8(sc.map(|p| p.1)))
        }
        #[inline(always)]
        fn floor(self) -> Self {
            F64x8(lanewise!(self.0, |a| a.floor()))
        }
        #[inline(always)]
        fn atan2(self, x: Self) -> Self {
            F64x8(std::array::from_fn(|i| self.0[i].atan2(x.0[i])))
        }
        #[inline(always)]
        fn exp(self) -> Self {
            F64x8(lanewise!(self.0, |a| a.exp()))
        }
        #[inline(always)]
        fn ln(self) -> Self {
            F64x8(lanewise!(self.0, |a| a.ln()))
        }
    }
);

impl M64x8 {
    /// The mask of the set bits of `bits` (lane i set where bit i is).
    #[inline(always)]
    pub fn from_bits(bits: u32) -> M64x8 {
        M64x8(std::array::from_fn(|i| {
            0u64.wrapping_sub(((bits >> i) & 1) as u64)
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eight_lanes_compute_what_f64_computes_bit_for_bit() {
        let a = F64x8([0.3, -2.5, 1e-300, f64::INFINITY, 4.0, -0.0, 7.5, 1e10]);
        let b = F64x8([7.0, 0.1, 3.0, 2.0, 4.0, 1.0, -2.0, 3e-10]);
        type LaneOp = fn(F64x8, F64x8) -> F64x8;
        type ScalarOp = fn(f64, f64) -> f64;
        let ops: [(LaneOp, ScalarOp); 4] = [
            (|x, y| x + y, |x, y| x + y),
            (|x, y| x - y, |x, y| x - y),
            (|x, y| x * y, |x, y| x * y),
            (|x, y| x / y, |x, y| x / y),
        ];
        for (lanes, scalar) in ops {
            let r = lanes(a, b);
            for i in 0..8 {
                assert_eq!(r.0[i].to_bits(), scalar(a.0[i], b.0[i]).to_bits());
            }
        }
        let m = a.lt(b);
        assert_eq!(m.bits(), 0b0010_0111);
        assert_eq!(M64x8::from_bits(m.bits()), m);
        assert!(m.any() && !m.all() && (m | !m).all() && !(m & !m).any());
        assert_eq!(F64x8::select(m, a, b).0[3], 2.0);
        assert_eq!(b.sqrt().0[2], 3f64.sqrt());
        assert_eq!(F64x8::splat(0.5).sin_cos().0 .0[7], 0.5f64.sin());
        // is_finite: false exactly for ±∞ and NaN (f64::MAX and subnormals are finite).
        let v = F64x8([
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MAX,
            -f64::MAX,
            5e-324,
            -0.0,
            1.0,
        ]);
        assert_eq!(v.is_finite().bits(), 0b1111_1000);
    }
}
