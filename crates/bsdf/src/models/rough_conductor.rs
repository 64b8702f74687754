//! Rough conductor: the Cook–Torrance microfacet BRDF
//! f = F(i, h) D(h) G(i, o, h) / (4 |i·n| |o·n|)  [WMLT07 eq. 20; IL18 eq. 4] with a conductor
//! Fresnel term, any distribution and masking of the core; perfectly smooth (a delta
//! reflection) when α = 0. Upper hemisphere ([`TwoSided`](crate::two_sided::TwoSided) makes
//! it two-sided).
//!
//! | key | meaning | range | default |
//! |---|---|---|---|
//! | microfacet keys | see `docs/materials.md` (`distribution`, `alpha`, …) | | |
//! | `material` | metal preset (`Au`, `Ag`, `Cu`, `Al`, `Cr`) or `none` (F = 1) | — | `none` |
//! | `eta`, `k` | complex index per channel (instead of `material`) | η > 0, k ≥ 0 | — |
//! | `specular_reflectance` | multiplier of the lobe (number or RGB) | [0, 1] | 1 |

use crate::bsdf::{BsdfContext, BsdfSample, LobeFlags};
use crate::fresnel::Fresnel;
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::Vec3;
use crate::microfacet::specular_lobe::SpecularLobe;
use crate::microfacet::Distribution;
use crate::two_sided::OpaqueBsdf;

#[derive(Clone, Debug)]
pub struct RoughConductor {
    /// `None`: perfectly smooth.
    lobe: Option<SpecularLobe>,
    fresnel: Fresnel,
    tint: Spectrum,
}

impl RoughConductor {
    pub fn new(lobe: Option<SpecularLobe>, fresnel: Fresnel, tint: Spectrum) -> Self {
        RoughConductor {
            lobe,
            fresnel,
            tint,
        }
    }

    pub fn lobe(&self) -> Option<&SpecularLobe> {
        self.lobe.as_ref()
    }

    pub fn fresnel(&self) -> &Fresnel {
        &self.fresnel
    }

    /// The `specular_reflectance` multiplier.
    pub fn tint(&self) -> Spectrum {
        self.tint
    }
}

impl OpaqueBsdf for RoughConductor {
    fn flags(&self) -> LobeFlags {
        if self.lobe.is_some() {
            LobeFlags::GLOSSY_REFLECTION
        } else {
            LobeFlags::DELTA_REFLECTION
        }
    }

    fn eval(&self, wo: Vec3, wi: Vec3, _: &BsdfContext, _: &mut dyn RandomSource) -> Spectrum {
        let Some(lobe) = &self.lobe else {
            return Spectrum::ZERO;
        };
        self.tint * lobe.eval(wo, wi, |c| self.fresnel.eval(c))
    }

    fn sample(&self, wo: Vec3, _: &BsdfContext, rng: &mut dyn RandomSource) -> Option<BsdfSample> {
        let o = wo;
        let Some(lobe) = &self.lobe else {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return Some(BsdfSample {
                wi,
                weight: self.tint * self.fresnel.eval(o.z),
                pdf: 1.0,
                lobe: LobeFlags::DELTA_REFLECTION,
                eta: 1.0,
            });
        };
        let (i, h, pdf) = lobe.sample(o, rng.next_2d())?;
        let (geom, _, cos_oh) = lobe.geometry(o, i)?;
        let weight = self.tint * self.fresnel.eval(cos_oh) * (geom * i.z / pdf);
        Some(BsdfSample {
            wi: i,
            weight,
            pdf,
            lobe: LobeFlags::GLOSSY_REFLECTION,
            eta: 1.0,
        })
        .filter(|_| h.z > 0.0)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, _: &BsdfContext) -> f64 {
        match &self.lobe {
            Some(lobe) => lobe.pdf(wo, wi),
            None => 0.0,
        }
    }

    fn lobe_width(&self) -> f64 {
        self.lobe.as_ref().map_or(0.0, |l| l.typical_width())
    }

    fn describe(&self) -> String {
        let fres = match &self.fresnel {
            Fresnel::Conductor { eta, k } => format!("eta={:?}, k={:?}", eta.0, k.0),
            Fresnel::One => "F=1".into(),
            other => format!("{other:?}"),
        };
        match &self.lobe {
            Some(l) => format!(
                "conductor({}, masking={}, sampling={}, {fres})",
                l.ndf.describe(),
                l.masking.name(),
                l.sampling().name()
            ),
            None => format!("conductor(smooth, {fres})"),
        }
    }
}
