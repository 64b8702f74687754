//! Cosine-weighted sampling on the side of the outgoing direction, shared by the
//! diffuse-type models (Lambert, Oren–Nayar, the IL body lobe); the warp itself is
//! [`super::warp::square_to_cosine_hemisphere`].

use super::rng::RandomSource;
use super::warp::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};
use super::{flip, Vec3};

/// A cosine-distributed direction on the side of `wo`, with its solid-angle pdf.
pub fn sample_cosine_same_side(wo: Vec3, rng: &mut dyn RandomSource) -> Option<(Vec3, f64)> {
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
