//! The reflection of one patch given its normal distribution  [CCM19 eq. 7]:
//!
//!   f(o, i) = F(o·h) χ⁺(o·h) χ⁺(i·h) D(h) / (4 I(o) I(i)),
//!
//! with I the patch's visible projected area, and its sampling: a normal of D, mirrored,
//! with pdf D(h) cos θ_h / (4 o·h)  [WMLT07 eqs. 14, 38]. Shared by the P-BRDF of a footprint
//! ([`super::GlintBsdf`]) and the one-lobe brute-force reference
//! ([`super::PointReferenceBsdf`]), which differ only in D, its sampler and I.
//!
//! **The sample weight needs no D.** f cos θ_i / pdf = F (o·h) cos θ_i / (I(o) I(i) cos θ_h):
//! D cancels, so a sample is weighted exactly without evaluating D at its half vector —
//! the one query of the footprint's lobes a sample would otherwise cost. D is still needed
//! for the density a sample reports, which only multiple importance sampling reads. Where
//! the caller does not read it ([`BsdfContext::skip_sample_pdf`]) a sample reports the
//! cosine density cos θ_i / π, positive and free (the filtered lobe the proxy below needs
//! cost 3 % of a point-lit render, perf). A model that reports a cheap positive proxy
//! density ([`PatchReflection::proxy_pdf`], with [`Bsdf::pdf_is_exact`] false) reports it
//! in every context: MIS stays unbiased with any weights that sum to one.
//!
//! [`Bsdf::pdf_is_exact`]: crate::bsdf::Bsdf::pdf_is_exact
//! [`BsdfContext::skip_sample_pdf`]: crate::bsdf::BsdfContext::skip_sample_pdf

use crate::bsdf::{BsdfSample, LobeFlags};
use crate::finite::guard;
use crate::fresnel::Fresnel;
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::{reflect, Vec3, PI};

/// What distinguishes one patch model from another.
pub(crate) trait PatchReflection {
    /// D(h) of the patch (0 below the horizon).
    fn d(&self, h: Vec3) -> f64;
    /// A normal drawn from D(m) cos θ_m; `None` when the draw fails.
    fn sample_normal(&self, rng: &mut dyn RandomSource) -> Option<Vec3>;
    /// I(v), the visible projected area, for the view direction (may be cached).
    fn view_area(&self, o: Vec3) -> f64;
    /// I(v) for the light direction.
    fn light_area(&self, i: Vec3) -> f64;
    fn fresnel(&self) -> &Fresnel;
    fn tint(&self) -> Spectrum;
    /// The density `sample` and `pdf` report in place of the sampler's D(h) cos θ_h /
    /// (4 o·h), where the model reports one (for multiple importance sampling): cheap and
    /// positive over the upper hemisphere (module notes). `None`: the sampler's own.
    fn proxy_pdf(&self, _o: Vec3, _i: Vec3, _h: Vec3) -> Option<f64> {
        None
    }
}

/// f for an upper-hemisphere pair given D(h) (the sampler has it already).
pub(crate) fn eval_with_d(
    p: &impl PatchReflection,
    o: Vec3,
    i: Vec3,
    cos_oh: f64,
    d: f64,
) -> Spectrum {
    if !(d > 0.0) {
        return Spectrum::ZERO;
    }
    let (io, ii) = (p.view_area(o), p.light_area(i));
    if !(io > 0.0 && ii > 0.0) {
        return Spectrum::ZERO;
    }
    let v = guard(d / (4.0 * io * ii), || {
        format!("glint patch reflection at o = {o:?}, i = {i:?}: D = {d}, I(o) = {io}, I(i) = {ii}")
    });
    p.tint() * p.fresnel().eval(cos_oh) * v
}

/// f(o, i) for an upper-hemisphere pair.
pub(crate) fn eval(p: &impl PatchReflection, o: Vec3, i: Vec3) -> Spectrum {
    let h = (o + i).normalize_or_zero();
    let cos_oh = o.dot(h);
    if !(h.z > 0.0) || !(cos_oh > 0.0) || !(i.dot(h) > 0.0) {
        return Spectrum::ZERO;
    }
    eval_with_d(p, o, i, cos_oh, p.d(h))
}

/// A sample: a normal of D mirrored, weighted without D (module notes); its reported
/// density is the model's proxy where the model reports one, else cos θ_i / π where
/// `pdf_read` is false, else the sampler's own (one D query).
pub(crate) fn sample(
    p: &impl PatchReflection,
    wo: Vec3,
    pdf_read: bool,
    rng: &mut dyn RandomSource,
) -> Option<BsdfSample> {
    if !wo.is_finite() {
        return None;
    }
    let o = wo;
    let m = p.sample_normal(rng)?;
    if !(o.dot(m) > 0.0) {
        return None;
    }
    let i = reflect(o, m).normalize();
    if !(i.z > 0.0) {
        return None;
    }
    let h = (o + i).normalize();
    let cos_oh = o.dot(h);
    if !(cos_oh > 0.0) || !(i.dot(h) > 0.0) || !(h.z > 0.0) {
        return None;
    }
    let pdf = match p.proxy_pdf(o, i, h) {
        Some(proxy) => proxy,
        // Nobody reads it: the cosine density, positive here (i.z > 0) and free.
        None if !pdf_read => i.z / PI,
        None => p.d(h) * h.z / (4.0 * cos_oh),
    };
    if !(pdf > 0.0) || !pdf.is_finite() {
        return None;
    }
    let (io, ii) = (p.view_area(o), p.light_area(i));
    if !(io > 0.0 && ii > 0.0) {
        return None;
    }
    // f cos θ_i / pdf with D cancelled  [CCM19 eq. 7; WMLT07 eqs. 14, 38].
    let weight = p.tint() * p.fresnel().eval(cos_oh) * (cos_oh * i.z / (io * ii * h.z));
    if !weight.is_finite() {
        return None;
    }
    Some(BsdfSample {
        wi: i,
        weight,
        pdf,
        lobe: LobeFlags::GLOSSY_REFLECTION,
        eta: 1.0,
    })
}

/// The density [`sample`] reports for an upper-hemisphere pair: the model's proxy where it
/// reports one, else [`sampler_pdf`].
pub(crate) fn pdf(p: &impl PatchReflection, o: Vec3, i: Vec3) -> f64 {
    let h = (o + i).normalize_or_zero();
    let cos_oh = o.dot(h);
    if !(h.z > 0.0) || !(cos_oh > 0.0) {
        return 0.0;
    }
    match p.proxy_pdf(o, i, h) {
        Some(v) => guard(v, || format!("glint MIS proxy pdf at o = {o:?}, i = {i:?}")),
        None => sampler_pdf(p, o, i),
    }
}

/// The density with which [`sample`] draws `i` (solid angle), whatever the model reports.
pub(crate) fn sampler_pdf(p: &impl PatchReflection, o: Vec3, i: Vec3) -> f64 {
    let h = (o + i).normalize_or_zero();
    let cos_oh = o.dot(h);
    if !(h.z > 0.0) || !(cos_oh > 0.0) {
        return 0.0;
    }
    let v = p.d(h) * h.z / (4.0 * cos_oh);
    guard(v, || format!("glint patch pdf at o = {o:?}, i = {i:?}"))
}
