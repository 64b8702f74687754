//! Four f64 lanes as a plain array (one 256-bit AVX register): the renderer's geometry in
//! lanes at the precision of its scalar code. The shapes' ray tests are written once over
//! [`Real`] and instantiated with `f64` for one ray and `F64x4` for four, so the two give
//! the same bits (no fused multiply-add is ever formed: Rust does not contract `a * b + c`).
//! The transcendental functions, which no geometry test uses, are the scalar libm ones
//! lane by lane.

use super::array_lanes::{array_lanes, lanewise};
use super::real::{Mask, Real};
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Four f64 lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct F64x4(pub [f64; 4]);

/// Four lane booleans, all bits set or clear.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct M64x4(pub [u64; 4]);

array_lanes!(
    F64x4,
    M64x4,
    f64,
    u64,
    4,
    tiny = 1e-300,
    cells = f64_cells,
    {
        #[inline(always)]
        fn sin_cos(self) -> (Self, Self) {
            let sc = lanewise!(self.0, |a| crate::math::sin_cos::sin_cos(a));
            (F64x4(sc.map(|p| p.0)), F64x4(sc.map(|p| p.1)))
        }
        #[inline(always)]
        fn floor(self) -> Self {
            F64x4(lanewise!(self.0, |a| a.floor()))
        }
        #[inline(always)]
        fn atan2(self, x: Self) -> Self {
            F64x4(std::array::from_fn(|i| self.0[i].atan2(x.0[i])))
        }
        #[inline(always)]
        fn exp(self) -> Self {
            F64x4(lanewise!(self.0, |a| a.exp()))
        }
        #[inline(always)]
        fn ln(self) -> Self {
            F64x4(lanewise!(self.0, |a| a.ln()))
        }
    }
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_compute_what_f64_computes_bit_for_bit() {
        let a = F64x4([0.3, -2.5, 1e-300, f64::INFINITY]);
        let b = F64x4([7.0, 0.1, 3.0, 2.0]);
        type LaneOp = fn(F64x4, F64x4) -> F64x4;
        type ScalarOp = fn(f64, f64) -> f64;
        let ops: [(LaneOp, ScalarOp); 4] = [
            (|x, y| x + y, |x, y| x + y),
            (|x, y| x - y, |x, y| x - y),
            (|x, y| x * y, |x, y| x * y),
            (|x, y| x / y, |x, y| x / y),
        ];
        for (lanes, scalar) in ops {
            let r = lanes(a, b);
            for i in 0..4 {
                assert_eq!(r.0[i].to_bits(), scalar(a.0[i], b.0[i]).to_bits());
            }
        }
        assert_eq!(b.sqrt().0[2], 3f64.sqrt());
        let m = a.lt(b);
        assert_eq!(m.bits(), 0b0111);
        assert!(m.any() && !m.all() && (m | !m).all() && !(m & !m).any());
        assert_eq!(F64x4::select(m, a, b).0, [0.3, -2.5, 1e-300, 2.0]);
        assert_eq!((-a).abs().0[1], 2.5);
        assert_eq!(a.is_finite().bits(), 0b0111);
        assert_eq!(F64x4::splat(0.5).sin_cos().1 .0[3], 0.5f64.cos());
        assert_eq!(b.ln().exp().0[0], 7f64.ln().exp());
    }
}
