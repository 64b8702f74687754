//! Rough conductor with every order of inter-reflection between microfacets
//! (`scattering = "multiple"`): the random walk on the Smith microsurface [HHdD16 §5,
//! conductors] of [`smith_microsurface`](super::smith_microsurface), with mirror facets of the
//! material's Fresnel term (times `specular_reflectance` at every reflection).
//!
//! - `eval`: today's single-scattering lobe (the shared specular lobe with the
//!   height-correlated Smith masking, exactly what `scattering = "single"` returns) plus an
//!   unbiased estimate of the orders ≥ 2 by one walk entering from the more masked of the two
//!   directions with next-event estimation toward the other
//!   ([`Microsurface::walk_from_first`]: the low-variance choice). The estimate is
//!   stochastic ([`Bsdf::is_stochastic`]); as the choice depends on the unordered pair, the
//!   estimates of f(a, b) and f(b, a) have the same distribution.
//! - `sample`: the physical walk from `wo`; the weight is the product of the Fresnel factors
//!   met — exactly 1 for a white conductor, whose albedo is then 1 but for walks longer than
//!   [`MAX_ORDER`](super::smith_microsurface::MAX_ORDER) (measured negligible).
//! - `pdf`: the walk's exit density has no closed form; `pdf` returns a proxy for multiple
//!   importance sampling ([`Bsdf::pdf_is_exact`] is false): the density of the compensated
//!   conductor's sampler (E(μ_o) of the single-scattering lobe's density plus 1 − E(μ_o) of
//!   the compensation lobe's, see [`CompensatedConductor`]) — an energy-conserving
//!   approximation of the walk's exit density — mixed with 0.1 % of the cosine density so
//!   that it is positive wherever a walk can exit.

use super::compensated_conductor::CompensatedConductor;
use super::random_walk::{check_lobe, PROXY_COSINE_SHARE};
use super::smith_microsurface::{FacetScattering, HeightDistribution, Microsurface};
use crate::bsdf::{BsdfContext, BsdfSample, LobeFlags};
use crate::error::{ParamError, ParamResult};
use crate::finite::guard;
use crate::fresnel::Fresnel;
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::warp::cosine_hemisphere_pdf;
use crate::math::{reflect, to_upper_pair, Vec3};
use crate::models::rough_conductor::RoughConductor;
use crate::two_sided::OpaqueBsdf;

/// Mirror facets with a conductor's Fresnel term.
#[derive(Clone, Debug)]
struct ConductorFacets {
    fresnel: Fresnel,
    tint: Spectrum,
}

impl FacetScattering for ConductorFacets {
    #[inline]
    fn scatter(
        &self,
        wi: Vec3,
        m: Vec3,
        _: bool,
        _: &mut dyn RandomSource,
    ) -> Option<(Vec3, bool, Spectrum)> {
        let c = wi.dot(m);
        (c > 0.0).then(|| (reflect(wi, m), false, self.tint * self.fresnel.eval(c)))
    }

    /// F(wi·h) D_wi(h) / (4 wi·h), h the half vector [WMLT07 eq. 14 with the visible normals].
    #[inline]
    fn phase(&self, s: &Microsurface, wi: Vec3, wo: Vec3, _: bool, crosses: bool) -> Spectrum {
        if crosses {
            return Spectrum::ZERO;
        }
        let h = (wi + wo).normalize_or_zero();
        let c = wi.dot(h);
        if h.z <= 0.0 || c <= 0.0 {
            return Spectrum::ZERO;
        }
        self.tint * self.fresnel.eval(c) * (s.visible_density(wi, h) / (4.0 * c))
    }
}

#[derive(Clone, Debug)]
pub struct MultipleScatteringConductor {
    single: RoughConductor,
    surface: Microsurface,
    facets: ConductorFacets,
    proxy: CompensatedConductor,
}

impl MultipleScatteringConductor {
    /// The multiple-scattering version of a rough conductor, whose lobe must use the
    /// height-correlated Smith masking (the walk's first order) and visible-normal sampling.
    pub fn new(single: RoughConductor, heights: HeightDistribution) -> ParamResult<Self> {
        let lobe = single.lobe().ok_or_else(|| {
            ParamError::Invalid("a smooth conductor has no inter-reflections".into())
        })?;
        check_lobe(lobe.masking, lobe.sampling())?;
        let surface = Microsurface::new(lobe.ndf.clone(), heights)?;
        let facets = ConductorFacets {
            fresnel: *single.fresnel(),
            tint: single.tint(),
        };
        let proxy = CompensatedConductor::new(single.clone())?;
        Ok(MultipleScatteringConductor {
            single,
            surface,
            facets,
            proxy,
        })
    }

    pub fn single(&self) -> &RoughConductor {
        &self.single
    }

    pub fn surface(&self) -> &Microsurface {
        &self.surface
    }

    /// Unbiased estimate of the orders ≥ `min_order` of f(i, o) for the light direction `i`
    /// and view `o` (same side): `min_order = 1` estimates the whole BRDF by the walk alone,
    /// including the first order the model otherwise evaluates in closed form.
    pub fn estimate_orders(
        &self,
        i: Vec3,
        o: Vec3,
        min_order: usize,
        rng: &mut dyn RandomSource,
    ) -> Spectrum {
        let Some((o, i)) = to_upper_pair(o, i) else {
            return Spectrum::ZERO;
        };
        self.surface.estimate(&self.facets, i, o, min_order, rng) / o.z
    }

    /// [`Self::estimate_orders`] with the choice of the next-event masking factor
    /// ([`Microsurface::estimate_with`]): `expected_masking = false` is HHdD16's estimator
    /// as printed, whose variance is huge for Beckmann (kept to measure it).
    pub fn estimate_orders_with(
        &self,
        i: Vec3,
        o: Vec3,
        min_order: usize,
        expected_masking: bool,
        rng: &mut dyn RandomSource,
    ) -> Spectrum {
        let Some((o, i)) = to_upper_pair(o, i) else {
            return Spectrum::ZERO;
        };
        self.surface
            .estimate_with(&self.facets, i, o, min_order, expected_masking, rng)
            / o.z
    }
}

impl OpaqueBsdf for MultipleScatteringConductor {
    fn flags(&self) -> LobeFlags {
        LobeFlags::GLOSSY_REFLECTION
    }

    fn is_stochastic(&self) -> bool {
        true
    }

    fn pdf_is_exact(&self) -> bool {
        false
    }

    fn eval(&self, wo: Vec3, wi: Vec3, ctx: &BsdfContext, rng: &mut dyn RandomSource) -> Spectrum {
        let (o, i) = (wo, wi);
        // The walk enters from the more masked of the two directions (the estimator's
        // variance, `Microsurface::walk_from_first`); the conductor is reciprocal, so the
        // transport mode does not matter.
        let (light, view) = if self.surface.walk_from_first(i, o) {
            (i, o)
        } else {
            (o, i)
        };
        let higher = self.surface.estimate(&self.facets, light, view, 2, rng) / view.z;
        let v = self.single.eval(wo, wi, ctx, rng) + higher;
        guard(v, || {
            format!("{} eval(wo = {wo:?}, wi = {wi:?})", self.describe())
        })
    }

    fn sample(
        &self,
        wo: Vec3,
        ctx: &BsdfContext,
        rng: &mut dyn RandomSource,
    ) -> Option<BsdfSample> {
        let exit = self.surface.walk(&self.facets, wo, rng)?;
        if exit.dir.z <= 0.0 {
            return None;
        }
        let wi = exit.dir;
        let pdf = self.pdf(wo, wi, ctx);
        (pdf > 0.0 && exit.weight.is_finite()).then_some(BsdfSample {
            wi,
            weight: exit.weight,
            pdf,
            lobe: LobeFlags::GLOSSY_REFLECTION,
            eta: 1.0,
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, ctx: &BsdfContext) -> f64 {
        (1.0 - PROXY_COSINE_SHARE) * self.proxy.pdf(wo, wi, ctx)
            + PROXY_COSINE_SHARE * cosine_hemisphere_pdf(wi)
    }

    fn lobe_width(&self) -> f64 {
        self.single.lobe_width()
    }

    fn describe(&self) -> String {
        let s = self.single.describe();
        format!(
            "{}, scattering=multiple, heights={})",
            s.strip_suffix(')').unwrap_or(&s),
            self.surface.heights().name()
        )
    }
}
