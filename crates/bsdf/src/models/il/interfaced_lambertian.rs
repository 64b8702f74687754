//! Interfaced Lambertian microfacets — Simonot's model as rendered by IL18 and TSBRM.
//!
//! Each microfacet is a Lambertian substrate K_d under a flat interface of relative index
//! n_i. A facet reflects specularly, F(i,m) δ/(4|i·h|²)  [IL18 eq. 6], and by its body,
//! f_b^μ = T(i,m) T(o,m) K_d / (π n_i² (1 − K_d r_i))  [IL18 eq. 9], r_i from n_i²(1 − r_i)
//! = 1 − r_e and Molenaar's r_e  [IL18 eqs. 10–11].
//!
//! - **Flat** (σ = 0, `alpha = 0`)  [IL18 §3.1]: a Fresnel delta reflection plus the body term
//!   of eq. 9 with m = n; energy conserving by construction (K_d = 1 reflects exactly 1).
//! - **Rough**  [IL18 §3.2]: the specular lobe of eq. 4 (the shared
//!   [`SpecularLobe`](crate::microfacet::specular_lobe::SpecularLobe) with dielectric
//!   Fresnel n_i) plus the body term of eq. 13,
//!   f_b = K_d/(π n_i² (1 − r_i K_d)) ∫ T(i,m) T(o,m) D G |i·m||o·m|/(|i·n||o·n|) dω_m,
//!   with any distribution and masking of the core (IL18 Table 2).
//!
//! The body integral is evaluated four ways ([`BodyEvaluation`]): *stochastic* — one
//! microfacet per call, unbiased, IL18 eq. 28; *quadrature* — adaptive Gauss–Kronrod over
//! the hemisphere of normals to a relative tolerance, with its error estimate (or, with
//! `samples = N`, N microfacets, TSBRM eq. 37, with their standard error); *table* — TSBRM §4.3's (θ_i, θ_o, φ_o) grid, trilinear; *approx*
//! — the closed form of IL18 §4.2 (see `il_approx`).
//!
//! **Sampling**  [IL18 §4.1]: the specular lobe with probability R_s/(R_s + R_b), R_s = r_e,
//! R_b = (1 − r_e)² K̄_d / (n_i² (1 − K̄_d r_i)) (K̄_d the channel mean); otherwise a
//! cosine-weighted direction. The pdf is exact; the body part of the weight is the
//! (stochastic or deterministic) body estimate, so the weight is unbiased.
//!
//! **Multiple scattering**  [IL18 §3.3]: `scattering = "double"` (IL₂) or `"multiple"`
//! (IL_∞) adds the V-cavity inter-reflections of [`super::vcavity`], estimated without bias
//! by a random walk with next-event estimation (one groove per evaluation); it requires
//! `masking = "v-cavity"` so that every order uses the same microsurface. With
//! [`InterfacedLambertian::with_multiple_quadrature`] (`multiple_evaluation = "quadrature"`)
//! `eval` computes the same orders deterministically, purely specular chains included, by
//! [`super::vcavity_quadrature`]; `sample` keeps the walk.
//!
//! Flat IL is `evaluation`-independent (closed form). IL with n_i = 1 is the exact
//! Oren–Nayar model when the distribution is Gaussian with V-cavity masking.

use super::il_approx::IlApprox;
use super::il_table::BodyTable;
use super::vcavity::{self, IlFacet, Orders};
use super::vcavity_quadrature::VCavityQuadrature;
use crate::bsdf::{BsdfContext, BsdfSample, LobeFlags};
use crate::checks::{check_min_count, check_range, check_reflectance, Bounds};
use crate::error::{ParamError, ParamResult};
use crate::finite::guard;
use crate::fresnel::{
    external_diffuse_reflectance, fresnel_dielectric, internal_diffuse_reflectance,
};
use crate::math::cosine_lobe::sample_cosine_same_side;
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::warp::cosine_hemisphere_pdf;
use crate::math::{fmt_num, Vec3, INV_PI};
use crate::microfacet::integral::{check_tolerance, FrozenFacets, MicrofacetIntegral};
use crate::microfacet::specular_lobe::SpecularLobe;
use crate::microfacet::{Distribution, Masking};
use crate::two_sided::OpaqueBsdf;
use std::sync::Arc;

/// How the body term is evaluated.
#[derive(Clone, Debug)]
pub enum BodyEvaluation {
    /// One microfacet per call [IL18 eq. 28].
    Stochastic,
    /// N microfacets, deterministic [TSBRM eq. 37] (`samples = N`).
    Quadrature { samples: usize },
    /// Adaptive Gauss–Kronrod quadrature of [IL18 eq. 13] to a relative tolerance, with
    /// its error estimate (`evaluation = "quadrature"` without `samples`).
    Adaptive { tolerance: f64 },
    /// The tabulated body integral [TSBRM §4.3].
    Table(Arc<BodyTable>),
    /// The approximate closed form [IL18 §4.2].
    Approx(Arc<IlApprox>),
}

impl BodyEvaluation {
    pub const NAMES: &'static [&'static str] = &["stochastic", "quadrature", "table", "approx"];

    pub fn name(&self) -> &'static str {
        match self {
            BodyEvaluation::Stochastic => "stochastic",
            BodyEvaluation::Quadrature { .. } | BodyEvaluation::Adaptive { .. } => "quadrature",
            BodyEvaluation::Table(_) => "table",
            BodyEvaluation::Approx(_) => "approx",
        }
    }
}

/// Orders of inter-reflection between microfacets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scattering {
    /// IL₁: single scattering (IL18 eq. 3).
    Single,
    /// IL₂: plus paths with two facet interactions.
    Double,
    /// IL_∞: all orders (Russian roulette).
    Multiple,
}

impl Scattering {
    pub const NAMES: &'static [&'static str] = &["single", "double", "multiple"];

    pub fn parse(s: &str) -> ParamResult<Self> {
        match s {
            "single" => Ok(Scattering::Single),
            "double" => Ok(Scattering::Double),
            "multiple" => Ok(Scattering::Multiple),
            other => Err(ParamError::UnknownChoice {
                what: "scattering".into(),
                given: other.into(),
                valid: Self::NAMES.join(", "),
            }),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            Scattering::Single => "single",
            Scattering::Double => "double",
            Scattering::Multiple => "multiple",
        }
    }
}

#[derive(Clone, Debug)]
pub struct InterfacedLambertian {
    kd: Spectrum,
    ni: f64,
    re: f64,
    ri: f64,
    /// K_d/(n_i² (1 − K_d r_i)).
    body_factor: Spectrum,
    /// `None`: flat IL.
    lobe: Option<SpecularLobe>,
    integral: Option<MicrofacetIntegral>,
    evaluation: BodyEvaluation,
    scattering: Scattering,
    /// Probability of sampling the specular lobe (rough IL).
    specular_probability: f64,
    /// Deterministic multiple scattering for `eval` (`multiple_evaluation = "quadrature"`);
    /// `None`: the V-cavity walk. Sampling always uses the walk.
    ms_quadrature: Option<Arc<VCavityQuadrature>>,
    /// The fixed point set of `evaluation = "quadrature"` with `samples`, drawn once (up to
    /// [`FrozenFacets::MAX_NORMALS`]).
    frozen_body: Option<Arc<FrozenFacets>>,
}

/// The stream of the body's fixed quadrature set (exact Oren–Nayar uses stream 0).
const QUADRATURE_STREAM: u64 = 1;

/// K_d/(n_i² (1 − K_d r_i)) per channel: the body's factor in IL18 eq. 13 (r_i the internal
/// diffuse reflectance of the interface).
pub(crate) fn body_factor(kd: Spectrum, ni: f64, ri: f64) -> Spectrum {
    kd.map(|k| k / (ni * ni * (1.0 - k * ri)))
}

/// The probability of sampling the specular lobe of rough IL [IL18 §4.1]: the specular
/// albedo r_e against it plus the body's (1 − r_e)² K̄_d/(n_i² (1 − K̄_d r_i)), K̄_d the
/// channel average.
pub(crate) fn specular_probability(kd: Spectrum, ni: f64, re: f64, ri: f64) -> f64 {
    let kbar = kd.average();
    let rs = re;
    let rb = (1.0 - re) * (1.0 - re) * kbar / (ni * ni * (1.0 - kbar * ri));
    if rs + rb > 0.0 {
        rs / (rs + rb)
    } else {
        1.0
    }
}

impl InterfacedLambertian {
    pub fn new(
        kd: Spectrum,
        ni: f64,
        lobe: Option<SpecularLobe>,
        evaluation: BodyEvaluation,
        scattering: Scattering,
    ) -> ParamResult<Self> {
        check_reflectance("kd", kd)?;
        check_range("ni", ni, 1.0, 10.0, Bounds::Closed)?;
        let re = external_diffuse_reflectance(ni);
        let ri = internal_diffuse_reflectance(ni);
        let body_factor = body_factor(kd, ni, ri);
        if let BodyEvaluation::Quadrature { samples } = evaluation {
            check_min_count("samples", samples, 8)?;
        }
        if let BodyEvaluation::Adaptive { tolerance } = evaluation {
            check_tolerance(tolerance)?;
        }
        let integral = match &lobe {
            Some(l) => Some(MicrofacetIntegral::new(l.ndf.clone(), l.masking)?),
            None => None,
        };
        if scattering != Scattering::Single {
            match &lobe {
                Some(l) if l.masking != Masking::VCavity => {
                    return Err(ParamError::Invalid(format!(
                        "scattering = \"{}\" follows light inside V-cavities (IL18 §3.3): it needs masking = \"v-cavity\" (got \"{}\")",
                        scattering.name(),
                        l.masking.name()
                    )))
                }
                _ => {}
            }
        }
        if let (BodyEvaluation::Table(t), Some(l)) = (&evaluation, &lobe) {
            t.check_matches(ni, l)?;
        }
        let specular_probability = specular_probability(kd, ni, re, ri);
        let frozen_body = match (&evaluation, &integral) {
            (BodyEvaluation::Quadrature { samples }, Some(integral)) => {
                integral.freeze(*samples, QUADRATURE_STREAM)
            }
            _ => None,
        };
        Ok(InterfacedLambertian {
            kd,
            ni,
            re,
            ri,
            body_factor,
            lobe,
            integral,
            evaluation,
            scattering,
            specular_probability,
            ms_quadrature: None,
            frozen_body,
        })
    }

    /// Evaluates the V-cavity multiple scattering (IL_2 / IL_∞) deterministically, by the
    /// quadrature of [`super::vcavity_quadrature`] to the relative `tolerance`, in `eval`
    /// and `eval_estimate`; `sample` keeps the unbiased walk (its weight has the same
    /// expectation). Single scattering, or flat IL, ignores it.
    pub fn with_multiple_quadrature(mut self, tolerance: f64) -> ParamResult<Self> {
        check_tolerance(tolerance)?;
        let orders = match self.scattering {
            Scattering::Single => return Ok(self),
            Scattering::Double => Orders::Second,
            Scattering::Multiple => Orders::SecondAndHigher,
        };
        if let Some(l) = &self.lobe {
            self.ms_quadrature = Some(Arc::new(VCavityQuadrature::new(
                l.ndf.clone(),
                self.ni,
                self.body_factor,
                orders,
                tolerance,
            )));
        }
        Ok(self)
    }

    /// The deterministic multiple-scattering evaluator, when configured.
    pub fn multiple_quadrature(&self) -> Option<&VCavityQuadrature> {
        self.ms_quadrature.as_deref()
    }

    pub fn kd(&self) -> Spectrum {
        self.kd
    }

    /// The interface's external and internal diffuse reflectances (r_e, r_i).
    pub fn diffuse_reflectances(&self) -> (f64, f64) {
        (self.re, self.ri)
    }

    pub fn ni(&self) -> f64 {
        self.ni
    }

    pub fn r_e(&self) -> f64 {
        self.re
    }

    pub fn r_i(&self) -> f64 {
        self.ri
    }

    /// K_d/(n_i² (1 − K_d r_i)) per channel: the body term's prefactor without 1/π
    /// [IL18 eq. 13].
    pub fn body_factor(&self) -> Spectrum {
        self.body_factor
    }

    /// The probability of sampling the specular lobe (rough IL) [IL18 §4.1].
    pub fn specular_probability(&self) -> f64 {
        self.specular_probability
    }

    pub fn lobe(&self) -> Option<&SpecularLobe> {
        self.lobe.as_ref()
    }

    pub fn scattering(&self) -> Scattering {
        self.scattering
    }

    pub fn evaluation(&self) -> &BodyEvaluation {
        &self.evaluation
    }

    fn facet(&self) -> IlFacet {
        IlFacet {
            ni: self.ni,
            kd: self.kd,
            body_factor: self.body_factor,
        }
    }

    #[inline]
    fn transmittance(&self, cos: f64) -> f64 {
        1.0 - fresnel_dielectric(cos.abs(), self.ni)
    }

    /// The body integral I(i, o) = ∫ T T D G |im||om|/(|in||on|) dω (IL18 eq. 13 without its
    /// prefactor) by the model's evaluation mode, with its standard error (stochastic,
    /// fixed-N quadrature) or the adaptive quadrature's error estimate, where known.
    /// `samples` > 0 asks stochastic evaluation for an average of that many estimates.
    pub fn body_integral(
        &self,
        i: Vec3,
        o: Vec3,
        samples: usize,
        rng: &mut dyn RandomSource,
    ) -> (f64, f64) {
        let Some(integral) = &self.integral else {
            // Flat: D is a delta at n.
            return (self.transmittance(i.z) * self.transmittance(o.z), 0.0);
        };
        let h = |m: Vec3| self.transmittance(i.dot(m)) * self.transmittance(o.dot(m));
        match &self.evaluation {
            BodyEvaluation::Stochastic if samples <= 1 => {
                (integral.estimate_one(i, o, rng.next_2d(), h), 0.0)
            }
            BodyEvaluation::Stochastic => {
                // Independent one-microfacet estimates: their standard error has many degrees
                // of freedom (the 8-rotation QMC error of `estimate` is too noisy for tests).
                let (m, se) = crate::bsdf::mean_and_stderr(samples, || {
                    Spectrum::splat(integral.estimate_one(i, o, rng.next_2d(), h))
                });
                (m[0], se[0])
            }
            BodyEvaluation::Quadrature { samples } => integral.estimate_fixed(
                self.frozen_body.as_deref(),
                *samples,
                QUADRATURE_STREAM,
                i,
                o,
                h,
            ),
            BodyEvaluation::Adaptive { tolerance } => {
                // With the multiple scattering by quadrature too (and a tighter body
                // tolerance: else `eval` integrates both at once, `eval_folded`), the body
                // takes half of the tolerance and the inter-reflections what the body's
                // error estimate leaves of tolerance · (f₁ + f_ms) (`multiple_eval`), so
                // that the value meets it.
                let share = if self.ms_quadrature.is_some() {
                    0.5
                } else {
                    1.0
                };
                let q = integral.integrate(i, o, share * *tolerance, h);
                (q.value, q.error)
            }
            BodyEvaluation::Table(t) => (t.lookup(i, o), 0.0),
            BodyEvaluation::Approx(a) => (a.body_integral(i, o, self.ni, self.re), 0.0),
        }
    }

    /// The rough specular lobe f_s [IL18 eq. 4] (0 for flat IL, whose reflection is a delta).
    fn specular(&self, o: Vec3, i: Vec3) -> Spectrum {
        match &self.lobe {
            Some(l) => l.eval(o, i, |c| Spectrum::splat(fresnel_dielectric(c, self.ni))),
            None => Spectrum::ZERO,
        }
    }

    /// f_s + f_b (single scattering) for the upper-hemisphere pair (o, i).
    fn single(
        &self,
        o: Vec3,
        i: Vec3,
        samples: usize,
        rng: &mut dyn RandomSource,
    ) -> (Spectrum, Spectrum) {
        let spec = self.specular(o, i);
        let (b, se) = self.body_integral(i, o, samples, rng);
        let k = self.body_factor * INV_PI;
        (spec + k * b, k * se)
    }

    /// The multiple-scattering part for `eval` of the BRDF value `single` + f_ms: the
    /// quadrature when configured (to the tolerance relative to that value, `single`'s own
    /// error estimate left out of the budget; see [`VCavityQuadrature::eval_in`]), else one
    /// walk.
    fn multiple_eval(
        &self,
        o: Vec3,
        i: Vec3,
        (single, single_error): (Spectrum, Spectrum),
        rng: &mut dyn RandomSource,
    ) -> Spectrum {
        match &self.ms_quadrature {
            Some(q) => {
                q.eval_in(i, o, single, self.deterministic_error(single_error))
                    .value
            }
            None => self.multiple(o, i, rng),
        }
    }

    /// The single-scattering error that counts against a quadrature's budget: the adaptive
    /// body quadrature's estimate; a stochastic body's standard error is noise of another
    /// kind, outside the tolerance.
    fn deterministic_error(&self, single_error: Spectrum) -> Spectrum {
        if self.body_is_adaptive() {
            single_error
        } else {
            Spectrum::ZERO
        }
    }

    /// The multiple-scattering quadrature when it also integrates the body's single
    /// scattering ([`VCavityQuadrature::eval_body_and_multiple`]): both by adaptive
    /// quadrature and the body's tolerance no tighter than the multiple scattering's (one
    /// `tolerance` key sets both). The value's tolerance is then the multiple scattering's,
    /// relative to f₁ + f_ms, as with two quadratures; one costs less (IL_∞ `eval` at 1e-4:
    /// docs/performance.md).
    fn body_and_multiple_quadrature(&self) -> Option<&VCavityQuadrature> {
        let q = self.ms_quadrature.as_deref()?;
        match self.evaluation {
            BodyEvaluation::Adaptive { tolerance } if tolerance >= q.tolerance() => Some(q),
            _ => None,
        }
    }

    /// f₁ + f_ms by [`Self::body_and_multiple_quadrature`] and its error estimate.
    fn eval_folded(&self, q: &VCavityQuadrature, o: Vec3, i: Vec3) -> (Spectrum, Spectrum) {
        let spec = self.specular(o, i);
        let r = q.eval_body_and_multiple(i, o, spec);
        (spec + r.value, r.error)
    }

    /// Whether the body integral is the adaptive quadrature (its error a bound, not noise).
    fn body_is_adaptive(&self) -> bool {
        matches!(self.evaluation, BodyEvaluation::Adaptive { .. })
    }

    /// The multiple-scattering part (orders ≥ 2) for the upper-hemisphere pair: one V-cavity
    /// walk per estimate.
    fn multiple(&self, o: Vec3, i: Vec3, rng: &mut dyn RandomSource) -> Spectrum {
        let (Some(lobe), Some(orders)) = (
            &self.lobe,
            match self.scattering {
                Scattering::Single => None,
                Scattering::Double => Some(Orders::Second),
                Scattering::Multiple => Some(Orders::SecondAndHigher),
            },
        ) else {
            return Spectrum::ZERO;
        };
        let m = lobe.ndf.sample_normal(rng.next_2d());
        let p = lobe.ndf.pdf_normal(m);
        if !(p > 0.0) {
            return Spectrum::ZERO;
        }
        let w = lobe.ndf.d(m) * m.z / p;
        vcavity::estimate(&self.facet(), m, i, o, orders, rng) * w
    }

    /// Energy split of the sampler between the specular lobe and the cosine lobe.
    fn specular_choice(&self, o: Vec3) -> f64 {
        match &self.lobe {
            Some(_) => self.specular_probability,
            None => fresnel_dielectric(o.z, self.ni),
        }
    }
}

impl OpaqueBsdf for InterfacedLambertian {
    fn flags(&self) -> LobeFlags {
        let spec = if self.lobe.is_some() {
            LobeFlags::GLOSSY_REFLECTION
        } else {
            LobeFlags::DELTA_REFLECTION
        };
        spec | LobeFlags::DIFFUSE_REFLECTION
    }

    // With `multiple_evaluation = "quadrature"` eval is deterministic but `sample`'s weight
    // still carries one walk: the model stays stochastic for the consistency checks.
    fn is_stochastic(&self) -> bool {
        self.lobe.is_some()
            && (matches!(self.evaluation, BodyEvaluation::Stochastic)
                || self.scattering != Scattering::Single)
    }

    fn eval_is_deterministic(&self) -> bool {
        self.lobe.is_none()
            || (!matches!(self.evaluation, BodyEvaluation::Stochastic)
                && (self.scattering == Scattering::Single || self.ms_quadrature.is_some()))
    }

    fn eval(&self, wo: Vec3, wi: Vec3, _: &BsdfContext, rng: &mut dyn RandomSource) -> Spectrum {
        let (o, i) = (wo, wi);
        let v = match self.body_and_multiple_quadrature() {
            Some(q) if o.z > 0.0 && i.z > 0.0 => self.eval_folded(q, o, i).0,
            _ => {
                let single = self.single(o, i, 1, rng);
                single.0 + self.multiple_eval(o, i, single, rng)
            }
        };
        guard(v, || {
            format!("{} eval(wo = {wo:?}, wi = {wi:?})", self.describe())
        })
    }

    fn eval_estimate(
        &self,
        wo: Vec3,
        wi: Vec3,
        _: &BsdfContext,
        samples: usize,
        rng: &mut dyn RandomSource,
    ) -> (Spectrum, Spectrum) {
        let (o, i) = (wo, wi);
        if let Some(q) = self.body_and_multiple_quadrature() {
            if o.z > 0.0 && i.z > 0.0 {
                return self.eval_folded(q, o, i);
            }
        }
        let (single, single_se) = self.single(o, i, samples.max(2), rng);
        if self.scattering == Scattering::Single || self.lobe.is_none() {
            return (single, single_se);
        }
        if let Some(q) = &self.ms_quadrature {
            let rest_error = self.deterministic_error(single_se);
            let ms = q.eval_in(i, o, single, rest_error);
            // Deterministic error bounds add; a standard error and a bound, in quadrature.
            let se = if self.body_is_adaptive() {
                single_se + ms.error
            } else {
                (single_se * single_se + ms.error * ms.error).map(f64::sqrt)
            };
            return (single + ms.value, se);
        }
        let (ms, ms_se) = crate::bsdf::mean_and_stderr(samples, || self.multiple(o, i, rng));
        let se = (single_se * single_se + ms_se * ms_se).map(f64::sqrt);
        (single + ms, se)
    }

    fn sample(
        &self,
        wo: Vec3,
        ctx: &BsdfContext,
        rng: &mut dyn RandomSource,
    ) -> Option<BsdfSample> {
        let o = wo;
        let ps = self.specular_choice(o);
        let choose_specular = rng.next_f64() < ps;
        let Some(lobe) = &self.lobe else {
            // Flat IL: the Fresnel delta, or the body term by cosine sampling.
            if choose_specular {
                let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                return Some(BsdfSample {
                    wi,
                    weight: Spectrum::ONE,
                    pdf: ps,
                    lobe: LobeFlags::DELTA_REFLECTION,
                    eta: 1.0,
                });
            }
            let (wi, pdf) = sample_cosine_same_side(wo, rng)?;
            // f_b cos/((1 − F) cos/π) = K_d T(i)/(n_i²(1 − K_d r_i)).
            return Some(BsdfSample {
                wi,
                weight: self.body_factor * self.transmittance(wi.z),
                pdf: (1.0 - ps) * pdf,
                lobe: LobeFlags::DIFFUSE_REFLECTION,
                eta: 1.0,
            });
        };
        let (i, lobe_flag) = if choose_specular {
            (
                lobe.sample(o, rng.next_2d())?.0,
                LobeFlags::GLOSSY_REFLECTION,
            )
        } else {
            let (wi, _) = sample_cosine_same_side(o, rng)?;
            (wi, LobeFlags::DIFFUSE_REFLECTION)
        };
        let pdf = self.pdf(o, i, ctx);
        if !(pdf > 0.0) {
            return None;
        }
        let f = self.single(o, i, 1, rng).0 + self.multiple(o, i, rng);
        let weight = f * (i.z / pdf);
        if !weight.is_finite() {
            return None;
        }
        Some(BsdfSample {
            wi: i,
            weight,
            pdf,
            lobe: lobe_flag,
            eta: 1.0,
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, _: &BsdfContext) -> f64 {
        let (o, i) = (wo, wi);
        let ps = self.specular_choice(o);
        let spec = match &self.lobe {
            Some(l) => ps * l.pdf(o, i),
            None => 0.0,
        };
        spec + (1.0 - ps) * cosine_hemisphere_pdf(i)
    }

    fn lobe_width(&self) -> f64 {
        // The diffuse part dominates the bins: use the global map unless the glossy lobe is
        // narrow enough to need its zoom.
        self.lobe.as_ref().map_or(1.0, |l| l.typical_width())
    }

    fn describe(&self) -> String {
        let rough = match &self.lobe {
            Some(l) => format!("{}, masking={}", l.ndf.describe(), l.masking.name()),
            None => "flat".into(),
        };
        let ev = match &self.evaluation {
            BodyEvaluation::Quadrature { samples } => format!("quadrature {samples}"),
            BodyEvaluation::Adaptive { tolerance } => {
                format!("quadrature tolerance {}", fmt_num(*tolerance))
            }
            e => e.name().to_string(),
        };
        let ms = match &self.ms_quadrature {
            Some(q) => format!(" (quadrature tolerance {})", fmt_num(q.tolerance())),
            None => String::new(),
        };
        format!(
            "il(kd={:?}, ni={}, {rough}, body={ev}, scattering={}{ms})",
            self.kd.0,
            fmt_num(self.ni),
            self.scattering.name()
        )
    }
}
