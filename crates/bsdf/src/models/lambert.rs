//! The Lambertian BRDF f = R/π, sampled cosine-weighted. Upper hemisphere
//! ([`TwoSided`](crate::two_sided::TwoSided) makes it two-sided).
//!
//! | key | meaning | range | default |
//! |---|---|---|---|
//! | `reflectance` | albedo R (number or RGB) | [0, 1] | 0.5 |

use crate::bsdf::{BsdfContext, BsdfSample, LobeFlags};
use crate::checks::check_reflectance;
use crate::error::ParamResult;
use crate::math::cosine_lobe::sample_cosine_same_side;
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::warp::cosine_hemisphere_pdf;
use crate::math::{Vec3, INV_PI};
use crate::two_sided::OpaqueBsdf;

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

impl OpaqueBsdf for Lambert {
    fn flags(&self) -> LobeFlags {
        LobeFlags::DIFFUSE_REFLECTION
    }

    fn eval(&self, _: Vec3, _: Vec3, _: &BsdfContext, _: &mut dyn RandomSource) -> Spectrum {
        self.reflectance * INV_PI
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

    fn pdf(&self, _: Vec3, wi: Vec3, _: &BsdfContext) -> f64 {
        cosine_hemisphere_pdf(wi)
    }

    fn describe(&self) -> String {
        format!("lambert(reflectance={:?})", self.reflectance.0)
    }
}
