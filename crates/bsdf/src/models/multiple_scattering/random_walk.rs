//! What the two random-walk models ([`MultipleScatteringConductor`] and
//! [`MultipleScatteringDielectric`]) share: the requirements on the single-scattering lobe
//! they extend, and the weight of the cosine density in their MIS proxy density.
//!
//! [`MultipleScatteringConductor`]: super::MultipleScatteringConductor
//! [`MultipleScatteringDielectric`]: super::MultipleScatteringDielectric

use crate::error::{ParamError, ParamResult};
use crate::microfacet::specular_lobe::NormalSampling;
use crate::microfacet::Masking;

/// Share of the cosine density in the MIS proxy: small, so that the proxy follows the
/// compensated model's density, but positive wherever a walk can exit.
pub const PROXY_COSINE_SHARE: f64 = 1e-3;

/// The multiple-scattering models' requirements on the lobe they extend: the walk's first
/// order is the height-correlated Smith masking, and it draws visible normals.
pub fn check_lobe(masking: Masking, sampling: NormalSampling) -> ParamResult<()> {
    if masking != Masking::SmithCorrelated {
        return Err(ParamError::Invalid(format!(
            "scattering = \"multiple\" walks on the Smith microsurface, whose first order is the \
             height-correlated Smith masking: use masking = \"smith-correlated\" (the default \
             with scattering = \"multiple\"), got \"{}\"",
            masking.name()
        )));
    }
    if sampling != NormalSampling::Visible {
        return Err(ParamError::Invalid(
            "scattering = \"multiple\" samples by the random walk, which draws visible normals \
             (HHdD16): `sampling` does not apply, and the distribution needs a visible-normal \
             sampler (beckmann, ggx; phong has none)"
                .into(),
        ));
    }
    Ok(())
}
