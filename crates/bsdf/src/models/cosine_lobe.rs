//! Cosine-weighted sampling on the side of the outgoing direction, shared by the
//! diffuse-type models (Lambert, Oren–Nayar, the IL body lobe).

use super::{flip, to_upper_pair};
use crate::bsdf::{Bsdf, BsdfContext, BsdfSample, LobeFlags};
use crate::math::rng::RandomSource;
use crate::math::warp::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};
use crate::math::Vec3;

/// A cosine-distributed direction on the side of `wo`, with its solid-angle pdf.
pub(crate) fn sample_cosine_same_side(wo: Vec3, rng: &mut dyn RandomSource) -> Option<(Vec3, f64)> {
    if wo.z == 0.0 {
        return None;
    }
    let wi = square_to_cosine_hemisphere(rng.next_2d());
    if wi.z <= 0.0 {
        return None;
    }
    let pdf = cosine_hemisphere_pdf(wi);
    Some((if wo.z < 0.0 { flip(wi) } else { wi }, pdf))
}

/// The density of [`sample_cosine_same_side`]: |cos θ_i|/π when both directions are on the
/// same side, 0 otherwise.
pub(crate) fn cosine_same_side_pdf(wo: Vec3, wi: Vec3) -> f64 {
    match to_upper_pair(wo, wi) {
        Some((_, wi)) => cosine_hemisphere_pdf(wi),
        None => 0.0,
    }
}

/// A diffuse-reflection sample of `bsdf` drawn with the cosine lobe, weighted
/// f·|cos θ_i|/pdf with f from `bsdf.eval` (which may be a stochastic estimate).
pub(crate) fn sample_diffuse_reflection(
    bsdf: &dyn Bsdf,
    wo: Vec3,
    ctx: &BsdfContext,
    rng: &mut dyn RandomSource,
) -> Option<BsdfSample> {
    let (wi, pdf) = sample_cosine_same_side(wo, rng)?;
    let f = bsdf.eval(wo, wi, ctx, rng);
    Some(BsdfSample {
        wi,
        weight: f * (wi.z.abs() / pdf),
        pdf,
        lobe: LobeFlags::DIFFUSE_REFLECTION,
        eta: 1.0,
    })
}
