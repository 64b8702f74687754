//! The three colour channels of a lane spectrum (`[R; 3]`), built by functions that are
//! always inlined. `std::array::from_fn` and `<[T; 3]>::map` go through library functions
//! that LLVM does not always inline; in the render kernel's AVX2 build such a function is
//! compiled without AVX2, and the register lanes' ([`F32x8Avx2`](super::F32x8Avx2))
//! operations inside its closure became calls of the intrinsics (measured on
//! `bench-sphere`: 9 % of the render time in out-of-line `_mm256_mul_ps` and
//! `_mm256_blendv_ps`). Lane code builds its channel arrays with these instead.

/// `[f(0), f(1), f(2)]`.
#[inline(always)]
pub fn channels<T>(mut f: impl FnMut(usize) -> T) -> [T; 3] {
    [f(0), f(1), f(2)]
}

/// `[f(a[0]), f(a[1]), f(a[2])]`.
#[inline(always)]
pub fn map_channels<T, U>(a: [T; 3], mut f: impl FnMut(T) -> U) -> [U; 3] {
    let [x, y, z] = a;
    [f(x), f(y), f(z)]
}
