//! The approximate closed form of the interfaced-Lambertian body term  [IL18 §4.2].
//!
//! IL18's appendix, with its rational coefficient functions, is not in our text (ERRATA 1),
//! so this module keeps the published *structure* and exact limits and ships coefficients
//! fitted by facette itself (`facette il-approx fit`, in the lab crate):
//!
//!   f_b ≈ 1/(n_i² (1 − K_d r_i)) · T̄(i) T̄(o) · F_a            [IL18 eq. 32]
//!   T̄(u) = a T(u, n) + b t₀₁,  t₀₁ = 1 − r_e                    [IL18 eq. 33]
//!   F_a = (1 + max(−1, c F'_a)) f_a,
//!   F'_a = −r_e (1 − |i·n|)² (1 − |o·n|)² min(0, −H),  H = d (cos φ_i cos φ_o + sin φ_i sin φ_o)
//!
//! with, for isotropic distributions, d_xy = d_yx = d, so that c and d enter only through
//! k = c·d: the grazing factor is 1 + max(−1, k r_e (1 − μ_i)²(1 − μ_o)² max(0, cos Δφ)).
//! f_a is Oren & Nayar's approximate L1 model (SIGGRAPH 1994, the single-scattering term with
//! its coefficients C1–C3; see [`super::oren_nayar::oren_nayar_l1_factor`]) — IL18's f_a^g —
//! exactly for the Gaussian distribution, and for Beckmann the same form with the scales of
//! C1's σ term, C2 and C3 fitted to Lambertian facets (n_i = 1) with the chosen masking —
//! IL18's f_a^{ab}.
//!
//! a, b, k (and Beckmann's A, B) are fitted per node of a (σ, n_i) grid against the
//! quadrature body term (log-error least squares over θ_i, θ_o ∈ {0, 10, …, 80}°,
//! Δφ ∈ {0, 45, …, 180}°) and interpolated bilinearly. The limits are exact by construction:
//! σ = 0 gives a = 1, b = 0, k = 0 and f_a = K_d/π, i.e. flat IL (IL18 eq. 9); n_i = 1 gives
//! T = t₀₁ = 1, r_e = 0, so f_b = f_a — Oren & Nayar's L1 model for the Gaussian.
//! σ is the Gaussian roughness in radians; Beckmann materials use σ = α/√2 (IL18 §3.2).
//! The fitted domain is σ ∈ [0, 1.4], n_i ∈ [1, 3], isotropic; other inputs are refused.

use super::il_approx_coefficients as coef;
use crate::error::{ParamError, ParamResult};
use crate::fresnel::fresnel_dielectric;
use crate::math::Vec3;
use crate::microfacet::specular_lobe::SpecularLobe;
use crate::microfacet::{Distribution, Masking, Ndf};
use crate::models::oren_nayar::oren_nayar_l1_factor;

/// Distribution and masking combinations with fitted coefficients.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ApproxFamily {
    GaussianVCavity,
    BeckmannVCavity,
    BeckmannSmith,
}

impl ApproxFamily {
    pub const ALL: [ApproxFamily; 3] = [
        ApproxFamily::GaussianVCavity,
        ApproxFamily::BeckmannVCavity,
        ApproxFamily::BeckmannSmith,
    ];

    pub fn name(&self) -> &'static str {
        match self {
            ApproxFamily::GaussianVCavity => "gaussian/v-cavity",
            ApproxFamily::BeckmannVCavity => "beckmann/v-cavity",
            ApproxFamily::BeckmannSmith => "beckmann/smith",
        }
    }

    fn table(&self) -> &'static [[[f64; 3]; coef::NI_NODES.len()]; coef::SIGMA_NODES.len()] {
        match self {
            ApproxFamily::GaussianVCavity => &coef::GAUSSIAN_VCAVITY,
            ApproxFamily::BeckmannVCavity => &coef::BECKMANN_VCAVITY,
            ApproxFamily::BeckmannSmith => &coef::BECKMANN_SMITH,
        }
    }
}

/// Coefficients of the approximation at one (σ, n_i).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ApproxCoefficients {
    /// Gaussian-equivalent roughness (radians).
    pub sigma: f64,
    pub a: f64,
    pub b: f64,
    pub k: f64,
    /// Scales of Oren–Nayar's L1 coefficients (C1's σ term, C2, C3); (1, 1, 1) is their
    /// Gaussian model.
    pub on: [f64; 3],
}

/// The approximate body integral I ≈ T̄(i) T̄(o) (1 + max(−1, k r_e …)) (A + B …), such that
/// f_b = K_d/(π n_i² (1 − K_d r_i)) · I; i and o in the upper hemisphere.
pub fn approx_integral(c: &ApproxCoefficients, i: Vec3, o: Vec3, ni: f64, re: f64) -> f64 {
    let t01 = 1.0 - re;
    let tbar = |u: Vec3| c.a * (1.0 - fresnel_dielectric(u.z, ni)) + c.b * t01;
    let (si, so) = (
        (1.0 - i.z * i.z).max(0.0).sqrt(),
        (1.0 - o.z * o.z).max(0.0).sqrt(),
    );
    let cos_dphi = if si > 1e-12 && so > 1e-12 {
        ((i.x * o.x + i.y * o.y) / (si * so)).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let fa = oren_nayar_l1_factor(c.sigma, c.on, i, o);
    let grazing = re * (1.0 - i.z).powi(2) * (1.0 - o.z).powi(2) * cos_dphi.max(0.0);
    let corr = 1.0 + (c.k * grazing).max(-1.0);
    (tbar(i) * tbar(o) * corr * fa).max(0.0)
}

/// The approximation for one material.
#[derive(Clone, Debug)]
pub struct IlApprox {
    pub family: ApproxFamily,
    pub sigma: f64,
    pub coefficients: ApproxCoefficients,
}

impl IlApprox {
    /// Looks up the coefficients for the lobe's distribution and masking and index `ni`.
    pub fn new(lobe: &SpecularLobe, ni: f64) -> ParamResult<Self> {
        let (family, sigma) = match (&lobe.ndf, lobe.masking) {
            (Ndf::Gaussian(g), Masking::VCavity) => (ApproxFamily::GaussianVCavity, g.sigma()),
            (Ndf::Beckmann(b), m) if b.alpha_x() == b.alpha_y() => {
                let fam = match m {
                    Masking::VCavity => ApproxFamily::BeckmannVCavity,
                    Masking::SmithSeparable => ApproxFamily::BeckmannSmith,
                    other => {
                        return Err(ParamError::Invalid(format!(
                            "evaluation = \"approx\" is fitted for masking v-cavity and smith, not `{}`",
                            other.name()
                        )))
                    }
                };
                (fam, b.alpha_x() / std::f64::consts::SQRT_2)
            }
            _ => {
                return Err(ParamError::Invalid(format!(
                    "evaluation = \"approx\" is fitted for isotropic gaussian (v-cavity) and beckmann (v-cavity or smith) distributions, not {} with masking {}",
                    lobe.ndf.describe(),
                    lobe.masking.name()
                )))
            }
        };
        Self::for_family(family, sigma, ni)
    }

    /// Coefficients of a family at (σ, n_i), bilinearly interpolated on the fitted grid.
    pub fn for_family(family: ApproxFamily, sigma: f64, ni: f64) -> ParamResult<Self> {
        let smax = *coef::SIGMA_NODES.last().unwrap();
        let nmax = *coef::NI_NODES.last().unwrap();
        if !(0.0..=smax + 1e-12).contains(&sigma) || !(1.0..=nmax + 1e-12).contains(&ni) {
            return Err(ParamError::Invalid(format!(
                "evaluation = \"approx\" is fitted for sigma in [0, {smax}] (beckmann: alpha = √2 sigma) and ni in [1, {nmax}]; got sigma = {}, ni = {}",
                crate::math::fmt_num(sigma),
                crate::math::fmt_num(ni)
            )));
        }
        let (is, ts) = locate(&coef::SIGMA_NODES, sigma);
        let (jn, tn) = locate(&coef::NI_NODES, ni);
        let t = family.table();
        let lerp = |k: usize| {
            let v00 = t[is][jn][k];
            let v01 = t[is][jn + 1][k];
            let v10 = t[is + 1][jn][k];
            let v11 = t[is + 1][jn + 1][k];
            (v00 * (1.0 - tn) + v01 * tn) * (1.0 - ts) + (v10 * (1.0 - tn) + v11 * tn) * ts
        };
        let on = match family {
            ApproxFamily::GaussianVCavity => [1.0, 1.0, 1.0],
            ApproxFamily::BeckmannVCavity | ApproxFamily::BeckmannSmith => {
                let ab = match family {
                    ApproxFamily::BeckmannVCavity => &coef::BECKMANN_VCAVITY_ON,
                    _ => &coef::BECKMANN_SMITH_ON,
                };
                let l = |k: usize| ab[is][k] * (1.0 - ts) + ab[is + 1][k] * ts;
                [l(0), l(1), l(2)]
            }
        };
        Ok(IlApprox {
            family,
            sigma,
            coefficients: ApproxCoefficients {
                sigma,
                a: lerp(0),
                b: lerp(1),
                k: lerp(2),
                on,
            },
        })
    }

    /// The approximate body integral (see [`approx_integral`]).
    pub fn body_integral(&self, i: Vec3, o: Vec3, ni: f64, re: f64) -> f64 {
        approx_integral(&self.coefficients, i, o, ni, re)
    }
}

/// Cell index and fraction of `x` on increasing `nodes`.
fn locate(nodes: &[f64], x: f64) -> (usize, f64) {
    let n = nodes.len();
    let mut k = 0;
    while k + 2 < n && x > nodes[k + 1] {
        k += 1;
    }
    let t = ((x - nodes[k]) / (nodes[k + 1] - nodes[k])).clamp(0.0, 1.0);
    (k, t)
}
