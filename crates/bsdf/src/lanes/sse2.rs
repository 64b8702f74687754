//! Eight f32 lanes (and their masks and 32-bit integers) held in two SSE registers, every
//! operation SSE2 intrinsics on both halves: the render kernel's lanes in its portable
//! x86-64 build, the one that runs where the CPU has no AVX2.
//!
//! Why not the array lanes [`F32x8`](super::F32x8) there: the kernel's code is the same, but
//! over `[f32; 8]` every operation is eight scalar operations that LLVM's SLP vectorizer has
//! to find and fuse again, and on the kernel's large functions that search was most of the
//! render crate's compile time (an instantiation over array lanes took about 120–150 s of
//! LLVM passes, the AVX2 register one 8–13 s; docs/performance.md, "The test build"). Here,
//! as in [`F32x8Avx2`](super::F32x8Avx2), a value is registers from the start.
//!
//! SSE2 is part of every x86-64 CPU, so these types may be used anywhere on x86-64 (unlike
//! the AVX2 ones). They compute the array lanes' bits (and so the AVX2 lanes'): the same IEEE
//! operations, no fused multiply-add, the transcendental functions from one source
//! ([`f32_polynomials`](super::f32_polynomials)), and the operations SSE2 lacks (`floor`,
//! `blendv`, 32-bit `mullo`, unsigned compares, variable shifts) built from ones it has with
//! the same results; the tests compare them with the array lanes operation by operation.

// SSE2 intrinsics are safe to call from Rust 1.87 on (x86-64 enables SSE2 everywhere);
// under the crate's minimum Rust they still need `unsafe`. Each `unsafe` block below holds
// SSE2 intrinsics only (SAFETY: SSE2 is part of x86-64), unless its own comment says more.
#![allow(unused_unsafe)]

use super::f32_polynomials::{self, F32Lanes};
use super::{Bits32, CellTable, Mask, Real};
use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Sub};

/// Eight f32 lanes in two SSE registers (lanes 0–3, 4–7).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct F32x8Sse2(pub [__m128; 2]);

/// Eight lane booleans (all bits set or clear per lane) in two SSE registers, the form
/// `cmpps` makes.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct M32x8Sse2(pub [__m128; 2]);

/// Eight u32 lanes in two SSE registers.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct U32x8Sse2(pub [__m128i; 2]);

/// `$t` made of `e` on each half, with each name bound to that half of its value.
macro_rules! halves {
    ($t:ident, |$($x:ident = $v:ident),+| $e:expr) => {
        $t([0, 1].map(|h| {
            $(let $x = $v.0[h];)+
            unsafe { $e }
        }))
    };
}

impl F32x8Sse2 {
    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [f32; 8] {
        // SAFETY: both are 32 bytes of plain numbers.
        unsafe { std::mem::transmute::<[__m128; 2], [f32; 8]>(self.0) }
    }
    /// The lanes of an array.
    #[inline(always)]
    pub fn from_array(a: [f32; 8]) -> Self {
        // SAFETY: both are 32 bytes of plain numbers.
        F32x8Sse2(unsafe { std::mem::transmute::<[f32; 8], [__m128; 2]>(a) })
    }
}

impl U32x8Sse2 {
    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [u32; 8] {
        // SAFETY: both are 32 bytes of plain numbers.
        unsafe { std::mem::transmute::<[__m128i; 2], [u32; 8]>(self.0) }
    }
    /// The lanes of an array.
    #[inline(always)]
    pub fn from_array(a: [u32; 8]) -> Self {
        // SAFETY: both are 32 bytes of plain numbers.
        U32x8Sse2(unsafe { std::mem::transmute::<[u32; 8], [__m128i; 2]>(a) })
    }
    /// Each lane with its sign bit flipped, so that signed compares order them as unsigned.
    #[inline(always)]
    fn biased(self) -> [__m128i; 2] {
        let bias = unsafe { _mm_set1_epi32(i32::MIN) };
        self.0.map(|x| unsafe { _mm_xor_si128(x, bias) })
    }
}

/// All bits set in lane `i` where bit `i` of `bits` is 1 (lanes 0..8), zero elsewhere.
#[inline(always)]
fn lane_bit_mask(bits: u32) -> [__m128i; 2] {
    unsafe {
        let all = _mm_set1_epi32(bits as i32);
        [_mm_setr_epi32(1, 2, 4, 8), _mm_setr_epi32(16, 32, 64, 128)]
            .map(|lane_bit| _mm_cmpeq_epi32(_mm_and_si128(all, lane_bit), lane_bit))
    }
}

macro_rules! float_op {
    ($tr:ident, $f:ident, $intrinsic:ident) => {
        impl $tr for F32x8Sse2 {
            type Output = F32x8Sse2;
            #[inline(always)]
            fn $f(self, o: F32x8Sse2) -> F32x8Sse2 {
                halves!(F32x8Sse2, |x = self, y = o| $intrinsic(x, y))
            }
        }
    };
}
float_op!(Add, add, _mm_add_ps);
float_op!(Sub, sub, _mm_sub_ps);
float_op!(Mul, mul, _mm_mul_ps);
float_op!(Div, div, _mm_div_ps);

impl Neg for F32x8Sse2 {
    type Output = F32x8Sse2;
    #[inline(always)]
    fn neg(self) -> F32x8Sse2 {
        halves!(F32x8Sse2, |x = self| _mm_xor_ps(x, _mm_set1_ps(-0.0)))
    }
}

macro_rules! mask_op {
    ($tr:ident, $f:ident, $intrinsic:ident) => {
        impl $tr for M32x8Sse2 {
            type Output = M32x8Sse2;
            #[inline(always)]
            fn $f(self, o: M32x8Sse2) -> M32x8Sse2 {
                halves!(M32x8Sse2, |x = self, y = o| $intrinsic(x, y))
            }
        }
    };
}
mask_op!(BitAnd, bitand, _mm_and_ps);
mask_op!(BitOr, bitor, _mm_or_ps);

impl Not for M32x8Sse2 {
    type Output = M32x8Sse2;
    #[inline(always)]
    fn not(self) -> M32x8Sse2 {
        halves!(M32x8Sse2, |x = self| _mm_xor_ps(
            x,
            _mm_castsi128_ps(_mm_set1_epi32(-1))
        ))
    }
}

impl Mask for M32x8Sse2 {
    #[inline(always)]
    fn splat(b: bool) -> Self {
        let v = unsafe { _mm_castsi128_ps(_mm_set1_epi32(-(b as i32))) };
        M32x8Sse2([v, v])
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
    /// Two `movmskps`.
    #[inline(always)]
    fn lane_bits(self) -> u32 {
        let [lo, hi] = self.0.map(|h| unsafe { _mm_movemask_ps(h) as u32 });
        lo | (hi << 4)
    }
    #[inline(always)]
    fn from_lane_bits(bits: u32) -> Self {
        M32x8Sse2(lane_bit_mask(bits).map(|h| unsafe { _mm_castsi128_ps(h) }))
    }
    #[inline(always)]
    fn width() -> usize {
        8
    }
}

impl Real for F32x8Sse2 {
    type Mask = M32x8Sse2;
    const LANES: usize = 8;
    const TINY: f64 = 1e-30;
    const DIGITS: u32 = f32::MANTISSA_DIGITS;

    #[inline(always)]
    fn splat(v: f64) -> Self {
        let v = unsafe { _mm_set1_ps(v as f32) };
        F32x8Sse2([v, v])
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f64 {
        self.to_array()[i] as f64
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> f64) -> Self {
        let mut a = [0f32; 8];
        for (i, v) in a.iter_mut().enumerate() {
            *v = f(i) as f32;
        }
        Self::from_array(a)
    }
    /// In place: a scalar store to the lane.
    #[inline(always)]
    fn set_lane(&mut self, i: usize, v: f64) {
        assert!(i < 8);
        // SAFETY: lane i < 8 of the two 16-byte registers, 32 contiguous bytes of f32.
        unsafe {
            (&mut self.0 as *mut [__m128; 2] as *mut f32)
                .add(i)
                .write(v as f32)
        }
    }
    #[inline(always)]
    fn permute(self, from: &[u8; 8]) -> Self {
        let a = self.to_array();
        Self::from_array(std::array::from_fn(|i| a[from[i] as usize & 7]))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        halves!(F32x8Sse2, |x = self| _mm_sqrt_ps(x))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        halves!(F32x8Sse2, |x = self| _mm_and_ps(
            x,
            _mm_castsi128_ps(_mm_set1_epi32(i32::MAX))
        ))
    }
    /// `self < o ? self : o` (`minps`: a NaN `self` yields `o`), as the array lanes.
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        halves!(F32x8Sse2, |x = self, y = o| _mm_min_ps(x, y))
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        halves!(F32x8Sse2, |x = self, y = o| _mm_max_ps(x, y))
    }
    #[inline(always)]
    fn lt(self, o: Self) -> M32x8Sse2 {
        halves!(M32x8Sse2, |x = self, y = o| _mm_cmplt_ps(x, y))
    }
    #[inline(always)]
    fn le(self, o: Self) -> M32x8Sse2 {
        halves!(M32x8Sse2, |x = self, y = o| _mm_cmple_ps(x, y))
    }
    #[inline(always)]
    fn gt(self, o: Self) -> M32x8Sse2 {
        halves!(M32x8Sse2, |x = self, y = o| _mm_cmpgt_ps(x, y))
    }
    #[inline(always)]
    fn ge(self, o: Self) -> M32x8Sse2 {
        halves!(M32x8Sse2, |x = self, y = o| _mm_cmpge_ps(x, y))
    }
    #[inline(always)]
    fn eq(self, o: Self) -> M32x8Sse2 {
        halves!(M32x8Sse2, |x = self, y = o| _mm_cmpeq_ps(x, y))
    }
    /// `(m & a) | (!m & b)`: SSE2 has no `blendvps`; the masks are whole lanes, so this is
    /// the blend.
    #[inline(always)]
    fn select(m: M32x8Sse2, a: Self, b: Self) -> Self {
        halves!(F32x8Sse2, |m = m, a = a, b = b| _mm_or_ps(
            _mm_and_ps(m, a),
            _mm_andnot_ps(m, b)
        ))
    }
    /// SSE2 has no `roundps`: below 2²³ in magnitude, the truncation (`cvttps2dq` and back)
    /// less one where it came out above x, with x's sign bit (⌊−0⌋ = −0, and a negative x
    /// has a negative floor); from 2²³ on (and for ±∞, NaN) x is an integer already.
    #[inline(always)]
    fn floor(self) -> Self {
        let big = Self::splat(8_388_608.0);
        let sign = unsafe { _mm_set1_ps(-0.0) };
        let small = self.abs().lt(big);
        let truncated = halves!(F32x8Sse2, |x = self| _mm_cvtepi32_ps(_mm_cvttps_epi32(x)));
        let above = truncated.gt(self);
        let floored = truncated - Self::masked(above, Self::one());
        let signed = halves!(F32x8Sse2, |floored = floored, x = self| _mm_or_ps(
            floored,
            _mm_and_ps(x, sign)
        ));
        Self::select(small, signed, self)
    }
    f32_polynomials::polynomial_methods!();
    /// x − x = 0 (NaN for ±∞ and NaN): one subtraction and one compare a half.
    #[inline(always)]
    fn is_finite(self) -> M32x8Sse2 {
        halves!(M32x8Sse2, |x = self| _mm_cmpeq_ps(_mm_sub_ps(x, x), _mm_setzero_ps()))
    }
    /// One 16-byte load of the cell's four numbers per lane and two 4 × 4 transposes. The
    /// index is the truncated lane (`cvttps2dq`): a negative, huge or NaN lane indexes out
    /// of bounds (a panic, never a wrong cell), as in the AVX2 lanes.
    #[inline(always)]
    fn gather4(table: &CellTable, cell: Self) -> [Self; 4] {
        let cells = table.f32_cells();
        let index = halves!(U32x8Sse2, |cell = cell| _mm_cvttps_epi32(cell)).to_array();
        let row = |i: usize| unsafe { _mm_loadu_ps(cells[index[i] as usize].as_ptr()) };
        let transposed = |k: usize| unsafe {
            let (a0, a1, a2, a3) = (row(k), row(k + 1), row(k + 2), row(k + 3));
            let t0 = _mm_unpacklo_ps(a0, a1);
            let t1 = _mm_unpacklo_ps(a2, a3);
            let t2 = _mm_unpackhi_ps(a0, a1);
            let t3 = _mm_unpackhi_ps(a2, a3);
            [
                _mm_movelh_ps(t0, t1),
                _mm_movehl_ps(t1, t0),
                _mm_movelh_ps(t2, t3),
                _mm_movehl_ps(t3, t2),
            ]
        };
        let (lo, hi) = (transposed(0), transposed(4));
        std::array::from_fn(|k| F32x8Sse2([lo[k], hi[k]]))
    }
}

impl F32Lanes for F32x8Sse2 {
    type Bits = U32x8Sse2;
    #[inline(always)]
    fn to_bits(self) -> U32x8Sse2 {
        halves!(U32x8Sse2, |x = self| _mm_castps_si128(x))
    }
    #[inline(always)]
    fn from_bits(b: U32x8Sse2) -> Self {
        halves!(F32x8Sse2, |b = b| _mm_castsi128_ps(b))
    }
    #[inline(always)]
    fn from_i32(b: U32x8Sse2) -> Self {
        halves!(F32x8Sse2, |b = b| _mm_cvtepi32_ps(b))
    }
    #[inline(always)]
    fn mask_from_bits(b: U32x8Sse2) -> M32x8Sse2 {
        halves!(M32x8Sse2, |b = b| _mm_castsi128_ps(b))
    }
}

macro_rules! int_op {
    ($tr:ident, $f:ident, $intrinsic:ident) => {
        impl $tr for U32x8Sse2 {
            type Output = U32x8Sse2;
            #[inline(always)]
            fn $f(self, o: U32x8Sse2) -> U32x8Sse2 {
                halves!(U32x8Sse2, |x = self, y = o| $intrinsic(x, y))
            }
        }
    };
}
int_op!(BitAnd, bitand, _mm_and_si128);
int_op!(BitOr, bitor, _mm_or_si128);
int_op!(BitXor, bitxor, _mm_xor_si128);

impl Bits32 for U32x8Sse2 {
    const LANES: usize = 8;
    #[inline(always)]
    fn splat(v: u32) -> Self {
        let v = unsafe { _mm_set1_epi32(v as i32) };
        U32x8Sse2([v, v])
    }
    #[inline(always)]
    fn lane(self, i: usize) -> u32 {
        self.to_array()[i]
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> u32) -> Self {
        let mut a = [0u32; 8];
        for (i, v) in a.iter_mut().enumerate() {
            *v = f(i);
        }
        Self::from_array(a)
    }
    #[inline(always)]
    fn permute(self, from: &[u8; 8]) -> Self {
        let a = self.to_array();
        Self::from_array(std::array::from_fn(|i| a[from[i] as usize & 7]))
    }
    #[inline(always)]
    fn blend_bits(set: u8, a: Self, b: Self) -> Self {
        let m = U32x8Sse2(lane_bit_mask(set as u32));
        halves!(U32x8Sse2, |m = m, a = a, b = b| _mm_or_si128(
            _mm_and_si128(m, a),
            _mm_andnot_si128(m, b)
        ))
    }
    /// A signed compare of the sign-flipped lanes (SSE2 has no unsigned one) and two
    /// `movmskps`.
    #[inline(always)]
    fn above_bits(self, v: u32) -> u8 {
        let limit = unsafe { _mm_set1_epi32((v ^ 0x8000_0000) as i32) };
        let [lo, hi] = self
            .biased()
            .map(|h| unsafe { _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(h, limit))) });
        (lo | (hi << 4)) as u8
    }
    #[inline(always)]
    fn wrapping_add(self, o: Self) -> Self {
        halves!(U32x8Sse2, |x = self, y = o| _mm_add_epi32(x, y))
    }
    #[inline(always)]
    fn wrapping_sub(self, o: Self) -> Self {
        halves!(U32x8Sse2, |x = self, y = o| _mm_sub_epi32(x, y))
    }
    /// SSE2 has no 32-bit `mullo`: the even lanes' and the odd lanes' 64-bit products
    /// (`pmuludq`), whose low halves are the wrapping products, interleaved back.
    #[inline(always)]
    fn wrapping_mul(self, o: Self) -> Self {
        halves!(U32x8Sse2, |x = self, y = o| {
            let even = _mm_mul_epu32(x, y);
            let odd = _mm_mul_epu32(_mm_srli_epi64::<32>(x), _mm_srli_epi64::<32>(y));
            _mm_unpacklo_epi32(
                _mm_shuffle_epi32::<0b00_00_10_00>(even),
                _mm_shuffle_epi32::<0b00_00_10_00>(odd),
            )
        })
    }
    #[inline(always)]
    fn shl(self, n: u32) -> Self {
        halves!(U32x8Sse2, |x = self| _mm_sll_epi32(
            x,
            _mm_cvtsi32_si128(n as i32)
        ))
    }
    #[inline(always)]
    fn shr(self, n: u32) -> Self {
        halves!(U32x8Sse2, |x = self| _mm_srl_epi32(
            x,
            _mm_cvtsi32_si128(n as i32)
        ))
    }
    /// Lane by lane (SSE2 has no variable shift).
    #[inline(always)]
    fn shr_lanes(self, n: Self) -> Self {
        let (a, n) = (self.to_array(), n.to_array());
        Self::from_array(std::array::from_fn(|i| a[i] >> (n[i] & 31)))
    }
    /// Eight loads after one bounds test of the eight indices: an index outside the table
    /// panics before anything is read.
    #[inline(always)]
    fn gather(self, table: &[u32]) -> Self {
        let inside = self.all_below(table.len().min(u32::MAX as usize) as u32);
        assert!(
            inside,
            "a lane's index is outside the table of {} entries",
            table.len()
        );
        let index = self.to_array();
        Self::from_array(index.map(|i| table[i as usize]))
    }
    /// A signed compare of the sign-flipped lanes and a byte mask.
    #[inline(always)]
    fn all_below(self, n: u32) -> bool {
        let limit = unsafe { _mm_set1_epi32((n ^ 0x8000_0000) as i32) };
        let [lo, hi] = self
            .biased()
            .map(|h| unsafe { _mm_movemask_epi8(_mm_cmplt_epi32(h, limit)) });
        (lo & hi) == 0xFFFF
    }
    /// The top 24 bits (f32) or all 32 bits (f64) of each lane as a fraction in [0, 1): one
    /// shift and one conversion a half for f32 lanes (the shifted value is below 2²⁴, exact).
    #[inline(always)]
    fn unit<R: Real>(self) -> R {
        if R::DIGITS < 32 {
            let f = halves!(F32x8Sse2, |x = self| _mm_mul_ps(
                _mm_cvtepi32_ps(_mm_srli_epi32::<8>(x)),
                _mm_set1_ps(1.0 / 16_777_216.0)
            ))
            .to_array();
            R::from_fn(|i| f[i] as f64)
        } else {
            let a = self.to_array();
            R::from_fn(|i| a[i] as f64 * (1.0 / 4_294_967_296.0))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::register_lane_tests as check;

    #[test]
    fn sse2_lanes_compute_the_array_lanes_bits() {
        check::float_operations_compute_the_array_lanes_bits::<crate::lanes::F32x8, F32x8Sse2>();
    }

    #[test]
    fn sse2_integers_compute_the_array_integers_bits() {
        check::integer_operations_compute_the_array_integers_bits::<F32x8Sse2>();
    }

    #[test]
    fn sse2_permutes_and_blends_move_the_array_lanes() {
        check::permutes_and_blends_move_the_array_lanes::<F32x8Sse2>();
    }

    #[test]
    fn sse2_mix_seeds_is_mix_seed() {
        check::mix_seeds_is_mix_seed::<U32x8Sse2>();
    }

    #[test]
    fn sse2_lanes_above_a_value_are_the_definitions() {
        check::lanes_above_a_value_are_the_definitions::<U32x8Sse2>();
    }

    #[test]
    fn sse2_integer_gather_reads_each_lanes_entry() {
        check::integer_gather_reads_each_lanes_entry::<U32x8Sse2>();
    }

    #[test]
    fn sse2_gather_reads_each_lanes_cell() {
        check::gather_reads_each_lanes_cell::<crate::lanes::F32x8, F32x8Sse2>(true);
    }
}
