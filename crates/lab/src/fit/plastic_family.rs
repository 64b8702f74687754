//! "Plastic" as a fitting family: a Lambertian term plus a Cook–Torrance specular lobe,
//! f = K_d/π + k_s F(o·h; η) D(h) G(i, o, h) / (4 |i·n| |o·n|)  [WMLT07 eq. 20; IL18
//! §5's *Plastic*], with an achromatic specular scale k_s, a dielectric Fresnel term of
//! fixed index η = 1.5 (k_s and η are nearly interchangeable in the fit, so η is not
//! free), Beckmann or GGX of width α and Smith masking. The sum is not energy conserving
//! (the Lambertian term ignores the light the lobe reflects) — that is the model IL18
//! compares against.

use super::family::{ModelFamily, Parameter};
use super::samples::FitSample;
use facette_bsdf::fresnel::fresnel_dielectric;
use facette_bsdf::microfacet::specular_lobe::{NormalSampling, SpecularLobe};
use facette_bsdf::microfacet::{Beckmann, Ggx, Masking, Ndf};
use facette_bsdf::{ParamError, Spectrum};
use rayon::prelude::*;
use std::f64::consts::FRAC_1_PI;

/// The Fresnel index of the plastic's interface.
pub const PLASTIC_ETA: f64 = 1.5;

pub struct PlasticFamily {
    /// `true`: GGX; `false`: Beckmann.
    pub ggx: bool,
}

impl PlasticFamily {
    fn lobe(&self, alpha: f64) -> Result<SpecularLobe, ParamError> {
        let ndf = if self.ggx {
            Ndf::Ggx(Ggx::isotropic(alpha)?)
        } else {
            Ndf::Beckmann(Beckmann::isotropic(alpha)?)
        };
        SpecularLobe::new(ndf, Masking::SmithSeparable, NormalSampling::Visible)
    }
}

impl ModelFamily for PlasticFamily {
    fn name(&self) -> String {
        format!(
            "plastic (Lambert + Cook–Torrance, {}, Smith, Fresnel η = {PLASTIC_ETA})",
            if self.ggx { "ggx" } else { "beckmann" }
        )
    }

    fn parameters(&self) -> Vec<Parameter> {
        vec![
            Parameter::new("kd_r", "", 0.0, 1.0),
            Parameter::new("kd_g", "", 0.0, 1.0),
            Parameter::new("kd_b", "", 0.0, 1.0),
            Parameter::new("ks", "", 0.0, 20.0),
            Parameter::new("alpha", "", 0.002, 1.5),
        ]
    }

    fn starts(&self, diffuse: Spectrum) -> Vec<Vec<f64>> {
        [0.05, 0.2, 0.5]
            .iter()
            .map(|&a| vec![diffuse[0], diffuse[1], diffuse[2], 1.0, a])
            .collect()
    }

    fn predict(&self, p: &[f64], samples: &[FitSample]) -> Result<Vec<Spectrum>, ParamError> {
        let kd = Spectrum::rgb(p[0], p[1], p[2]) * FRAC_1_PI;
        let (ks, lobe) = (p[3], self.lobe(p[4])?);
        Ok(samples
            .par_iter()
            .map(|s| {
                kd + lobe.eval(s.o, s.i, |c| {
                    Spectrum::splat(ks * fresnel_dielectric(c, PLASTIC_ETA))
                })
            })
            .collect())
    }

    fn material_toml(&self, _: &[f64]) -> Option<String> {
        None
    }
}
