//! Glints from high-definition normal maps  [CCM19]: the normal map approximated by a
//! mixture of non-centred anisotropic Beckmann lobes, the patch NDF of a ray footprint,
//! exact patch masking and projected area (and their mip-mapped approximation), the P-BRDF
//! with a conductor Fresnel term, and its exact importance sampling.
//!
//! One concept per file:
//! - [`normal_map`]: tangent-space maps as periodic slope fields, decoded and validated
//!   from pixels (the caller reads the image file: this crate does not depend on the
//!   renderer);
//! - [`generate`]: the procedural maps of CCM19 Fig. 7 (scratched, brushed, bumpy,
//!   flakes);
//! - [`lobe`]: one non-centred correlated Beckmann lobe and its closed-form masking
//!   (ERRATA 15);
//! - [`microsurface`]: seeds and lobe moments (CCM19 §3, ERRATA 14);
//! - [`hierarchy`]: the (u, slope) bounding-box tree of §5;
//! - [`lobe_blocks`]: the lobes stored by leaf block, in lanes (the query's inner loop);
//! - [`mip_levels`]: the moment pyramid of §4.2.2;
//! - [`footprint`]: the Gaussian footprint k_P and the weights W_i;
//! - [`patch_ndf`]: D_P (eq. 9) and its sampler;
//! - [`patch_masking`]: exact (eqs. 10–17) and approximate (§4.2.2) masking;
//! - [`surface`]: the precomputed data of one map, shared by every shading point;
//! - [`patch_reflection`]: eq. 7 and its sampling given a patch's D and projected area;
//! - [`glint_bsdf`]: the P-BRDF (eq. 7) implementing [`crate::Bsdf`];
//! - [`reference`]: the ground-truth slope histogram of a footprint;
//! - [`point_reference`]: the brute-force reference BSDF (the map at one point, σ_ε).
//!
//! Units: positions on the map in texels (texel centres at half-integers), slopes
//! unitless, footprints as covariances in texels².

pub mod footprint;
pub mod generate;
pub mod glint_bsdf;
pub mod hierarchy;
pub mod lobe;
pub mod lobe_blocks;
pub mod microsurface;
pub mod mip_levels;
pub mod normal_map;
pub mod patch_masking;
pub mod patch_ndf;
mod patch_reflection;
pub mod point_reference;
pub mod reference;
pub mod surface;

pub use footprint::Footprint;
pub use generate::{generate, NormalMapKind};
pub use glint_bsdf::{GlintBsdf, GlintParams, MisPdf};
pub use normal_map::{NormalEncoding, NormalMap};
pub use patch_masking::MaskingMode;
pub use point_reference::PointReferenceBsdf;
pub use surface::GlintSurface;
