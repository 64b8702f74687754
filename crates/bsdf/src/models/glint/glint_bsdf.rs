//! The P-BRDF of a footprint  [CCM19 eq. 7]:
//!
//!   f_P(o, i) = F(o·h) G2(P, h, o, i) D_P(h) / (4 A_P(o) A_P(i))
//!             = F(o·h) χ⁺(o·h) χ⁺(i·h) D_P(h) / (4 I_P(o) I_P(i)),
//!
//! the second form after the projected areas cancel (see [`super::patch_masking`]), with a
//! conductor (or F = 1) Fresnel term and a reflectance multiplier. Written for the upper
//! hemisphere like every opaque model of the library ([`crate::two_sided::TwoSided`] makes it
//! two-sided). Reciprocal (symmetric in o and i).
//!
//! **Sampling**: a lobe of the footprint, then a slope of that lobe ([`PatchNdf`]), mirrored:
//! pdf(i) = D_P(h) cos θ_h / (4 o·h)  [WMLT07 eqs. 14, 38; CCM19 §5], the density the
//! sampler has — not an approximation of it.
//!
//! **Energy.** ∫ f_P I_P(i) dω_i ≤ 1: the P-BRDF conserves energy for the cosine I_P(i)
//! (the patch's visible projected area). A renderer multiplies by cos θ_i instead; the
//! two agree on average but differ for a footprint whose mean slope is not zero, where the
//! albedo w.r.t. cos θ_i can exceed 1 (measured in the tests and docs/glints.md).

use super::footprint::{Footprint, FootprintQuery};
use super::patch_masking::{MaskingMode, PatchMasking};
use super::patch_ndf::PatchNdf;
use super::patch_reflection::{self, PatchReflection};
use super::surface::GlintSurface;
use crate::bsdf::{BsdfContext, BsdfSample, LobeFlags};
use crate::fresnel::Fresnel;
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::{fmt_num, Vec3};
use crate::two_sided::OpaqueBsdf;
use std::sync::{Arc, Mutex};

/// Material parameters besides the surface and the footprint.
#[derive(Clone, Debug)]
pub struct GlintParams {
    pub fresnel: Fresnel,
    pub tint: Spectrum,
    pub masking: MaskingMode,
    /// Budget of the exact masking sum (0 = unlimited).
    pub masking_lobes: usize,
}

/// The P-BRDF for one footprint (built per shading point; the surface is shared).
pub struct GlintBsdf {
    surface: Arc<GlintSurface>,
    query: FootprintQuery,
    masking: PatchMasking,
    fresnel: Fresnel,
    tint: Spectrum,
    footprint: Footprint,
    /// I_P of the last `wo`: the integrator asks for the same view direction many times.
    cache: Mutex<Option<(Vec3, f64)>>,
    /// D_P of the last half vector: a light sample's `eval` and `pdf` ask for the same one
    /// (each query sums the footprint's lobes, the cost of this material).
    last_d: Mutex<Option<(Vec3, f64)>>,
}

impl GlintBsdf {
    pub fn new(surface: Arc<GlintSurface>, footprint: Footprint, params: &GlintParams) -> Self {
        let footprint = footprint.sanitized();
        let query = surface.query(footprint);
        let masking = PatchMasking::new(params.masking, &surface, &query, params.masking_lobes);
        GlintBsdf {
            surface,
            query,
            masking,
            fresnel: params.fresnel,
            tint: params.tint,
            footprint,
            cache: Mutex::new(None),
            last_d: Mutex::new(None),
        }
    }

    pub fn ndf(&self) -> PatchNdf<'_> {
        PatchNdf::new(&self.surface, &self.query)
    }

    pub fn masking(&self) -> &PatchMasking {
        &self.masking
    }

    pub fn query(&self) -> &FootprintQuery {
        &self.query
    }

    pub fn surface(&self) -> &GlintSurface {
        &self.surface
    }

    /// I_P(v) for v in the upper hemisphere, remembering the last answer.
    fn visible_area(&self, v: Vec3) -> f64 {
        if let Ok(mut c) = self.cache.try_lock() {
            if let Some((w, a)) = *c {
                if w == v {
                    return a;
                }
            }
            let a = self.masking.visible_projected_area(v);
            *c = Some((v, a));
            return a;
        }
        self.masking.visible_projected_area(v)
    }
}

impl PatchReflection for GlintBsdf {
    /// D_P(h)  [CCM19 eq. 9], remembering the last answer.
    fn d(&self, h: Vec3) -> f64 {
        if let Ok(mut c) = self.last_d.try_lock() {
            if let Some((m, d)) = *c {
                if m == h {
                    return d;
                }
            }
            let d = self.ndf().d(h);
            *c = Some((h, d));
            return d;
        }
        self.ndf().d(h)
    }

    fn sample_normal(&self, rng: &mut dyn RandomSource) -> Option<Vec3> {
        self.ndf().sample_normal(rng)
    }

    fn view_area(&self, o: Vec3) -> f64 {
        self.visible_area(o)
    }

    fn light_area(&self, i: Vec3) -> f64 {
        self.masking.visible_projected_area(i)
    }

    fn fresnel(&self) -> &Fresnel {
        &self.fresnel
    }

    fn tint(&self) -> Spectrum {
        self.tint
    }
}

impl OpaqueBsdf for GlintBsdf {
    fn flags(&self) -> LobeFlags {
        LobeFlags::GLOSSY_REFLECTION
    }

    fn eval(&self, wo: Vec3, wi: Vec3, _: &BsdfContext, _: &mut dyn RandomSource) -> Spectrum {
        patch_reflection::eval(self, wo, wi)
    }

    fn sample(&self, wo: Vec3, _: &BsdfContext, rng: &mut dyn RandomSource) -> Option<BsdfSample> {
        patch_reflection::sample(self, wo, rng)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, _: &BsdfContext) -> f64 {
        patch_reflection::pdf(self, wo, wi)
    }

    /// The RMS slope of the footprint's distribution (at least 0.15, so the validation
    /// harness tests the whole hemisphere: the patch NDF has many separated peaks).
    fn lobe_width(&self) -> f64 {
        let l = self.masking.filtered_lobe();
        let spread = (l.mean[0].powi(2) + l.mean[1].powi(2) + l.cov[0] + l.cov[2]).sqrt();
        spread.max(0.15)
    }

    fn describe(&self) -> String {
        let fres = match &self.fresnel {
            Fresnel::Conductor { eta, k } => format!("eta={:?}, k={:?}", eta.0, k.0),
            Fresnel::One => "F=1".into(),
            other => format!("{other:?}"),
        };
        let c = self.footprint.cov;
        format!(
            "glint({}, footprint centre ({}, {}) texels, cov [{}, {}, {}] texels², masking={} (level {}, {} lobes), {fres})",
            self.surface.label(),
            fmt_num(self.footprint.center.x),
            fmt_num(self.footprint.center.y),
            fmt_num(c[0]),
            fmt_num(c[1]),
            fmt_num(c[2]),
            self.masking.mode().name(),
            self.masking.level(),
            self.masking.lobe_count()
        )
    }
}
