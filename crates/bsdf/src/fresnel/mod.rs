//! Fresnel terms: exact unpolarized dielectric with total internal reflection, conductors
//! with a complex index (named metal presets), Schlick's approximation, and the
//! hemispherical averages r_e and r_i of a flat interface.

pub mod conductor;
pub mod dielectric;
pub mod dielectric_table;
pub mod diffuse_averages;
pub mod schlick;

pub use conductor::{fresnel_conductor, MetalPreset};
pub use dielectric::fresnel_dielectric;
pub use dielectric_table::FresnelTable;
pub use diffuse_averages::{external_diffuse_reflectance, internal_diffuse_reflectance};
pub use schlick::fresnel_schlick;

use crate::math::spectrum::Spectrum;

/// A reflectance F(cos θ) for a microfacet lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fresnel {
    /// Exact dielectric with relative index η = η_t/η_i (WMLT07 eq. 22).
    Dielectric { eta: f64 },
    /// Exact conductor, complex index η + ik per channel.
    Conductor { eta: Spectrum, k: Spectrum },
    /// Schlick's approximation with normal-incidence reflectance F0.
    Schlick { f0: Spectrum },
    /// F = 1 (white furnace tests).
    One,
}

impl Fresnel {
    #[inline]
    pub fn eval(&self, cos_theta: f64) -> Spectrum {
        match self {
            Fresnel::Dielectric { eta } => Spectrum::splat(fresnel_dielectric(cos_theta, *eta)),
            Fresnel::Conductor { eta, k } => fresnel_conductor(cos_theta, *eta, *k),
            Fresnel::Schlick { f0 } => fresnel_schlick(cos_theta, *f0),
            Fresnel::One => Spectrum::ONE,
        }
    }
}
