//! A measured BRDF (MERL format) as a BSDF, so the lab's views and checks take measured
//! data beside the models: f(i, o) is the value of the bin the pair falls in
//! ([`MerlBrdf::lookup`], nearest bin, 0 for invalid bins), sampled cosine-weighted (the
//! data carry no sampling density of their own). Two-sided through [`TwoSided`].

use crate::merl::MerlBrdf;
use facette_bsdf::math::cosine_lobe::sample_cosine_same_side;
use facette_bsdf::math::rng::RandomSource;
use facette_bsdf::math::warp::cosine_hemisphere_pdf;
use facette_bsdf::two_sided::{OpaqueBsdf, TwoSided};
use facette_bsdf::{BsdfContext, BsdfSample, LobeFlags, Spectrum, Vec3};
use std::sync::Arc;

/// A MERL file's values as an opaque BRDF of the upper hemisphere.
#[derive(Clone)]
pub struct MeasuredBsdf {
    merl: Arc<MerlBrdf>,
    name: String,
}

impl MeasuredBsdf {
    /// The BRDF of `merl`, two-sided, named `name` (the file's) in descriptions.
    pub fn two_sided(merl: Arc<MerlBrdf>, name: impl Into<String>) -> TwoSided<MeasuredBsdf> {
        TwoSided::new(MeasuredBsdf {
            merl,
            name: name.into(),
        })
    }
}

impl OpaqueBsdf for MeasuredBsdf {
    fn flags(&self) -> LobeFlags {
        LobeFlags::GLOSSY_REFLECTION | LobeFlags::DIFFUSE_REFLECTION
    }

    fn eval(&self, wo: Vec3, wi: Vec3, _: &BsdfContext, _: &mut dyn RandomSource) -> Spectrum {
        self.merl.lookup(wi, wo).unwrap_or(Spectrum::ZERO)
    }

    fn sample(
        &self,
        wo: Vec3,
        ctx: &BsdfContext,
        rng: &mut dyn RandomSource,
    ) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let (wi, pdf) = sample_cosine_same_side(wo, rng)?;
        let f = self.eval(wo, wi, ctx, rng);
        Some(BsdfSample {
            wi,
            weight: f * (wi.z / pdf),
            pdf,
            lobe: LobeFlags::GLOSSY_REFLECTION,
            eta: 1.0,
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, _: &BsdfContext) -> f64 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        cosine_hemisphere_pdf(wi)
    }

    fn describe(&self) -> String {
        format!("measured({}, nearest MERL bin)", self.name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use facette_bsdf::math::rng::Pcg32;
    use facette_bsdf::validation::bsdf_checks::directional_albedo;
    use facette_bsdf::Bsdf;

    #[test]
    fn a_measured_lambert_is_lambert() {
        let merl = MerlBrdf::from_fn(|_, _, _| Some(Spectrum::splat(0.8 / std::f64::consts::PI)));
        let b = MeasuredBsdf::two_sided(Arc::new(merl), "white");
        let mut rng = Pcg32::new(1, 1);
        let wi = Vec3::new(0.3, 0.1, 0.9).normalize();
        let wo = Vec3::new(-0.5, 0.2, 0.6).normalize();
        let f = b.eval(wo, wi, &BsdfContext::RADIANCE, &mut rng);
        assert!((f[0] - 0.8 / std::f64::consts::PI).abs() < 1e-12);
        let (r, se, t, _) = directional_albedo(&b, wo, &BsdfContext::IMPORTANCE, 4096, 3);
        assert!((r[0] - 0.8).abs() < 1e-9 + 3.0 * se[0], "{r:?}");
        assert_eq!(t[0], 0.0);
        assert!(b.describe().contains("white"));
    }
}
