//! One source, several widths: the [`Real`] lane trait and its instantiations (`f64` for the
//! lab, `f32`, [`F32x8`], and on x86-64 `F32x8Sse2` (any CPU) and `F32x8Avx2` (with AVX2)
//! for the renderer's kernel, [`F64x4`] and [`F64x8`] for its
//! geometry, `F64x8Sse2` for its f64 test instantiation), the integer lanes [`Bits32`] (`u32` and [`U32x8`], the samplers' hashing) and
//! the lane vector [`LVec3`] — the bottom layer of the lane code, beside `math`. The models that
//! vectorize are `models::lane_models`, over these lanes. The microfacet core
//! (`microfacet::{Ggx, Beckmann}`'s `*_lanes` methods, `fresnel::*_lanes`) is the source
//! the f64 [`Distribution`](crate::microfacet::Distribution) methods instantiate.

pub(crate) mod array_lanes;
#[cfg(target_arch = "x86_64")]
pub mod avx2;
mod cell_table;
mod channels;
pub mod f32_polynomials;
mod f32x8;
mod f64x4;
mod f64x8;
#[cfg(target_arch = "x86_64")]
mod f64x8_sse2;
mod frame;
mod real;
#[cfg(all(test, target_arch = "x86_64"))]
mod register_lane_tests;
#[cfg(target_arch = "x86_64")]
pub mod sse2;
mod u32x8;
mod vec3;

#[cfg(target_arch = "x86_64")]
pub use avx2::{F32x8Avx2, M32x8Avx2, U32x8Avx2};
pub use cell_table::CellTable;
pub use channels::{channels, map_channels};
pub use f32x8::{F32x8, M32x8};
pub use f64x4::{F64x4, M64x4};
pub use f64x8::{F64x8, M64x8};
#[cfg(target_arch = "x86_64")]
pub use f64x8_sse2::{F64x8Sse2, M64x8Sse2};
pub use frame::LFrame;
pub use real::{Mask, Real};
#[cfg(target_arch = "x86_64")]
pub use sse2::{F32x8Sse2, M32x8Sse2, U32x8Sse2};
pub use u32x8::{Bits32, U32x8};
pub use vec3::LVec3;
