//! Eight f32 lanes (and their masks and 32-bit integers) held in AVX registers, every
//! operation one AVX2 intrinsic: the render kernel's shading lanes in its AVX2 + FMA build.
//!
//! Why a second eight-lane type beside the array lanes [`F32x8`](super::F32x8): LLVM turns
//! the array lanes' loops into vector code only where its SLP vectorizer finds them, and
//! in the kernel's large functions it left a third of them as 4-wide and scalar code
//! (measured on `bench-sphere`: 705 256-bit, 172 128-bit and 250 scalar floating-point
//! instructions a sample). Here a value is an `__m256` from the start, so there is nothing
//! left to find. The two types compute the same bits: the same IEEE operations, no fused
//! multiply-add, and the transcendental functions from one source
//! ([`f32_polynomials`](super::f32_polynomials)); a test compares them operation by
//! operation.
//!
//! **Where these types may be used.** Their methods are `#[inline(always)]` wrappers of
//! AVX2 intrinsics, compiled into whatever function they are inlined in. They are only
//! correct inside code that runs after [`available`] returned true (the kernel's
//! `#[target_feature(enable = "avx2,fma")]` build, which the renderer enters after that
//! test); on a CPU without AVX2 any use is an illegal instruction. The trait methods
//! cannot be `unsafe` (they implement [`Real`], which the one-source models are written
//! over), so this rule is the caller's, like the renderer's feature test itself.

use super::f32_polynomials::{self, F32Lanes};
use super::{Bits32, CellTable, Mask, Real};
use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Sub};

/// Whether this CPU runs AVX2 and FMA: the condition for using this module's types (the
/// test is cached by the standard library).
#[inline(always)]
pub fn available() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
}

/// Eight f32 lanes in one AVX register.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct F32x8Avx2(pub __m256);

/// Eight lane booleans (all bits set or clear per lane) in one AVX register, the form
/// `vcmpps` makes and `vblendvps` reads.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct M32x8Avx2(pub __m256);

/// Eight u32 lanes in one AVX register.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct U32x8Avx2(pub __m256i);

// SAFETY of every `unsafe` block below: the intrinsics need AVX2 (and FMA for none of
// them); the module's rule is that these types are used only where the CPU has AVX2.

impl F32x8Avx2 {
    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [f32; 8] {
        // SAFETY: both are 32 bytes of plain numbers.
        unsafe { std::mem::transmute::<__m256, [f32; 8]>(self.0) }
    }
    /// The lanes of an array.
    #[inline(always)]
    pub fn from_array(a: [f32; 8]) -> Self {
        // SAFETY: both are 32 bytes of plain numbers.
        F32x8Avx2(unsafe { std::mem::transmute::<[f32; 8], __m256>(a) })
    }
    #[inline(always)]
    fn cmp<const OP: i32>(self, o: Self) -> M32x8Avx2 {
        M32x8Avx2(unsafe { _mm256_cmp_ps::<OP>(self.0, o.0) })
    }
}

impl U32x8Avx2 {
    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [u32; 8] {
        // SAFETY: both are 32 bytes of plain numbers.
        unsafe { std::mem::transmute::<__m256i, [u32; 8]>(self.0) }
    }
    /// The lanes of an array.
    #[inline(always)]
    pub fn from_array(a: [u32; 8]) -> Self {
        // SAFETY: both are 32 bytes of plain numbers.
        U32x8Avx2(unsafe { std::mem::transmute::<[u32; 8], __m256i>(a) })
    }
}

/// All bits set in lane `i` where bit `i` of `bits` is 1 (lanes 0..8), zero elsewhere.
#[inline(always)]
unsafe fn lane_bit_mask(bits: u32) -> __m256i {
    let lane_bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    _mm256_cmpeq_epi32(
        _mm256_and_si256(_mm256_set1_epi32(bits as i32), lane_bit),
        lane_bit,
    )
}

/// Eight lane indices as 32-bit lanes, for `vpermps`/`vpermd` (which use the low three
/// bits of each).
#[inline(always)]
unsafe fn lane_indices(from: &[u8; 8]) -> __m256i {
    // SAFETY (caller's AVX2): `from` is 8 readable bytes.
    _mm256_cvtepu8_epi32(_mm_loadl_epi64(from.as_ptr() as *const __m128i))
}

/// The wrapping 64-bit product of each u64 lane with `c`: the low halves' product plus the
/// cross products shifted up (the high halves' product leaves the 64 bits).
#[inline(always)]
unsafe fn mul_u64(x: __m256i, c: u64) -> __m256i {
    let lo = _mm256_set1_epi64x(c as i64);
    let hi = _mm256_set1_epi64x((c >> 32) as i64);
    let p0 = _mm256_mul_epu32(x, lo);
    let p1 = _mm256_mul_epu32(_mm256_srli_epi64::<32>(x), lo);
    let p2 = _mm256_mul_epu32(x, hi);
    _mm256_add_epi64(p0, _mm256_slli_epi64::<32>(_mm256_add_epi64(p1, p2)))
}

/// `z ^ (z >> s)` in each u64 lane.
#[inline(always)]
unsafe fn xor_shift_u64(z: __m256i, s: i32) -> __m256i {
    _mm256_xor_si256(z, _mm256_srl_epi64(z, _mm_cvtsi32_si128(s)))
}

macro_rules! float_op {
    ($tr:ident, $f:ident, $intrinsic:ident) => {
        impl $tr for F32x8Avx2 {
            type Output = F32x8Avx2;
            #[inline(always)]
            fn $f(self, o: F32x8Avx2) -> F32x8Avx2 {
                F32x8Avx2(unsafe { $intrinsic(self.0, o.0) })
            }
        }
    };
}
float_op!(Add, add, _mm256_add_ps);
float_op!(Sub, sub, _mm256_sub_ps);
float_op!(Mul, mul, _mm256_mul_ps);
float_op!(Div, div, _mm256_div_ps);

impl Neg for F32x8Avx2 {
    type Output = F32x8Avx2;
    #[inline(always)]
    fn neg(self) -> F32x8Avx2 {
        F32x8Avx2(unsafe { _mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)) })
    }
}

macro_rules! mask_op {
    ($tr:ident, $f:ident, $intrinsic:ident) => {
        impl $tr for M32x8Avx2 {
            type Output = M32x8Avx2;
            #[inline(always)]
            fn $f(self, o: M32x8Avx2) -> M32x8Avx2 {
                M32x8Avx2(unsafe { $intrinsic(self.0, o.0) })
            }
        }
    };
}
mask_op!(BitAnd, bitand, _mm256_and_ps);
mask_op!(BitOr, bitor, _mm256_or_ps);

impl Not for M32x8Avx2 {
    type Output = M32x8Avx2;
    #[inline(always)]
    fn not(self) -> M32x8Avx2 {
        M32x8Avx2(unsafe { _mm256_xor_ps(self.0, _mm256_castsi256_ps(_mm256_set1_epi32(-1))) })
    }
}

impl Mask for M32x8Avx2 {
    #[inline(always)]
    fn splat(b: bool) -> Self {
        M32x8Avx2(unsafe { _mm256_castsi256_ps(_mm256_set1_epi32(-(b as i32))) })
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
        let mut a = [0u32; 8];
        for (i, v) in a.iter_mut().enumerate() {
            *v = if f(i) { !0 } else { 0 };
        }
        M32x8Avx2(unsafe { _mm256_castsi256_ps(U32x8Avx2::from_array(a).0) })
    }
    #[inline(always)]
    fn lane_bits(self) -> u32 {
        unsafe { _mm256_movemask_ps(self.0) as u32 }
    }
    #[inline(always)]
    fn from_lane_bits(bits: u32) -> Self {
        M32x8Avx2(unsafe { _mm256_castsi256_ps(lane_bit_mask(bits)) })
    }
    #[inline(always)]
    fn width() -> usize {
        8
    }
}

impl Real for F32x8Avx2 {
    type Mask = M32x8Avx2;
    const LANES: usize = 8;
    const TINY: f64 = 1e-30;
    const DIGITS: u32 = f32::MANTISSA_DIGITS;

    #[inline(always)]
    fn splat(v: f64) -> Self {
        F32x8Avx2(unsafe { _mm256_set1_ps(v as f32) })
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
    /// In place: a scalar store to the lane (as the array lanes do; rebuilding the register
    /// from a copy stalls store forwarding where it is read back at once).
    #[inline(always)]
    fn set_lane(&mut self, i: usize, v: f64) {
        assert!(i < 8);
        // SAFETY: lane i < 8 of the 32-byte register value, which is 32 bytes of f32.
        unsafe {
            (&mut self.0 as *mut __m256 as *mut f32)
                .add(i)
                .write(v as f32)
        }
    }
    /// One `vpermps`.
    #[inline(always)]
    fn permute(self, from: &[u8; 8]) -> Self {
        F32x8Avx2(unsafe { _mm256_permutevar8x32_ps(self.0, lane_indices(from)) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        F32x8Avx2(unsafe { _mm256_sqrt_ps(self.0) })
    }
    #[inline(always)]
    fn abs(self) -> Self {
        F32x8Avx2(unsafe {
            _mm256_and_ps(self.0, _mm256_castsi256_ps(_mm256_set1_epi32(i32::MAX)))
        })
    }
    /// `self < o ? self : o` (`vminps`: a NaN `self` yields `o`), as the array lanes.
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        F32x8Avx2(unsafe { _mm256_min_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        F32x8Avx2(unsafe { _mm256_max_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn lt(self, o: Self) -> M32x8Avx2 {
        self.cmp::<_CMP_LT_OQ>(o)
    }
    #[inline(always)]
    fn le(self, o: Self) -> M32x8Avx2 {
        self.cmp::<_CMP_LE_OQ>(o)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> M32x8Avx2 {
        self.cmp::<_CMP_GT_OQ>(o)
    }
    #[inline(always)]
    fn ge(self, o: Self) -> M32x8Avx2 {
        self.cmp::<_CMP_GE_OQ>(o)
    }
    #[inline(always)]
    fn eq(self, o: Self) -> M32x8Avx2 {
        self.cmp::<_CMP_EQ_OQ>(o)
    }
    #[inline(always)]
    fn select(m: M32x8Avx2, a: Self, b: Self) -> Self {
        F32x8Avx2(unsafe { _mm256_blendv_ps(b.0, a.0, m.0) })
    }
    #[inline(always)]
    fn floor(self) -> Self {
        F32x8Avx2(unsafe { _mm256_floor_ps(self.0) })
    }
    f32_polynomials::polynomial_methods!();
    /// x − x = 0 (NaN for ±∞ and NaN): one subtraction and one compare.
    #[inline(always)]
    fn is_finite(self) -> M32x8Avx2 {
        let difference = F32x8Avx2(unsafe { _mm256_sub_ps(self.0, self.0) });
        difference.eq(Self::zero())
    }
    /// One 16-byte load of the cell's four numbers per lane and a transpose of the eight
    /// loads into four registers. The index is the truncated lane (`vcvttps2dq`): a
    /// negative, huge or NaN lane indexes out of bounds (a panic, never a wrong cell).
    #[inline(always)]
    fn gather4(table: &CellTable, cell: Self) -> [Self; 4] {
        let cells = table.f32_cells();
        let index = U32x8Avx2(unsafe { _mm256_cvttps_epi32(cell.0) }).to_array();
        let row = |i: usize| unsafe { _mm_loadu_ps(cells[index[i] as usize].as_ptr()) };
        unsafe {
            // a_k holds cell k in its low half and cell k + 4 in its high half; the 4 × 4
            // transposes of the two halves then give the four numbers' lanes.
            let a0 = _mm256_set_m128(row(4), row(0));
            let a1 = _mm256_set_m128(row(5), row(1));
            let a2 = _mm256_set_m128(row(6), row(2));
            let a3 = _mm256_set_m128(row(7), row(3));
            let t0 = _mm256_unpacklo_ps(a0, a1);
            let t1 = _mm256_unpacklo_ps(a2, a3);
            let t2 = _mm256_unpackhi_ps(a0, a1);
            let t3 = _mm256_unpackhi_ps(a2, a3);
            [
                F32x8Avx2(_mm256_shuffle_ps::<0x44>(t0, t1)),
                F32x8Avx2(_mm256_shuffle_ps::<0xEE>(t0, t1)),
                F32x8Avx2(_mm256_shuffle_ps::<0x44>(t2, t3)),
                F32x8Avx2(_mm256_shuffle_ps::<0xEE>(t2, t3)),
            ]
        }
    }
}

impl F32Lanes for F32x8Avx2 {
    type Bits = U32x8Avx2;
    #[inline(always)]
    fn to_bits(self) -> U32x8Avx2 {
        U32x8Avx2(unsafe { _mm256_castps_si256(self.0) })
    }
    #[inline(always)]
    fn from_bits(b: U32x8Avx2) -> Self {
        F32x8Avx2(unsafe { _mm256_castsi256_ps(b.0) })
    }
    #[inline(always)]
    fn from_i32(b: U32x8Avx2) -> Self {
        F32x8Avx2(unsafe { _mm256_cvtepi32_ps(b.0) })
    }
    #[inline(always)]
    fn mask_from_bits(b: U32x8Avx2) -> M32x8Avx2 {
        M32x8Avx2(unsafe { _mm256_castsi256_ps(b.0) })
    }
}

macro_rules! int_op {
    ($tr:ident, $f:ident, $intrinsic:ident) => {
        impl $tr for U32x8Avx2 {
            type Output = U32x8Avx2;
            #[inline(always)]
            fn $f(self, o: U32x8Avx2) -> U32x8Avx2 {
                U32x8Avx2(unsafe { $intrinsic(self.0, o.0) })
            }
        }
    };
}
int_op!(BitAnd, bitand, _mm256_and_si256);
int_op!(BitOr, bitor, _mm256_or_si256);
int_op!(BitXor, bitxor, _mm256_xor_si256);

impl Bits32 for U32x8Avx2 {
    const LANES: usize = 8;
    #[inline(always)]
    fn splat(v: u32) -> Self {
        U32x8Avx2(unsafe { _mm256_set1_epi32(v as i32) })
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
    /// One `vpermd`.
    #[inline(always)]
    fn permute(self, from: &[u8; 8]) -> Self {
        U32x8Avx2(unsafe { _mm256_permutevar8x32_epi32(self.0, lane_indices(from)) })
    }
    /// SplitMix64's finalizer four lanes to a register, its 64-bit products from three
    /// `vpmuludq` each (AVX2 has no 64-bit `mullo`).
    #[inline(always)]
    fn mix_seeds(a: &[u64; 8], b: &[u64; 8]) -> [u64; 8] {
        let mut out = [0u64; 8];
        for h in 0..2 {
            // SAFETY: 4 u64 = 32 bytes read from and written to each array at 4h.
            unsafe {
                let va = _mm256_loadu_si256(a[4 * h..].as_ptr() as *const __m256i);
                let vb = _mm256_loadu_si256(b[4 * h..].as_ptr() as *const __m256i);
                let z = _mm256_xor_si256(va, mul_u64(vb, 0x9E37_79B9_7F4A_7C15));
                let z = mul_u64(xor_shift_u64(z, 30), 0xBF58_476D_1CE4_E5B9);
                let z = mul_u64(xor_shift_u64(z, 27), 0x94D0_49BB_1331_11EB);
                let z = xor_shift_u64(z, 31);
                _mm256_storeu_si256(out[4 * h..].as_mut_ptr() as *mut __m256i, z);
            }
        }
        out
    }
    #[inline(always)]
    fn blend_bits(set: u8, a: Self, b: Self) -> Self {
        U32x8Avx2(unsafe { _mm256_blendv_epi8(b.0, a.0, lane_bit_mask(set as u32)) })
    }
    /// One unsigned compare (`vpmaxud`, `vpcmpeqd`) and one `vmovmskps`.
    #[inline(always)]
    fn above_bits(self, v: u32) -> u8 {
        if v == u32::MAX {
            return 0;
        }
        // SAFETY: AVX2 (module rule). self > v ⟺ max(self, v + 1) = self.
        unsafe {
            let next = _mm256_set1_epi32(v.wrapping_add(1) as i32);
            let above = _mm256_cmpeq_epi32(_mm256_max_epu32(self.0, next), self.0);
            _mm256_movemask_ps(_mm256_castsi256_ps(above)) as u8
        }
    }
    #[inline(always)]
    fn wrapping_add(self, o: Self) -> Self {
        U32x8Avx2(unsafe { _mm256_add_epi32(self.0, o.0) })
    }
    #[inline(always)]
    fn wrapping_sub(self, o: Self) -> Self {
        U32x8Avx2(unsafe { _mm256_sub_epi32(self.0, o.0) })
    }
    #[inline(always)]
    fn wrapping_mul(self, o: Self) -> Self {
        U32x8Avx2(unsafe { _mm256_mullo_epi32(self.0, o.0) })
    }
    #[inline(always)]
    fn shl(self, n: u32) -> Self {
        U32x8Avx2(unsafe { _mm256_sll_epi32(self.0, _mm_cvtsi32_si128(n as i32)) })
    }
    #[inline(always)]
    fn shr(self, n: u32) -> Self {
        U32x8Avx2(unsafe { _mm256_srl_epi32(self.0, _mm_cvtsi32_si128(n as i32)) })
    }
    #[inline(always)]
    fn shr_lanes(self, n: Self) -> Self {
        U32x8Avx2(unsafe {
            _mm256_srlv_epi32(self.0, _mm256_and_si256(n.0, _mm256_set1_epi32(31)))
        })
    }
    /// One `vpgatherdd` after one bounds test of the eight indices (unsigned minimum and
    /// compare): an index outside the table panics before anything is read, and a table
    /// beyond 2³¹ entries is addressed only below 2³¹ (the gather's offsets are signed).
    #[inline(always)]
    fn gather(self, table: &[u32]) -> Self {
        let inside = self.all_below(table.len().min(1 << 31) as u32);
        assert!(
            inside,
            "a lane's index is outside the table of {} entries",
            table.len()
        );
        // SAFETY: every index is below `table.len()` (tested above).
        U32x8Avx2(unsafe { _mm256_i32gather_epi32::<4>(table.as_ptr() as *const i32, self.0) })
    }
    /// An unsigned minimum with `n − 1`, a compare and a byte mask.
    #[inline(always)]
    fn all_below(self, n: u32) -> bool {
        n > 0
            && unsafe {
                let last = _mm256_set1_epi32((n - 1) as i32);
                let kept = _mm256_cmpeq_epi32(_mm256_min_epu32(self.0, last), self.0);
                _mm256_movemask_epi8(kept) == -1
            }
    }
    /// The top 24 bits (f32) or all 32 bits (f64) of each lane as a fraction in [0, 1): one
    /// shift and one conversion for f32 lanes (the shifted value is below 2²⁴, exact).
    #[inline(always)]
    fn unit<R: Real>(self) -> R {
        if R::DIGITS < 32 {
            let f = unsafe {
                _mm256_mul_ps(
                    _mm256_cvtepi32_ps(_mm256_srli_epi32::<8>(self.0)),
                    _mm256_set1_ps(1.0 / 16_777_216.0),
                )
            };
            let a = F32x8Avx2(f).to_array();
            R::from_fn(|i| a[i] as f64)
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

    /// Whether the checks can run here (they are skipped, saying so, on a CPU without AVX2).
    fn runs_here() -> bool {
        let yes = available();
        if !yes {
            eprintln!("this CPU has no AVX2 + FMA: the register lanes cannot run here");
        }
        yes
    }

    #[test]
    fn register_lanes_compute_the_array_lanes_bits() {
        if runs_here() {
            check::float_operations_compute_the_array_lanes_bits::<crate::lanes::F32x8, F32x8Avx2>(
            );
        }
    }

    #[test]
    fn register_integers_compute_the_array_integers_bits() {
        if runs_here() {
            check::integer_operations_compute_the_array_integers_bits::<F32x8Avx2>();
        }
    }

    #[test]
    fn register_permutes_and_blends_move_the_array_lanes() {
        if runs_here() {
            check::permutes_and_blends_move_the_array_lanes::<F32x8Avx2>();
        }
    }

    #[test]
    fn register_mix_seeds_is_mix_seed() {
        if runs_here() {
            check::mix_seeds_is_mix_seed::<U32x8Avx2>();
        }
    }

    #[test]
    fn register_lanes_above_a_value_are_the_definitions() {
        if runs_here() {
            check::lanes_above_a_value_are_the_definitions::<U32x8Avx2>();
        }
    }

    #[test]
    fn register_integer_gather_reads_each_lanes_entry() {
        if runs_here() {
            check::integer_gather_reads_each_lanes_entry::<U32x8Avx2>();
        }
    }

    #[test]
    fn register_gather_reads_each_lanes_cell() {
        if runs_here() {
            check::gather_reads_each_lanes_cell::<crate::lanes::F32x8, F32x8Avx2>(true);
        }
    }
}
