//! What every array-backed lane type shares: the arithmetic, comparisons, masks and
//! `select` written lane by lane over `[T; N]` (each operation one vector instruction where
//! the function is compiled for the target's vector width), generated once by
//! [`array_lanes!`] for [`F32x8`](super::F32x8) and [`F64x4`](super::F64x4). Each type adds
//! its own transcendental functions.

/// `body` for `i` = 0, …, N − 1 (N ≤ 8) written out, not as a loop: a lane type's every
/// operation is one of these, and LLVM's loop passes (rotation above all) on the render
/// kernel's thousands of 8-trip loops were most of its compile time. The branches past N
/// are constant and vanish.
macro_rules! unrolled {
    ($n:expr, |$i:ident| $body:expr) => {{
        const { assert!($n <= 8, "array lanes are at most 8 wide") };
        unrolled!(@ $n, $i, $body, 0 1 2 3 4 5 6 7)
    }};
    (@ $n:expr, $i:ident, $body:expr, $($k:literal)*) => {{
        $(if $k < $n {
            let $i = $k;
            $body;
        })*
    }};
}

/// `[f(a[0]), …, f(a[N−1])]`: the length comes from the input array. Written into a zeroed
/// array rather than by `std::array::from_fn`, whose initialization guard LLVM does not
/// always remove (measured: 2,124 against 2,102 instructions a sample on `bench-sphere`).
#[inline(always)]
pub(crate) fn map1<T: Copy, U: Copy + Default, const N: usize>(
    a: [T; N],
    f: impl Fn(T) -> U,
) -> [U; N] {
    let mut r = [U::default(); N];
    unrolled!(N, |i| r[i] = f(a[i]));
    r
}

/// `[f(a[0], b[0]), …]`.
#[inline(always)]
pub(crate) fn map2<T: Copy, S: Copy, U: Copy + Default, const N: usize>(
    a: [T; N],
    b: [S; N],
    f: impl Fn(T, S) -> U,
) -> [U; N] {
    let mut r = [U::default(); N];
    unrolled!(N, |i| r[i] = f(a[i], b[i]));
    r
}

/// `lanewise!(a, |x| e)` is [`map1`], `lanewise!(a, b, |x, y| e)` is [`map2`].
macro_rules! lanewise {
    ($a:expr, |$x:ident| $e:expr) => {
        $crate::lanes::array_lanes::map1($a, |$x| $e)
    };
    ($a:expr, $b:expr, |$x:ident, $y:ident| $e:expr) => {
        $crate::lanes::array_lanes::map2($a, $b, |$x, $y| $e)
    };
}
pub(crate) use lanewise;

/// The operators, the mask type's [`Mask`](super::Mask) impl and a [`Real`](super::Real)
/// impl for the lane type `$real` (`[$elem; $n]`) and its mask `$mask` (`[$bits; $n]`, all
/// bits set or clear per lane, the layout of a vector compare), with the transcendental
/// methods (`sin_cos`, `exp`, `ln`) given as `$special`.
macro_rules! array_lanes {
    ($real:ident, $mask:ident, $elem:ty, $bits:ty, $n:literal, tiny = $tiny:expr, cells = $cells:ident, { $($special:tt)* }) => {
        macro_rules! binop {
            ($tr:ident, $f:ident, $op:tt) => {
                impl $tr for $real {
                    type Output = $real;
                    #[inline(always)]
                    fn $f(self, o: $real) -> $real {
                        $real(lanewise!(self.0, o.0, |a, b| a $op b))
                    }
                }
            };
        }
        binop!(Add, add, +);
        binop!(Sub, sub, -);
        binop!(Mul, mul, *);
        binop!(Div, div, /);

        impl Neg for $real {
            type Output = $real;
            #[inline(always)]
            fn neg(self) -> $real {
                $real(lanewise!(self.0, |a| -a))
            }
        }

        impl BitAnd for $mask {
            type Output = $mask;
            #[inline(always)]
            fn bitand(self, o: $mask) -> $mask {
                $mask(lanewise!(self.0, o.0, |a, b| a & b))
            }
        }
        impl BitOr for $mask {
            type Output = $mask;
            #[inline(always)]
            fn bitor(self, o: $mask) -> $mask {
                $mask(lanewise!(self.0, o.0, |a, b| a | b))
            }
        }
        impl Not for $mask {
            type Output = $mask;
            #[inline(always)]
            fn not(self) -> $mask {
                $mask(lanewise!(self.0, |a| !a))
            }
        }

        impl $mask {
            /// One bit per lane, lane 0 in bit 0 (AVX's `movemask`).
            #[inline(always)]
            pub fn bits(self) -> u32 {
                let mut b = 0;
                for i in 0..$n {
                    b |= ((self.0[i] >> (<$bits>::BITS - 1)) as u32) << i;
                }
                b
            }
        }

        impl Mask for $mask {
            #[inline(always)]
            fn splat(b: bool) -> Self {
                $mask([if b { !0 } else { 0 }; $n])
            }
            #[inline(always)]
            fn any(self) -> bool {
                self.bits() != 0
            }
            #[inline(always)]
            fn all(self) -> bool {
                self.bits() == (1 << $n) - 1
            }
            #[inline(always)]
            fn lane(self, i: usize) -> bool {
                self.0[i] != 0
            }
            #[inline(always)]
            fn from_fn(mut f: impl FnMut(usize) -> bool) -> Self {
                $mask(std::array::from_fn(|i| if f(i) { !0 } else { 0 }))
            }
            #[inline(always)]
            fn lane_bits(self) -> u32 {
                self.bits()
            }
            #[inline(always)]
            fn from_lane_bits(bits: u32) -> Self {
                $mask(std::array::from_fn(|i| {
                    <$bits>::MIN.wrapping_sub(((bits >> i) & 1) as $bits)
                }))
            }
            #[inline(always)]
            fn width() -> usize {
                $n
            }
        }

        impl $real {
            #[inline(always)]
            fn cmp(self, b: $real, f: impl Fn($elem, $elem) -> bool) -> $mask {
                $mask(lanewise!(self.0, b.0, |x, y| if f(x, y) { !0 } else { 0 }))
            }
            #[inline(always)]
            fn bits(self) -> [$bits; $n] {
                lanewise!(self.0, |a| a.to_bits())
            }
            #[inline(always)]
            fn from_bits(b: [$bits; $n]) -> $real {
                $real(lanewise!(b, |a| <$elem>::from_bits(a)))
            }
        }

        impl Real for $real {
            type Mask = $mask;
            const LANES: usize = $n;
            const TINY: f64 = $tiny;
            const DIGITS: u32 = <$elem>::MANTISSA_DIGITS;

            #[inline(always)]
            fn splat(v: f64) -> Self {
                $real([v as $elem; $n])
            }
            #[inline(always)]
            fn lane(self, i: usize) -> f64 {
                self.0[i] as f64
            }
            #[inline(always)]
            fn from_fn(mut f: impl FnMut(usize) -> f64) -> Self {
                $real(std::array::from_fn(|i| f(i) as $elem))
            }
            /// In place: a scalar store to the lane (rebuilding the whole value, read back
            /// at once as a vector, stalled store forwarding in the kernel's refill).
            #[inline(always)]
            fn set_lane(&mut self, i: usize, v: f64) {
                self.0[i] = v as $elem;
            }
            /// One load of the cell's four numbers per lane, transposed into four lane values.
            #[inline(always)]
            fn gather4(table: &$crate::lanes::CellTable, cell: Self) -> [Self; 4] {
                let cells = table.$cells();
                // One vector conversion; a negative lane indexes out of bounds (a panic,
                // never a wrong cell). A NaN lane reads cell 0 (`as` maps NaN to 0), where
                // the register lanes' truncation indexes out of bounds and panics.
                let index = lanewise!(cell.0, |a| a as i32);
                let mut out = [[0.0 as $elem; $n]; 4];
                for i in 0..$n {
                    let c = cells[index[i] as u32 as usize];
                    for k in 0..4 {
                        out[k][i] = c[k];
                    }
                }
                [$real(out[0]), $real(out[1]), $real(out[2]), $real(out[3])]
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                $real(lanewise!(self.0, |a| a.sqrt()))
            }
            #[inline(always)]
            fn abs(self) -> Self {
                Self::from_bits(lanewise!(self.bits(), |b| b & (<$bits>::MAX >> 1)))
            }
            /// `self < o ? self : o` (the SSE/AVX `min` operand order: a NaN `self` yields
            /// `o`).
            #[inline(always)]
            fn min(self, o: Self) -> Self {
                $real(lanewise!(self.0, o.0, |a, b| if a < b { a } else { b }))
            }
            #[inline(always)]
            fn max(self, o: Self) -> Self {
                $real(lanewise!(self.0, o.0, |a, b| if a > b { a } else { b }))
            }
            #[inline(always)]
            fn lt(self, o: Self) -> $mask {
                self.cmp(o, |a, b| a < b)
            }
            #[inline(always)]
            fn le(self, o: Self) -> $mask {
                self.cmp(o, |a, b| a <= b)
            }
            #[inline(always)]
            fn gt(self, o: Self) -> $mask {
                self.cmp(o, |a, b| a > b)
            }
            #[inline(always)]
            fn ge(self, o: Self) -> $mask {
                self.cmp(o, |a, b| a >= b)
            }
            #[inline(always)]
            fn eq(self, o: Self) -> $mask {
                self.cmp(o, |a, b| a == b)
            }
            #[inline(always)]
            fn select(m: $mask, a: Self, b: Self) -> Self {
                let (ab, bb) = (a.bits(), b.bits());
                let mut r = [0; $n];
                for i in 0..$n {
                    r[i] = (m.0[i] & ab[i]) | (!m.0[i] & bb[i]);
                }
                Self::from_bits(r)
            }
            /// x − x = 0 (NaN for ±∞ and NaN): a subtraction and a compare per vector.
            /// Written with `is_finite` or |x| < ∞, LLVM turns the test (and its
            /// conjunction with a sign test) into a floating-point class test that it
            /// expands lane by lane in integer code on AVX2 (measured: 20 scalar
            /// instructions per camera sample in the sphere's hit record alone).
            #[inline(always)]
            fn is_finite(self) -> $mask {
                (self - self).eq(Self::zero())
            }

            $($special)*
        }
    };
}
pub(crate) use array_lanes;
