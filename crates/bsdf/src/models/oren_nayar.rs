//! Oren–Nayar: rough surfaces of Lambertian microfacets, twice.
//!
//! - [`OrenNayarExact`]: the single-scattering microfacet integral of IL18 eq. 3 with
//!   Lambertian facets (f^μ = K_d/π), the Gaussian distribution of IL18 eq. 14 and the
//!   V-cavity masking of IL18 eq. 15 — interfaced Lambertian with n_i = 1 (IL18 §3.2,
//!   TSBRM eq. 27), evaluated by the shared [`MicrofacetIntegral`].
//! - [`OrenNayarQualitative`]: Oren & Nayar's qualitative model (SIGGRAPH 1994, eq. 30):
//!   f = ρ/π (A + B max(0, cos(φ_i − φ_o)) sin α tan β), A = 1 − 0.5σ²/(σ² + 0.33),
//!   B = 0.45σ²/(σ² + 0.09), α = max(θ_i, θ_o), β = min(θ_i, θ_o) — or, with `model = "l1"`,
//!   their fuller approximation of the same single-scattering term (L1, coefficients C1–C3;
//!   [`oren_nayar_l1_factor`]).
//!
//! | key | meaning | range | default |
//! |---|---|---|---|
//! | `reflectance` | facet albedo K_d (number or RGB) | [0, 1] | 0.5 |
//! | `sigma` | Gaussian roughness, radians | (0, π/2) (0 = Lambert) | required |
//! | `model` | `exact`, `qualitative` or `l1` | — | `exact` |
//! | `evaluation` | exact only: `stochastic` (one microfacet per call, unbiased) or `quadrature` (deterministic: adaptive to `tolerance`, or N microfacets with `samples`) | — | `quadrature` |
//! | `tolerance` | exact, quadrature: relative tolerance of the adaptive quadrature | [1e-12, 0.1] | 1e-6 |
//! | `samples` | exact, quadrature: a fixed set of N microfacets per evaluation | ≥ 8 | 256 when none of `evaluation`, `tolerance`, `samples` is given |

use crate::bsdf::{BsdfContext, BsdfSample, LobeFlags};
use crate::checks::{check_min_count, check_range, check_reflectance, Bounds};
use crate::error::ParamResult;
use crate::finite::guard;
use crate::math::cosine_lobe::sample_cosine_same_side;
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::warp::cosine_hemisphere_pdf;
use crate::math::{fmt_num, Vec3, INV_PI, PI};
use crate::microfacet::integral::{check_tolerance, FrozenFacets, MicrofacetIntegral};
use crate::microfacet::{Gaussian, Masking, Ndf};
use crate::two_sided::OpaqueBsdf;
use std::sync::Arc;

/// The stream of the model's fixed quadrature set (the IL body uses stream 1).
const QUADRATURE_STREAM: u64 = 0;

/// How a model estimates its microfacet integral.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IntegralEvaluation {
    /// One microfacet per evaluation: unbiased, noisy, what a path tracer uses.
    Stochastic,
    /// A fixed set of N microfacets (randomized QMC frozen at construction): deterministic,
    /// exactly reciprocal, with a standard error.
    Quadrature { samples: usize },
    /// Adaptive Gauss–Kronrod quadrature to a relative tolerance, with its error estimate:
    /// deterministic, exactly reciprocal.
    Adaptive { tolerance: f64 },
}

impl IntegralEvaluation {
    pub const NAMES: &'static [&'static str] = &["stochastic", "quadrature"];
}

#[derive(Clone, Debug)]
pub struct OrenNayarExact {
    reflectance: Spectrum,
    sigma: f64,
    integral: MicrofacetIntegral,
    evaluation: IntegralEvaluation,
    /// The fixed point set of `evaluation = "quadrature"` with `samples`, drawn once (up to
    /// [`FrozenFacets::MAX_NORMALS`]).
    frozen: Option<Arc<FrozenFacets>>,
}

impl OrenNayarExact {
    pub fn new(
        reflectance: Spectrum,
        sigma: f64,
        evaluation: IntegralEvaluation,
    ) -> ParamResult<Self> {
        check_reflectance("reflectance", reflectance)?;
        check_range("sigma", sigma, 0.0, 0.5 * PI, Bounds::Open)?;
        if let IntegralEvaluation::Quadrature { samples } = evaluation {
            check_min_count("samples", samples, 8)?;
        }
        if let IntegralEvaluation::Adaptive { tolerance } = evaluation {
            check_tolerance(tolerance)?;
        }
        let integral =
            MicrofacetIntegral::new(Ndf::Gaussian(Gaussian::new(sigma)?), Masking::VCavity)?;
        let frozen = match evaluation {
            IntegralEvaluation::Quadrature { samples } => {
                integral.freeze(samples, QUADRATURE_STREAM)
            }
            _ => None,
        };
        Ok(OrenNayarExact {
            reflectance,
            sigma,
            integral,
            evaluation,
            frozen,
        })
    }

    /// The microfacet integral ∫ D G |im||om|/(|in||on|) dω (without K_d/π) [IL18 eq. 3]
    /// and its standard error or quadrature error estimate.
    fn integral_value(&self, i: Vec3, o: Vec3, rng: &mut dyn RandomSource) -> (f64, f64) {
        match self.evaluation {
            IntegralEvaluation::Stochastic => (
                self.integral.estimate_one(i, o, rng.next_2d(), |_| 1.0),
                0.0,
            ),
            IntegralEvaluation::Quadrature { samples } => self.integral.estimate_fixed(
                self.frozen.as_deref(),
                samples,
                QUADRATURE_STREAM,
                i,
                o,
                |_| 1.0,
            ),
            IntegralEvaluation::Adaptive { tolerance } => {
                let q = self.integral.integrate(i, o, tolerance, |_| 1.0);
                (q.value, q.error)
            }
        }
    }
}

impl OpaqueBsdf for OrenNayarExact {
    fn flags(&self) -> LobeFlags {
        LobeFlags::DIFFUSE_REFLECTION
    }

    fn is_stochastic(&self) -> bool {
        self.evaluation == IntegralEvaluation::Stochastic
    }

    fn eval(&self, wo: Vec3, wi: Vec3, _: &BsdfContext, rng: &mut dyn RandomSource) -> Spectrum {
        self.reflectance * (INV_PI * self.integral_value(wi, wo, rng).0)
    }

    fn eval_estimate(
        &self,
        wo: Vec3,
        wi: Vec3,
        ctx: &BsdfContext,
        samples: usize,
        rng: &mut dyn RandomSource,
    ) -> (Spectrum, Spectrum) {
        let (o, i) = (wo, wi);
        let (v, se) = match self.evaluation {
            IntegralEvaluation::Quadrature { .. } | IntegralEvaluation::Adaptive { .. } => {
                self.integral_value(i, o, rng)
            }
            IntegralEvaluation::Stochastic => {
                let (m, se) = crate::bsdf::mean_and_stderr(samples, || {
                    Spectrum::splat(self.integral.estimate_one(i, o, rng.next_2d(), |_| 1.0))
                });
                (m[0], se[0])
            }
        };
        let _ = ctx;
        (
            self.reflectance * (INV_PI * v),
            self.reflectance * (INV_PI * se),
        )
    }

    fn sample(
        &self,
        wo: Vec3,
        ctx: &BsdfContext,
        rng: &mut dyn RandomSource,
    ) -> Option<BsdfSample> {
        sample_diffuse_reflection(self, wo, ctx, rng)
    }

    fn pdf(&self, _: Vec3, wi: Vec3, _: &BsdfContext) -> f64 {
        cosine_hemisphere_pdf(wi)
    }

    fn describe(&self) -> String {
        let e = match self.evaluation {
            IntegralEvaluation::Stochastic => "stochastic".to_string(),
            IntegralEvaluation::Quadrature { samples } => format!("quadrature {samples}"),
            IntegralEvaluation::Adaptive { tolerance } => {
                format!("quadrature tolerance {}", fmt_num(tolerance))
            }
        };
        format!(
            "oren-nayar exact(reflectance={:?}, sigma={}, {e})",
            self.reflectance.0,
            fmt_num(self.sigma)
        )
    }
}

/// A diffuse-reflection sample of `bsdf` drawn with the cosine lobe, weighted
/// f·|cos θ_i|/pdf with f from `bsdf.eval` (which may be a stochastic estimate).
fn sample_diffuse_reflection(
    bsdf: &dyn OpaqueBsdf,
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

/// The scalar factor of Oren & Nayar's L1 model (single scattering, SIGGRAPH 1994, their
/// eq. 26 with the coefficients C1–C3): f·π/ρ = C1 + cos Δφ C2 tan β + (1 − |cos Δφ|) C3
/// tan((α + β)/2), for i and o in the upper hemisphere. `c` scales (C1's σ term, C2, C3):
/// (1, 1, 1) is Oren & Nayar's Gaussian model; the IL approximation fits other values for
/// Beckmann facets.
pub fn oren_nayar_l1_factor(sigma: f64, c: [f64; 3], i: Vec3, o: Vec3) -> f64 {
    let s2 = sigma * sigma;
    let (ti, to) = (i.z.clamp(-1.0, 1.0).acos(), o.z.clamp(-1.0, 1.0).acos());
    let (alpha, beta) = (ti.max(to), ti.min(to));
    let (si, so) = (
        (1.0 - i.z * i.z).max(0.0).sqrt(),
        (1.0 - o.z * o.z).max(0.0).sqrt(),
    );
    let cos_dphi = if si > 1e-12 && so > 1e-12 {
        ((i.x * o.x + i.y * o.y) / (si * so)).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let c1 = 1.0 - c[0] * 0.5 * s2 / (s2 + 0.33);
    let k = 0.45 * s2 / (s2 + 0.09);
    let c2 = c[1]
        * if cos_dphi >= 0.0 {
            k * alpha.sin()
        } else {
            k * (alpha.sin() - (2.0 * beta / PI).powi(3))
        };
    let c3 = c[2] * 0.125 * (s2 / (s2 + 0.09)) * (4.0 * alpha * beta / (PI * PI)).powi(2);
    let tan_b = beta.tan();
    let tan_ab = (0.5 * (alpha + beta)).tan();
    let v = c1 + cos_dphi * c2 * tan_b + (1.0 - cos_dphi.abs()) * c3 * tan_ab;
    guard(v, || {
        format!("Oren–Nayar L1 factor (sigma = {sigma}, c = {c:?}) at i = {i:?}, o = {o:?}")
    })
    .max(0.0)
}

#[derive(Clone, Debug)]
pub struct OrenNayarQualitative {
    reflectance: Spectrum,
    sigma: f64,
    a: f64,
    b: f64,
    /// Use the L1 model instead of the qualitative one.
    l1: bool,
}

impl OrenNayarQualitative {
    pub fn new(reflectance: Spectrum, sigma: f64) -> ParamResult<Self> {
        check_reflectance("reflectance", reflectance)?;
        check_range("sigma", sigma, 0.0, 0.5 * PI, Bounds::ClosedOpen)?;
        let s2 = sigma * sigma;
        Ok(OrenNayarQualitative {
            reflectance,
            sigma,
            a: 1.0 - 0.5 * s2 / (s2 + 0.33),
            b: 0.45 * s2 / (s2 + 0.09),
            l1: false,
        })
    }

    /// Oren & Nayar's L1 model (C1–C3) instead of the qualitative one.
    pub fn l1(reflectance: Spectrum, sigma: f64) -> ParamResult<Self> {
        let mut m = Self::new(reflectance, sigma)?;
        m.l1 = true;
        Ok(m)
    }

    /// The scalar factor A + B max(0, cos Δφ) sin α tan β, for i and o in the upper
    /// hemisphere.
    pub fn factor(&self, i: Vec3, o: Vec3) -> f64 {
        if self.l1 {
            return oren_nayar_l1_factor(self.sigma, [1.0; 3], i, o);
        }
        let (si, so) = (
            (1.0 - i.z * i.z).max(0.0).sqrt(),
            (1.0 - o.z * o.z).max(0.0).sqrt(),
        );
        let cos_dphi = if si > 1e-12 && so > 1e-12 {
            ((i.x * o.x + i.y * o.y) / (si * so)).clamp(-1.0, 1.0)
        } else {
            0.0
        };
        // α = max(θ_i, θ_o) has the smaller cosine; β = min(θ_i, θ_o) the larger.
        let (sin_alpha, sin_beta, cos_beta) = if i.z < o.z {
            (si, so, o.z)
        } else {
            (so, si, i.z)
        };
        let tan_beta = if cos_beta > 0.0 {
            sin_beta / cos_beta
        } else {
            0.0
        };
        self.a + self.b * cos_dphi.max(0.0) * sin_alpha * tan_beta
    }
}

impl OpaqueBsdf for OrenNayarQualitative {
    fn flags(&self) -> LobeFlags {
        LobeFlags::DIFFUSE_REFLECTION
    }

    fn eval(&self, wo: Vec3, wi: Vec3, _: &BsdfContext, _: &mut dyn RandomSource) -> Spectrum {
        self.reflectance * (INV_PI * self.factor(wi, wo))
    }

    fn sample(
        &self,
        wo: Vec3,
        ctx: &BsdfContext,
        rng: &mut dyn RandomSource,
    ) -> Option<BsdfSample> {
        sample_diffuse_reflection(self, wo, ctx, rng)
    }

    fn pdf(&self, _: Vec3, wi: Vec3, _: &BsdfContext) -> f64 {
        cosine_hemisphere_pdf(wi)
    }

    fn describe(&self) -> String {
        format!(
            "oren-nayar {}(reflectance={:?}, sigma={})",
            if self.l1 { "l1" } else { "qualitative" },
            self.reflectance.0,
            fmt_num(self.sigma)
        )
    }
}
