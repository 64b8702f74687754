//! The BSDF models, one file per model, each built from the shared parts of
//! [`crate::microfacet`] (one specular lobe, one microfacet integrator). The
//! multiple-scattering conductor and dielectric share the Smith-microsurface random walk of
//! [`smith_microsurface`]; the compensated ones share the albedo tables of
//! [`albedo_tables`].

pub mod albedo_tables;
pub mod compensated_conductor;
pub mod compensated_dielectric;
pub(crate) mod cosine_lobe;
pub mod glint;
pub mod il_approx;
pub mod il_approx_coefficients;
pub mod il_table;
pub mod il_table_part;
pub mod interfaced_lambertian;
pub mod kelemen;
pub mod lambert;
pub mod microfacet_integral;
pub mod multiple_scattering_conductor;
pub mod multiple_scattering_dielectric;
pub mod oren_nayar;
pub mod rough_conductor;
pub mod rough_dielectric;
pub mod smith_microsurface;
pub mod vcavity;

pub use compensated_conductor::CompensatedConductor;
pub use compensated_dielectric::CompensatedDielectric;
pub use interfaced_lambertian::InterfacedLambertian;
pub use kelemen::Kelemen;
pub use lambert::Lambert;
pub use multiple_scattering_conductor::MultipleScatteringConductor;
pub use multiple_scattering_dielectric::MultipleScatteringDielectric;
pub use oren_nayar::{OrenNayarExact, OrenNayarQualitative};
pub use rough_conductor::RoughConductor;
pub use rough_dielectric::RoughDielectric;

use crate::math::Vec3;

/// Opaque BRDFs are two-sided: a query from below the surface is answered as its mirror
/// image above it. Returns the pair flipped to the upper hemisphere, or `None` when the two
/// directions are on opposite sides (or in the tangent plane).
#[inline]
pub(crate) fn to_upper_pair(wo: Vec3, wi: Vec3) -> Option<(Vec3, Vec3)> {
    if wo.z * wi.z <= 0.0 {
        return None;
    }
    if wo.z > 0.0 {
        Some((wo, wi))
    } else {
        Some((flip(wo), flip(wi)))
    }
}

/// Mirror image through the tangent plane.
#[inline]
pub(crate) fn flip(v: Vec3) -> Vec3 {
    Vec3::new(v.x, v.y, -v.z)
}
