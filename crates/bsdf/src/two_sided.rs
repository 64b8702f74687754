//! Two-sided opaque surfaces: one adapter instead of the same mirroring code in every
//! opaque model (the role of Mitsuba 3's `twosided` plugin).
//!
//! An opaque model implements [`OpaqueBsdf`] for the upper hemisphere only: `eval`, `pdf`
//! and `eval_estimate` receive `wo` and `wi` above the surface (z > 0), `sample` receives
//! `wo` above it. [`TwoSided`] makes such a model a [`Bsdf`]: a pair below the surface is
//! answered as its mirror image through the tangent plane, a pair on opposite sides (or in
//! the tangent plane) scatters nothing, and a sample drawn for the mirrored `wo` is mirrored
//! back. Values, densities and the random numbers consumed are those of the mirrored
//! query, exactly.

use crate::bsdf::{Bsdf, BsdfContext, BsdfSample, LobeFlags};
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::{flip, to_upper_pair, Vec3};

/// A reflection-only BSDF written for the upper hemisphere; [`TwoSided`] turns it into a
/// [`Bsdf`]. The methods mean what [`Bsdf`]'s mean, under the preconditions of the module
/// notes.
pub trait OpaqueBsdf: Send + Sync {
    /// The lobes this BRDF has.
    fn flags(&self) -> LobeFlags;

    /// True when `eval` is a stochastic (unbiased) estimate that consumes random numbers.
    fn is_stochastic(&self) -> bool {
        false
    }

    /// See [`Bsdf::eval_is_deterministic`].
    fn eval_is_deterministic(&self) -> bool {
        !self.is_stochastic()
    }

    /// f(wo, wi) without the cosine factor; `wo.z > 0`, `wi.z > 0`.
    fn eval(&self, wo: Vec3, wi: Vec3, ctx: &BsdfContext, rng: &mut dyn RandomSource) -> Spectrum;

    /// Draws `wi` for `wo.z > 0`.
    fn sample(&self, wo: Vec3, ctx: &BsdfContext, rng: &mut dyn RandomSource)
        -> Option<BsdfSample>;

    /// The density of `sample` (a proxy when `pdf_is_exact` is false); `wo.z > 0`, `wi.z > 0`.
    fn pdf(&self, wo: Vec3, wi: Vec3, ctx: &BsdfContext) -> f64;

    /// See [`Bsdf::pdf_is_exact`].
    fn pdf_is_exact(&self) -> bool {
        true
    }

    /// See [`Bsdf::eval_estimate`]; `wo.z > 0`, `wi.z > 0`.
    fn eval_estimate(
        &self,
        wo: Vec3,
        wi: Vec3,
        ctx: &BsdfContext,
        samples: usize,
        rng: &mut dyn RandomSource,
    ) -> (Spectrum, Spectrum) {
        if !self.is_stochastic() {
            return (self.eval(wo, wi, ctx, rng), Spectrum::ZERO);
        }
        crate::bsdf::mean_and_stderr(samples, || self.eval(wo, wi, ctx, rng))
    }

    /// See [`Bsdf::lobe_width`].
    /// See [`Bsdf::albedo_excess`].
    fn albedo_excess(&self) -> f64 {
        0.0
    }

    fn lobe_width(&self) -> f64 {
        1.0
    }

    /// Short description of the model and its parameters.
    fn describe(&self) -> String;
}

/// An opaque model seen from both sides of the surface.
#[derive(Clone, Debug)]
pub struct TwoSided<M> {
    inner: M,
}

impl<M: OpaqueBsdf> TwoSided<M> {
    pub fn new(inner: M) -> Self {
        TwoSided { inner }
    }

    /// The upper-hemisphere model.
    pub fn inner(&self) -> &M {
        &self.inner
    }
}

/// The model's own methods (its parameters, tables, footprint…) through the adapter. The
/// [`Bsdf`] methods of the adapter come first in method resolution, so `eval`, `sample` and
/// `pdf` on a `TwoSided` are always the two-sided ones.
impl<M> std::ops::Deref for TwoSided<M> {
    type Target = M;

    fn deref(&self) -> &M {
        &self.inner
    }
}

impl<M: OpaqueBsdf> Bsdf for TwoSided<M> {
    fn flags(&self) -> LobeFlags {
        self.inner.flags()
    }

    fn is_stochastic(&self) -> bool {
        self.inner.is_stochastic()
    }

    fn eval_is_deterministic(&self) -> bool {
        self.inner.eval_is_deterministic()
    }

    fn eval(&self, wo: Vec3, wi: Vec3, ctx: &BsdfContext, rng: &mut dyn RandomSource) -> Spectrum {
        match to_upper_pair(wo, wi) {
            Some((o, i)) => self.inner.eval(o, i, ctx, rng),
            None => Spectrum::ZERO,
        }
    }

    fn sample(
        &self,
        wo: Vec3,
        ctx: &BsdfContext,
        rng: &mut dyn RandomSource,
    ) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let below = wo.z < 0.0;
        let o = if below { flip(wo) } else { wo };
        let mut s = self.inner.sample(o, ctx, rng)?;
        if below {
            s.wi = flip(s.wi);
        }
        Some(s)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, ctx: &BsdfContext) -> f64 {
        match to_upper_pair(wo, wi) {
            Some((o, i)) => self.inner.pdf(o, i, ctx),
            None => 0.0,
        }
    }

    fn pdf_is_exact(&self) -> bool {
        self.inner.pdf_is_exact()
    }

    fn eval_estimate(
        &self,
        wo: Vec3,
        wi: Vec3,
        ctx: &BsdfContext,
        samples: usize,
        rng: &mut dyn RandomSource,
    ) -> (Spectrum, Spectrum) {
        match to_upper_pair(wo, wi) {
            Some((o, i)) => self.inner.eval_estimate(o, i, ctx, samples, rng),
            None => (Spectrum::ZERO, Spectrum::ZERO),
        }
    }

    fn albedo_excess(&self) -> f64 {
        self.inner.albedo_excess()
    }

    fn lobe_width(&self) -> f64 {
        self.inner.lobe_width()
    }

    fn describe(&self) -> String {
        self.inner.describe()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rng::Pcg32;
    use crate::math::spherical_direction;

    /// An upper-hemisphere model that records what it was asked.
    struct Probe;

    impl OpaqueBsdf for Probe {
        fn flags(&self) -> LobeFlags {
            LobeFlags::DIFFUSE_REFLECTION
        }
        fn eval(&self, wo: Vec3, wi: Vec3, _: &BsdfContext, _: &mut dyn RandomSource) -> Spectrum {
            assert!(wo.z > 0.0 && wi.z > 0.0);
            Spectrum::rgb(wo.x, wi.x, wo.z * wi.z)
        }
        fn sample(
            &self,
            wo: Vec3,
            _: &BsdfContext,
            _: &mut dyn RandomSource,
        ) -> Option<BsdfSample> {
            assert!(wo.z > 0.0);
            Some(BsdfSample {
                wi: Vec3::new(-wo.x, -wo.y, wo.z),
                weight: Spectrum::ONE,
                pdf: 1.0,
                lobe: LobeFlags::DIFFUSE_REFLECTION,
                eta: 1.0,
            })
        }
        fn pdf(&self, wo: Vec3, wi: Vec3, _: &BsdfContext) -> f64 {
            assert!(wo.z > 0.0 && wi.z > 0.0);
            wo.z + wi.z
        }
        fn describe(&self) -> String {
            "probe".into()
        }
    }

    #[test]
    fn lower_pairs_are_mirrored_and_opposite_sides_are_black() {
        let b = TwoSided::new(Probe);
        let ctx = BsdfContext::RADIANCE;
        let rng = &mut Pcg32::new(1, 1);
        let (o, i) = (spherical_direction(0.4, 0.3), spherical_direction(1.1, 2.0));
        let below = |v: Vec3| flip(v);
        assert_eq!(
            b.eval(below(o), below(i), &ctx, rng),
            b.eval(o, i, &ctx, rng)
        );
        assert_eq!(b.pdf(below(o), below(i), &ctx), b.pdf(o, i, &ctx));
        assert_eq!(b.eval(o, below(i), &ctx, rng), Spectrum::ZERO);
        assert_eq!(b.pdf(below(o), i, &ctx), 0.0);
        let s = b.sample(below(o), &ctx, rng).unwrap();
        assert_eq!(s.wi, below(b.sample(o, &ctx, rng).unwrap().wi));
        assert!(b.sample(Vec3::new(1.0, 0.0, 0.0), &ctx, rng).is_none());
    }
}
