//! Half-vector densities P_H(H) of KSK01 §2.1.2, used by the coupled specular-matte model's
//! specular term f = P_H(H) F / (2 (1 + L·V))  [KSK01 eq. 3].
//!
//! | name | P_H(H) | sampler |
//! |---|---|---|
//! | `ward` | e^{−tan²α/m²} / (π m² cos³α)  [KSK01 eq. 4] | α = arctan(m √(−ln(1−u))), φ = 2πv (exact) |
//! | `beckmann` | e^{−tan²α/m²} / (π m² cos⁴α) (KSK01 §2.1.2; the text drops the π) | the Ward sampler, pdf = P_H cos α |
//! | `phong` | (n + 1)/(2π) cos^n α  [KSK01 eq. 5] | α = arccos u^{1/(n+1)} (exact) |
//!
//! α is the angle between N and H. Ward's density is a probability density of H (it is
//! Beckmann's D(H) cos α); KSK01's Beckmann P_H is D(H) itself, which is not a density —
//! its integral over the hemisphere exceeds 1 — so it is sampled with the Ward density and
//! weighted. The printed Beckmann density lacks the 1/π of the normalized Beckmann D; we
//! keep the normalized form (with 1/π the model's albedo stays below one).

use crate::checks::{check_alpha, check_range, Bounds};
use crate::error::{ParamError, ParamResult};
use crate::math::{Vec2, Vec3, PI, TWO_PI};

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HalfVectorDensity {
    Ward { m: f64 },
    Beckmann { m: f64 },
    Phong { n: f64 },
}

/// The narrowest RMS slope used (a narrower `alpha` is widened to it).
pub const MIN_SLOPE: f64 = 1e-4;

impl HalfVectorDensity {
    pub const NAMES: &'static [&'static str] = &["ward", "beckmann", "phong"];

    /// Builds a density from its name and roughness: `m` (RMS slope) for Ward and Beckmann,
    /// the exponent `n` for Phong.
    pub fn new(name: &str, roughness: f64) -> ParamResult<Self> {
        match name {
            // Widths below MIN_SLOPE are taken as MIN_SLOPE: m² of a subnormal width is 0
            // and the density 0/0 (the microfacet recipes widen below 1e-4 the same way).
            "ward" => Ok(HalfVectorDensity::Ward {
                m: check_alpha("alpha", roughness)?.max(MIN_SLOPE),
            }),
            "beckmann" => Ok(HalfVectorDensity::Beckmann {
                m: check_alpha("alpha", roughness)?.max(MIN_SLOPE),
            }),
            "phong" => Ok(HalfVectorDensity::Phong {
                n: check_range("exponent", roughness, 0.0, 1e7, Bounds::Closed)?,
            }),
            other => Err(ParamError::UnknownChoice {
                what: "half-vector density".into(),
                given: other.into(),
                valid: Self::NAMES.join(", "),
            }),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            HalfVectorDensity::Ward { .. } => "ward",
            HalfVectorDensity::Beckmann { .. } => "beckmann",
            HalfVectorDensity::Phong { .. } => "phong",
        }
    }

    /// P_H(H) for H in the upper hemisphere.
    #[inline]
    pub fn density(&self, h: Vec3) -> f64 {
        if h.z <= 0.0 {
            return 0.0;
        }
        match *self {
            HalfVectorDensity::Ward { m } => beckmann_d(h, m) * h.z,
            HalfVectorDensity::Beckmann { m } => beckmann_d(h, m),
            HalfVectorDensity::Phong { n } => (n + 1.0) / TWO_PI * h.z.powf(n),
        }
    }

    /// Draws H from the density's sampler.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Vec3 {
        let (ct, st) = match *self {
            // α = arctan(m √(−log(1−u)))  [KSK01 §2.1.2; ERRATA 13 keeps (1−u)].
            HalfVectorDensity::Ward { m } | HalfVectorDensity::Beckmann { m } => {
                let t = m * (-(1.0 - u.x).ln()).sqrt();
                let ct = 1.0 / (1.0 + t * t).sqrt();
                (ct, t * ct)
            }
            // α = arccos u^{1/(n+1)}  [KSK01 §2.1.2].
            HalfVectorDensity::Phong { n } => {
                let ct = u.x.powf(1.0 / (n + 1.0));
                (ct, (1.0 - ct * ct).max(0.0).sqrt())
            }
        };
        let (s, c) = (TWO_PI * u.y).sin_cos();
        Vec3::new(st * c, st * s, ct)
    }

    /// Density (solid angle of H) of [`HalfVectorDensity::sample`].
    #[inline]
    pub fn sample_pdf(&self, h: Vec3) -> f64 {
        match *self {
            HalfVectorDensity::Beckmann { m } => {
                if h.z <= 0.0 {
                    0.0
                } else {
                    beckmann_d(h, m) * h.z
                }
            }
            _ => self.density(h),
        }
    }

    /// Representative angular width, for numerical integration and validation bins.
    pub fn typical_width(&self) -> f64 {
        match *self {
            HalfVectorDensity::Ward { m } | HalfVectorDensity::Beckmann { m } => m,
            HalfVectorDensity::Phong { n } => (2.0 / (n + 2.0)).sqrt(),
        }
    }
}

#[inline]
fn beckmann_d(h: Vec3, m: f64) -> f64 {
    let z2 = h.z * h.z;
    if z2 * z2 < 1e-300 {
        return 0.0;
    }
    let t2 = (h.x * h.x + h.y * h.y) / z2;
    (-t2 / (m * m)).exp() / (PI * m * m * z2 * z2)
}
