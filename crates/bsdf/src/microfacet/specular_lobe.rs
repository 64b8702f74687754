//! The specular microfacet reflection lobe — one piece of code shared by the rough
//! conductor, the rough dielectric's reflection, and the surface term of interfaced
//! Lambertian: f_s(i, o) = F(i, h) D(h) G(i, o, h) / (4 |i·n| |o·n|)  [WMLT07 eq. 20;
//! IL18 eq. 4], sampled through a microfacet normal and the reflection Jacobian
//! 1/(4 |o·h|)  [WMLT07 eqs. 14, 38].
//!
//! The lobe works in the upper hemisphere (o·n > 0 and i·n > 0); models flip both
//! directions for the back side.

use super::{Distribution, Masking, Ndf};
use crate::error::{ParamError, ParamResult};
use crate::math::spectrum::Spectrum;
use crate::math::{reflect, Vec2, Vec3};

/// Which normals a lobe samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NormalSampling {
    /// The distribution of visible normals (Heitz 2018; lower variance). Falls back to
    /// `Distribution` for distributions without an exact visible-normal sampler.
    Visible,
    /// The papers' D(m)|m·n| sampling [WMLT07 eq. 24] (a GGX proposal for the Gaussian).
    Distribution,
}

impl NormalSampling {
    pub const NAMES: &'static [&'static str] = &["visible", "distribution"];

    pub fn parse(s: &str) -> ParamResult<Self> {
        match s {
            "visible" | "vndf" => Ok(NormalSampling::Visible),
            "distribution" | "ndf" => Ok(NormalSampling::Distribution),
            other => Err(ParamError::UnknownChoice {
                what: "sampling".into(),
                given: other.into(),
                valid: Self::NAMES.join(", "),
            }),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            NormalSampling::Visible => "visible",
            NormalSampling::Distribution => "distribution",
        }
    }
}

/// A microfacet distribution with its masking and normal sampler.
#[derive(Clone, Debug)]
pub struct SpecularLobe {
    pub ndf: Ndf,
    pub masking: Masking,
    sampling: NormalSampling,
}

impl SpecularLobe {
    /// Rejects masking forms that the distribution cannot support (Smith with the Gaussian,
    /// whose Λ diverges).
    pub fn new(ndf: Ndf, masking: Masking, sampling: NormalSampling) -> ParamResult<Self> {
        if masking.is_smith() && !ndf.supports_smith() {
            return Err(ParamError::Invalid(format!(
                "masking `{}` is not defined for the gaussian distribution: its Smith Λ \
                 diverges (IL18 eq. 14 has infinite microsurface area). Use masking = \
                 \"v-cavity\" (IL18 Table 2), or distribution = \"beckmann\" with alpha = \
                 √2·sigma (IL18 §3.2)",
                masking.name()
            )));
        }
        let sampling = if ndf.has_visible_sampling() {
            sampling
        } else {
            NormalSampling::Distribution
        };
        Ok(SpecularLobe {
            ndf,
            masking,
            sampling,
        })
    }

    /// The sampler in effect (visible sampling falls back where unsupported).
    pub fn sampling(&self) -> NormalSampling {
        self.sampling
    }

    /// Draws a microfacet normal for the view direction `wo` (wo·n > 0).
    #[inline]
    pub fn sample_normal(&self, wo: Vec3, u: Vec2) -> Vec3 {
        match self.sampling {
            NormalSampling::Visible => self.ndf.sample_visible(wo, u),
            NormalSampling::Distribution => self.ndf.sample_normal(u),
        }
    }

    /// Density of [`SpecularLobe::sample_normal`].
    #[inline]
    pub fn normal_pdf(&self, wo: Vec3, m: Vec3) -> f64 {
        match self.sampling {
            NormalSampling::Visible => self.ndf.pdf_visible(wo, m),
            NormalSampling::Distribution => self.ndf.pdf_normal(m),
        }
    }

    /// D(h) G(i, o, h) / (4 |i·n| |o·n|): the lobe without its Fresnel factor, for a
    /// reflection pair in the upper hemisphere; also returns h and |o·h|.
    #[inline]
    pub fn geometry(&self, wo: Vec3, wi: Vec3) -> Option<(f64, Vec3, f64)> {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return None;
        }
        let h = (wo + wi).normalize_or_zero();
        if h == Vec3::ZERO || h.z <= 0.0 {
            return None;
        }
        let d = self.ndf.d(h);
        if d == 0.0 {
            return Some((0.0, h, wo.dot(h)));
        }
        let g = self.masking.g(&self.ndf, wi, wo, h);
        Some((d * g / (4.0 * wo.z * wi.z), h, wo.dot(h)))
    }

    /// f_s(wi, wo) with a Fresnel term evaluated at cos = |o·h|.
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3, fresnel: impl Fn(f64) -> Spectrum) -> Spectrum {
        match self.geometry(wo, wi) {
            Some((v, _, cos_oh)) if v > 0.0 => fresnel(cos_oh) * v,
            _ => Spectrum::ZERO,
        }
    }

    /// Samples a reflected direction: returns (wi, h, pdf of wi) or `None` when the
    /// reflection falls below the horizon.
    #[inline]
    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<(Vec3, Vec3, f64)> {
        if wo.z <= 0.0 {
            return None;
        }
        let m = self.sample_normal(wo, u);
        let cos_om = wo.dot(m);
        if cos_om <= 0.0 {
            return None;
        }
        let wi = reflect(wo, m);
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = self.normal_pdf(wo, m) / (4.0 * cos_om);
        if !(pdf > 0.0) || !pdf.is_finite() {
            return None;
        }
        Some((wi, m, pdf))
    }

    /// Density of [`SpecularLobe::sample`] for the pair (wo, wi).
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f64 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let h = (wo + wi).normalize_or_zero();
        let cos_oh = wo.dot(h);
        if h.z <= 0.0 || cos_oh <= 0.0 {
            return 0.0;
        }
        self.normal_pdf(wo, h) / (4.0 * cos_oh)
    }

    /// Roughness scale of the lobe (for validation bins).
    pub fn typical_width(&self) -> f64 {
        self.ndf.typical_width()
    }
}
