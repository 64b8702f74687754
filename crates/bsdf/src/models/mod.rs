//! The BSDF models, one file per model, built from the shared parts below them
//! ([`crate::microfacet`]: one specular lobe, one microfacet integrator; [`crate::fresnel`];
//! [`crate::math`]). This file only declares and re-exports.
//!
//! - Single-lobe models stay at this level — [`lambert`], [`oren_nayar`],
//!   [`rough_conductor`], [`rough_dielectric`], [`kelemen`]: each is complete in its file
//!   and shares nothing private with another.
//! - [`il`]: the interfaced-Lambertian family — the exact model, its V-cavity inter-
//!   reflections, its tabulated and approximate body terms.
//! - [`multiple_scattering`]: what single scattering loses, two ways — the random walk on
//!   the Smith microsurface (HHdD16) and the Kulla–Conty compensation lobe with its albedo
//!   tables (KC17).
//! - [`glint`]: the CCM19 glint BRDF.
//! - [`lane_models`]: Lambert and the rough conductor and dielectric written over
//!   [`crate::lanes`] (f32 lanes for the renderer's packet kernel), tested against the models
//!   above.
//!
//! Opaque models are written for the upper hemisphere; [`crate::two_sided::TwoSided`] makes
//! them two-sided.

pub mod glint;
pub mod il;
pub mod kelemen;
pub mod lambert;
pub mod lane_colors;
pub mod lane_models;
pub mod multiple_scattering;
pub mod oren_nayar;
pub mod rough_conductor;
pub mod rough_dielectric;

pub use il::InterfacedLambertian;
pub use kelemen::Kelemen;
pub use lambert::Lambert;
pub use lane_colors::{ColorSource, LaneColorParam, LaneColors, OwnColors};
pub use lane_models::{LaneBsdf, LaneFresnel, LaneNdf, LaneRandom, LaneSample};
pub use multiple_scattering::{
    CompensatedConductor, CompensatedDielectric, MultipleScatteringConductor,
    MultipleScatteringDielectric,
};
pub use oren_nayar::{OrenNayarExact, OrenNayarQualitative};
pub use rough_conductor::RoughConductor;
pub use rough_dielectric::RoughDielectric;
