//! The P-BRDF of a footprint  [CCM19 eq. 7]:
//!
//!   f_P(o, i) = F(o·h) G2(P, h, o, i) D_P(h) / (4 A_P(o) A_P(i))
//!             = F(o·h) χ⁺(o·h) χ⁺(i·h) D_P(h) / (4 I_P(o) I_P(i)),
//!
//! the second form after the projected areas cancel (see [`super::patch_masking`]), with a
//! conductor (or F = 1) Fresnel term and a reflectance multiplier. Two-sided like every
//! opaque model of the library. Reciprocal (symmetric in o and i).
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
use super::surface::GlintSurface;
use crate::bsdf::{Bsdf, BsdfContext, BsdfSample, LobeFlags};
use crate::fresnel::Fresnel;
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::{fmt_num, reflect, Vec3};
use crate::models::{flip, to_upper_pair};
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
}

impl GlintBsdf {
    pub fn new(surface: Arc<GlintSurface>, footprint: Footprint, params: &GlintParams) -> Self {
        let footprint = footprint.sanitized();
        let query = FootprintQuery::new(footprint, surface.width(), surface.height());
        let masking = PatchMasking::new(params.masking, &surface, &query, params.masking_lobes);
        GlintBsdf {
            surface,
            query,
            masking,
            fresnel: params.fresnel,
            tint: params.tint,
            footprint,
            cache: Mutex::new(None),
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

    /// f_P for an upper-hemisphere pair.
    fn eval_upper(&self, o: Vec3, i: Vec3) -> Spectrum {
        let h = (o + i).normalize_or_zero();
        let cos_oh = o.dot(h);
        if !(h.z > 0.0) || !(cos_oh > 0.0) || !(i.dot(h) > 0.0) {
            return Spectrum::ZERO;
        }
        self.eval_with_d(o, i, cos_oh, self.ndf().d(h))
    }

    /// f_P given D_P(h) (the sampler has it already: one P-NDF query per sample).
    fn eval_with_d(&self, o: Vec3, i: Vec3, cos_oh: f64, d: f64) -> Spectrum {
        if !(d > 0.0) {
            return Spectrum::ZERO;
        }
        let io = self.visible_area(o);
        let ii = self.masking.visible_projected_area(i);
        if !(io > 0.0 && ii > 0.0) {
            return Spectrum::ZERO;
        }
        let v = d / (4.0 * io * ii);
        if !v.is_finite() {
            return Spectrum::ZERO;
        }
        self.tint * self.fresnel.eval(cos_oh) * v
    }
}

impl Bsdf for GlintBsdf {
    fn flags(&self) -> LobeFlags {
        LobeFlags::GLOSSY_REFLECTION
    }

    fn eval(&self, wo: Vec3, wi: Vec3, _: &BsdfContext, _: &mut dyn RandomSource) -> Spectrum {
        match to_upper_pair(wo, wi) {
            Some((o, i)) => self.eval_upper(o, i),
            None => Spectrum::ZERO,
        }
    }

    fn sample(&self, wo: Vec3, _: &BsdfContext, rng: &mut dyn RandomSource) -> Option<BsdfSample> {
        if wo.z == 0.0 || !wo.is_finite() {
            return None;
        }
        let below = wo.z < 0.0;
        let o = if below { flip(wo) } else { wo };
        let ndf = self.ndf();
        let m = ndf.sample_normal(rng)?;
        let cos_om = o.dot(m);
        if !(cos_om > 0.0) {
            return None;
        }
        let i = reflect(o, m).normalize();
        if !(i.z > 0.0) {
            return None;
        }
        // The pdf is evaluated at the half vector of (o, i), exactly as `pdf` will.
        let h = (o + i).normalize();
        let cos_oh = o.dot(h);
        if !(cos_oh > 0.0) || !(i.dot(h) > 0.0) {
            return None;
        }
        let d = ndf.d(h);
        let pdf = d * h.z.max(0.0) / (4.0 * cos_oh);
        if !(pdf > 0.0) || !pdf.is_finite() {
            return None;
        }
        let f = self.eval_with_d(o, i, cos_oh, d);
        let weight = f * (i.z / pdf);
        if !weight.is_finite() {
            return None;
        }
        Some(BsdfSample {
            wi: if below { flip(i) } else { i },
            weight,
            pdf,
            lobe: LobeFlags::GLOSSY_REFLECTION,
            eta: 1.0,
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, _: &BsdfContext) -> f64 {
        let Some((o, i)) = to_upper_pair(wo, wi) else {
            return 0.0;
        };
        let h = (o + i).normalize_or_zero();
        let cos_oh = o.dot(h);
        if !(h.z > 0.0) || !(cos_oh > 0.0) {
            return 0.0;
        }
        let p = self.ndf().pdf_normal(h) / (4.0 * cos_oh);
        if p.is_finite() {
            p
        } else {
            0.0
        }
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
