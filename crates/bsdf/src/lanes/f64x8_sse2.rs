//! Eight f64 lanes in four SSE2 registers: [`F64x8`](super::F64x8)'s numbers (the same bits,
//! tested operation by operation) in a form LLVM compiles as written. The render kernel's
//! f64 instantiation — the test that finds the scalar integrator's image — uses it: over the
//! array lanes that instantiation alone had cost LLVM about 90 s of the render crate's test
//! build, its SLP vectorizer searching the kernel's large functions for the array loops to
//! fuse (docs/performance.md, "The test build").
//!
//! The arithmetic, comparisons and `select` are SSE2 instructions; `floor` is built from
//! them (SSE2 has no `roundpd`); the transcendental functions are the array lanes' scalar
//! ones lane by lane, so every lane computes what one `f64` computes.

// SSE2 intrinsics are safe to call from Rust 1.87 on (x86-64 enables SSE2 everywhere);
// under the crate's minimum Rust they still need `unsafe`. Each `unsafe` block below holds
// SSE2 intrinsics only (SAFETY: SSE2 is part of x86-64), unless its own comment says more.
#![allow(unused_unsafe)]

use super::{CellTable, Mask, Real};
use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Eight f64 lanes in four SSE registers (lanes 0–1, 2–3, 4–5, 6–7).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct F64x8Sse2(pub [__m128d; 4]);

/// Eight lane booleans (all bits set or clear per lane) in four SSE registers.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct M64x8Sse2(pub [__m128d; 4]);

/// `$t` made of `e` on each quarter, with each name bound to that quarter of its value.
macro_rules! quarters {
    ($t:ident, |$($x:ident = $v:ident),+| $e:expr) => {
        $t([0, 1, 2, 3].map(|q| {
            $(let $x = $v.0[q];)+
            unsafe { $e }
        }))
    };
}

impl F64x8Sse2 {
    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [f64; 8] {
        // SAFETY: both are 64 bytes of plain numbers.
        unsafe { std::mem::transmute::<[__m128d; 4], [f64; 8]>(self.0) }
    }
    /// The lanes of an array.
    #[inline(always)]
    pub fn from_array(a: [f64; 8]) -> Self {
        // SAFETY: both are 64 bytes of plain numbers.
        F64x8Sse2(unsafe { std::mem::transmute::<[f64; 8], [__m128d; 4]>(a) })
    }
    /// `f` lane by lane (the scalar fallback of the transcendental functions).
    #[inline(always)]
    fn each(self, f: impl Fn(f64) -> f64) -> Self {
        Self::from_array(self.to_array().map(f))
    }
}

macro_rules! float_op {
    ($tr:ident, $f:ident, $intrinsic:ident) => {
        impl $tr for F64x8Sse2 {
            type Output = F64x8Sse2;
            #[inline(always)]
            fn $f(self, o: F64x8Sse2) -> F64x8Sse2 {
                quarters!(F64x8Sse2, |x = self, y = o| $intrinsic(x, y))
            }
        }
    };
}
float_op!(Add, add, _mm_add_pd);
float_op!(Sub, sub, _mm_sub_pd);
float_op!(Mul, mul, _mm_mul_pd);
float_op!(Div, div, _mm_div_pd);

impl Neg for F64x8Sse2 {
    type Output = F64x8Sse2;
    #[inline(always)]
    fn neg(self) -> F64x8Sse2 {
        quarters!(F64x8Sse2, |x = self| _mm_xor_pd(x, _mm_set1_pd(-0.0)))
    }
}

macro_rules! mask_op {
    ($tr:ident, $f:ident, $intrinsic:ident) => {
        impl $tr for M64x8Sse2 {
            type Output = M64x8Sse2;
            #[inline(always)]
            fn $f(self, o: M64x8Sse2) -> M64x8Sse2 {
                quarters!(M64x8Sse2, |x = self, y = o| $intrinsic(x, y))
            }
        }
    };
}
mask_op!(BitAnd, bitand, _mm_and_pd);
mask_op!(BitOr, bitor, _mm_or_pd);

impl Not for M64x8Sse2 {
    type Output = M64x8Sse2;
    #[inline(always)]
    fn not(self) -> M64x8Sse2 {
        quarters!(M64x8Sse2, |x = self| _mm_xor_pd(
            x,
            _mm_castsi128_pd(_mm_set1_epi32(-1))
        ))
    }
}

impl Mask for M64x8Sse2 {
    #[inline(always)]
    fn splat(b: bool) -> Self {
        let v = unsafe { _mm_castsi128_pd(_mm_set1_epi32(-(b as i32))) };
        M64x8Sse2([v; 4])
    }
    #[inline(always)]
    fn any(self) -> bool {
        self.lane_bits() != 0
    }
    #[inline(always)]
    fn all(self) -> bool {
        self.lane_bits() == 0xFF
    }
    #[inline(always)]
    fn lane(self, i: usize) -> bool {
        (self.lane_bits() >> i) & 1 != 0
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> bool) -> Self {
        let mut bits = 0;
        for i in 0..8 {
            bits |= (f(i) as u32) << i;
        }
        Self::from_lane_bits(bits)
    }
    /// Four `movmskpd`.
    #[inline(always)]
    fn lane_bits(self) -> u32 {
        let q = self.0.map(|h| unsafe { _mm_movemask_pd(h) as u32 });
        q[0] | (q[1] << 2) | (q[2] << 4) | (q[3] << 6)
    }
    #[inline(always)]
    fn from_lane_bits(bits: u32) -> Self {
        M64x8Sse2([0, 2, 4, 6].map(|k| {
            let lane = |i: u32| 0i64.wrapping_sub(((bits >> (k + i)) & 1) as i64);
            unsafe { _mm_castsi128_pd(_mm_set_epi64x(lane(1), lane(0))) }
        }))
    }
    #[inline(always)]
    fn width() -> usize {
        8
    }
}

impl Real for F64x8Sse2 {
    type Mask = M64x8Sse2;
    const LANES: usize = 8;
    const TINY: f64 = 1e-300;
    const DIGITS: u32 = f64::MANTISSA_DIGITS;

    #[inline(always)]
    fn splat(v: f64) -> Self {
        F64x8Sse2([unsafe { _mm_set1_pd(v) }; 4])
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f64 {
        self.to_array()[i]
    }
    #[inline(always)]
    fn from_fn(f: impl FnMut(usize) -> f64) -> Self {
        Self::from_array(std::array::from_fn(f))
    }
    /// In place: a scalar store to the lane.
    #[inline(always)]
    fn set_lane(&mut self, i: usize, v: f64) {
        assert!(i < 8);
        // SAFETY: lane i < 8 of the four 16-byte registers, 64 contiguous bytes of f64.
        unsafe {
            (&mut self.0 as *mut [__m128d; 4] as *mut f64)
                .add(i)
                .write(v)
        }
    }
    #[inline(always)]
    fn permute(self, from: &[u8; 8]) -> Self {
        let a = self.to_array();
        Self::from_array(std::array::from_fn(|i| a[from[i] as usize & 7]))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        quarters!(F64x8Sse2, |x = self| _mm_sqrt_pd(x))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        quarters!(F64x8Sse2, |x = self| _mm_andnot_pd(_mm_set1_pd(-0.0), x))
    }
    /// `self < o ? self : o` (`minpd`: a NaN `self` yields `o`), as the array lanes.
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        quarters!(F64x8Sse2, |x = self, y = o| _mm_min_pd(x, y))
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        quarters!(F64x8Sse2, |x = self, y = o| _mm_max_pd(x, y))
    }
    #[inline(always)]
    fn lt(self, o: Self) -> M64x8Sse2 {
        quarters!(M64x8Sse2, |x = self, y = o| _mm_cmplt_pd(x, y))
    }
    #[inline(always)]
    fn le(self, o: Self) -> M64x8Sse2 {
        quarters!(M64x8Sse2, |x = self, y = o| _mm_cmple_pd(x, y))
    }
    #[inline(always)]
    fn gt(self, o: Self) -> M64x8Sse2 {
        quarters!(M64x8Sse2, |x = self, y = o| _mm_cmpgt_pd(x, y))
    }
    #[inline(always)]
    fn ge(self, o: Self) -> M64x8Sse2 {
        quarters!(M64x8Sse2, |x = self, y = o| _mm_cmpge_pd(x, y))
    }
    #[inline(always)]
    fn eq(self, o: Self) -> M64x8Sse2 {
        quarters!(M64x8Sse2, |x = self, y = o| _mm_cmpeq_pd(x, y))
    }
    /// `(m & a) | (!m & b)` (SSE2 has no `blendvpd`; the masks are whole lanes).
    #[inline(always)]
    fn select(m: M64x8Sse2, a: Self, b: Self) -> Self {
        quarters!(F64x8Sse2, |m = m, a = a, b = b| _mm_or_pd(
            _mm_and_pd(m, a),
            _mm_andnot_pd(m, b)
        ))
    }
    /// SSE2 has no `roundpd`: below 2⁵² in magnitude, |x| rounded to the nearest integer
    /// (adding and subtracting 2⁵²), stepped down where that came out above |x| (x ≥ 0) or
    /// up where it came out below (x < 0: ⌊x⌋ = −⌈|x|⌉), with x's sign bit (⌊−0⌋ = −0);
    /// from 2⁵² on (and for ±∞, NaN) x is an integer already.
    #[inline(always)]
    fn floor(self) -> Self {
        let two52 = Self::splat(4_503_599_627_370_496.0);
        let a = self.abs();
        let rounded = (a + two52) - two52;
        let negative = self.lt(Self::zero());
        let step_down = rounded.gt(a) & !negative;
        let step_up = rounded.lt(a) & negative;
        let magnitude =
            rounded - Self::masked(step_down, Self::one()) + Self::masked(step_up, Self::one());
        let sign = unsafe { _mm_set1_pd(-0.0) };
        let signed = quarters!(F64x8Sse2, |m = magnitude, x = self| _mm_or_pd(
            m,
            _mm_and_pd(x, sign)
        ));
        Self::select(a.lt(two52), signed, self)
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let sc = self.to_array().map(crate::math::sin_cos::sin_cos);
        (
            Self::from_array(sc.map(|p| p.0)),
            Self::from_array(sc.map(|p| p.1)),
        )
    }
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        let (y, x) = (self.to_array(), x.to_array());
        Self::from_array(std::array::from_fn(|i| y[i].atan2(x[i])))
    }
    #[inline(always)]
    fn exp(self) -> Self {
        self.each(f64::exp)
    }
    #[inline(always)]
    fn ln(self) -> Self {
        self.each(f64::ln)
    }
    /// x − x = 0 (NaN for ±∞ and NaN).
    #[inline(always)]
    fn is_finite(self) -> M64x8Sse2 {
        quarters!(M64x8Sse2, |x = self| _mm_cmpeq_pd(_mm_sub_pd(x, x), _mm_setzero_pd()))
    }
    /// One 32-byte read of the cell's four numbers per lane. The index is the truncated
    /// lane as the array lanes take it (`as i32`, then as unsigned): a negative lane
    /// indexes out of bounds (a panic, never a wrong cell).
    #[inline(always)]
    fn gather4(table: &CellTable, cell: Self) -> [Self; 4] {
        let cells = table.f64_cells();
        let index = cell.to_array().map(|c| c as i32 as u32 as usize);
        let rows = index.map(|i| cells[i]);
        std::array::from_fn(|k| Self::from_array(rows.map(|r| r[k])))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::register_lane_tests as check;
    use crate::lanes::F64x8;

    #[test]
    fn f64_sse2_lanes_compute_the_array_lanes_bits() {
        check::float_operations_compute_the_array_lanes_bits::<F64x8, F64x8Sse2>();
    }

    #[test]
    fn f64_sse2_gather_reads_each_lanes_cell() {
        check::gather_reads_each_lanes_cell::<F64x8, F64x8Sse2>(false);
    }
}
