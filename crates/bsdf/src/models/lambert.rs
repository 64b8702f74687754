//! The Lambertian BRDF f = R/π, sampled cosine-weighted. Two-sided.
//!
//! | key | meaning | range | default |
//! |---|---|---|---|
//! | `reflectance` | albedo R (number or RGB) | [0, 1] | 0.5 |

use crate::bsdf::{Bsdf, BsdfContext, BsdfSample, LobeFlags};
use crate::checks::check_reflectance;
use crate::error::ParamResult;
use crate::math::cosine_lobe::{cosine_same_side_pdf, sample_cosine_same_side};
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::{to_upper_pair, Vec3, INV_PI};

#[derive(Clone, Debug)]
pub struct Lambert {
    reflectance: Spectrum,
}

impl Lambert {
    pub fn new(reflectance: Spectrum) -> ParamResult<Self> {
        Ok(Lambert {
            reflectance: check_reflectance("reflectance", reflectance)?,
        })
    }
}

impl Bsdf for Lambert {
    fn flags(&self) -> LobeFlags {
        LobeFlags::DIFFUSE_REFLECTION
    }

    fn eval(&self, wo: Vec3, wi: Vec3, _: &BsdfContext, _: &mut dyn RandomSource) -> Spectrum {
        match to_upper_pair(wo, wi) {
            Some(_) => self.reflectance * INV_PI,
            None => Spectrum::ZERO,
        }
    }

    fn sample(&self, wo: Vec3, _: &BsdfContext, rng: &mut dyn RandomSource) -> Option<BsdfSample> {
        // f·cos/pdf = reflectance exactly: no evaluation needed.
        let (wi, pdf) = sample_cosine_same_side(wo, rng)?;
        Some(BsdfSample {
            wi,
            weight: self.reflectance,
            pdf,
            lobe: LobeFlags::DIFFUSE_REFLECTION,
            eta: 1.0,
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, _: &BsdfContext) -> f64 {
        cosine_same_side_pdf(wo, wi)
    }

    fn describe(&self) -> String {
        format!("lambert(reflectance={:?})", self.reflectance.0)
    }
}
