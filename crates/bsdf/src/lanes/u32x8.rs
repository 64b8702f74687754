//! 32-bit integer lanes: the samplers' hashing (Owen scrambles, Sobol matrix products,
//! counter-based hashes) written once over [`Bits32`] and instantiated with `u32` for one
//! camera sample and [`U32x8`] for eight — every operation a loop of eight that compiles to
//! one AVX2 instruction (`vpmulld`, shifts, logic) in the kernel's instantiation, so the
//! same source gives the same bits at both widths.

use std::ops::{BitAnd, BitOr, BitXor};

/// Unsigned 32-bit lanes with wrapping arithmetic.
pub trait Bits32:
    Copy + BitAnd<Output = Self> + BitOr<Output = Self> + BitXor<Output = Self>
{
    const LANES: usize;
    fn splat(v: u32) -> Self;
    fn lane(self, i: usize) -> u32;
    fn from_fn(f: impl FnMut(usize) -> u32) -> Self;
    fn wrapping_add(self, o: Self) -> Self;
    fn wrapping_sub(self, o: Self) -> Self;
    fn wrapping_mul(self, o: Self) -> Self;
    /// `self << n` (n < 32).
    fn shl(self, n: u32) -> Self;
    /// `self >> n` (n < 32).
    fn shr(self, n: u32) -> Self;
    /// `self >> n[i]` lane by lane (each n < 32).
    fn shr_lanes(self, n: Self) -> Self;
    /// `table[self[i]]` in each lane (a table look-up per lane); panics where an index is
    /// outside the table.
    fn gather(self, table: &[u32]) -> Self;
    /// Whether every lane is below `n`.
    fn all_below(self, n: u32) -> bool;

    /// Lane `i` takes lane `from[i]` of `self` (each index below `LANES`; the first
    /// `LANES` entries are read).
    #[inline(always)]
    fn permute(self, from: &[u8; 8]) -> Self {
        Self::from_fn(|i| self.lane(from[i] as usize))
    }
    /// [`mix_seed`](crate::math::rng::mix_seed)`(a[i], b[i])` for eight pairs: the
    /// independent sampler's 64-bit keys of a batch of camera samples (the AVX2 register
    /// lanes hash four pairs to a register).
    #[inline(always)]
    fn mix_seeds(a: &[u64; 8], b: &[u64; 8]) -> [u64; 8] {
        std::array::from_fn(|i| crate::math::rng::mix_seed(a[i], b[i]))
    }
    /// Lane `i` of `a` where bit `i` of `set` is 1, else lane `i` of `b`.
    #[inline(always)]
    fn blend_bits(set: u8, a: Self, b: Self) -> Self {
        Self::from_fn(|i| {
            if (set >> i) & 1 != 0 {
                a.lane(i)
            } else {
                b.lane(i)
            }
        })
    }

    /// The lanes above `v` as a bit set (bit `i` for lane `i`).
    #[inline(always)]
    fn above_bits(self, v: u32) -> u8 {
        (0..Self::LANES).fold(0, |s, i| s | ((self.lane(i) > v) as u8) << i)
    }

    /// The bits in reverse order: five swaps of ever smaller fields (the branch-free
    /// reversal, which vectorizes; `u32::reverse_bits` is one instruction only on ARM).
    #[inline(always)]
    fn reverse(self) -> Self {
        let swap =
            |v: Self, s: u32, m: u32| (v.shr(s) & Self::splat(m)) | (v & Self::splat(m)).shl(s);
        let v = swap(self, 16, 0x0000_ffff);
        let v = swap(v, 8, 0x00ff_00ff);
        let v = swap(v, 4, 0x0f0f_0f0f);
        let v = swap(v, 2, 0x3333_3333);
        swap(v, 1, 0x5555_5555)
    }

    /// A 32-bit fraction as a number in [0, 1) of each lane of `R`, never 1 (in f32 the
    /// fraction is cut to its top 24 bits, which f32 holds exactly).
    #[inline(always)]
    fn unit<R: super::Real>(self) -> R {
        if R::DIGITS >= 32 {
            R::from_fn(|i| self.lane(i) as f64 * (1.0 / 4_294_967_296.0))
        } else {
            R::from_fn(|i| (self.lane(i) >> 8) as f64 * (1.0 / 16_777_216.0))
        }
    }
}

impl Bits32 for u32 {
    const LANES: usize = 1;
    #[inline(always)]
    fn splat(v: u32) -> Self {
        v
    }
    #[inline(always)]
    fn lane(self, _: usize) -> u32 {
        self
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> u32) -> Self {
        f(0)
    }
    #[inline(always)]
    fn wrapping_add(self, o: Self) -> Self {
        u32::wrapping_add(self, o)
    }
    #[inline(always)]
    fn wrapping_sub(self, o: Self) -> Self {
        u32::wrapping_sub(self, o)
    }
    #[inline(always)]
    fn wrapping_mul(self, o: Self) -> Self {
        u32::wrapping_mul(self, o)
    }
    #[inline(always)]
    fn shl(self, n: u32) -> Self {
        self << n
    }
    #[inline(always)]
    fn shr(self, n: u32) -> Self {
        self >> n
    }
    #[inline(always)]
    fn shr_lanes(self, n: Self) -> Self {
        self >> n
    }
    #[inline(always)]
    fn gather(self, table: &[u32]) -> Self {
        table[self as usize]
    }
    #[inline(always)]
    fn all_below(self, n: u32) -> bool {
        self < n
    }
}

/// Eight u32 lanes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct U32x8(pub [u32; 8]);

macro_rules! bit_op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for U32x8 {
            type Output = U32x8;
            #[inline(always)]
            fn $f(self, o: U32x8) -> U32x8 {
                U32x8(std::array::from_fn(|i| self.0[i] $op o.0[i]))
            }
        }
    };
}
bit_op!(BitAnd, bitand, &);
bit_op!(BitOr, bitor, |);
bit_op!(BitXor, bitxor, ^);

impl Bits32 for U32x8 {
    const LANES: usize = 8;
    #[inline(always)]
    fn splat(v: u32) -> Self {
        U32x8([v; 8])
    }
    #[inline(always)]
    fn lane(self, i: usize) -> u32 {
        self.0[i]
    }
    #[inline(always)]
    fn from_fn(f: impl FnMut(usize) -> u32) -> Self {
        U32x8(std::array::from_fn(f))
    }
    #[inline(always)]
    fn wrapping_add(self, o: Self) -> Self {
        U32x8(std::array::from_fn(|i| self.0[i].wrapping_add(o.0[i])))
    }
    #[inline(always)]
    fn wrapping_sub(self, o: Self) -> Self {
        U32x8(std::array::from_fn(|i| self.0[i].wrapping_sub(o.0[i])))
    }
    #[inline(always)]
    fn wrapping_mul(self, o: Self) -> Self {
        U32x8(std::array::from_fn(|i| self.0[i].wrapping_mul(o.0[i])))
    }
    #[inline(always)]
    fn shl(self, n: u32) -> Self {
        U32x8(std::array::from_fn(|i| self.0[i] << n))
    }
    #[inline(always)]
    fn shr(self, n: u32) -> Self {
        U32x8(std::array::from_fn(|i| self.0[i] >> n))
    }
    #[inline(always)]
    fn shr_lanes(self, n: Self) -> Self {
        U32x8(std::array::from_fn(|i| self.0[i] >> (n.0[i] & 31)))
    }
    #[inline(always)]
    fn gather(self, table: &[u32]) -> Self {
        U32x8(std::array::from_fn(|i| table[self.0[i] as usize]))
    }
    #[inline(always)]
    fn all_below(self, n: u32) -> bool {
        self.0.iter().all(|&v| v < n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::{F32x8, Real};

    #[test]
    fn eight_lanes_compute_what_one_lane_computes() {
        let a = U32x8([
            0,
            1,
            0x8000_0001,
            u32::MAX,
            0x1234_5678,
            7,
            1 << 31,
            0xdead_beef,
        ]);
        let b = U32x8([3, 0xffff_fff0, 5, 2, 0x9e37_79b9, 0, 1, 31]);
        for i in 0..8 {
            let (x, y) = (a.0[i], b.0[i]);
            assert_eq!(a.reverse().0[i], x.reverse_bits());
            assert_eq!(Bits32::reverse(x), x.reverse_bits());
            assert_eq!(a.wrapping_mul(b).0[i], x.wrapping_mul(y));
            assert_eq!(a.wrapping_add(b).0[i], x.wrapping_add(y));
            assert_eq!(a.wrapping_sub(b).0[i], x.wrapping_sub(y));
            assert_eq!((a ^ b).0[i], x ^ y);
            assert_eq!(a.shl(3).0[i], x << 3);
            assert_eq!(a.shr(5).0[i], x >> 5);
            assert_eq!(a.shr_lanes(b).0[i], x >> (y & 31));
        }
        // Units: below 1 at both precisions, exact 32-bit fractions in f64.
        let top = U32x8::splat(u32::MAX);
        assert!(top.unit::<F32x8>().lane(0) < 1.0);
        assert_eq!(u32::MAX.unit::<f64>(), 1.0 - 2f64.powi(-32));
        assert_eq!(0x8000_0000u32.unit::<f32>(), 0.5);
    }
}
