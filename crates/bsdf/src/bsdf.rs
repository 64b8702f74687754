//! The BSDF interface.
//!
//! Directions are unit vectors in the local shading frame (z = shading normal), both
//! pointing away from the surface: `wo` is the direction the path arrives from (toward the
//! camera when tracing radiance), `wi` the direction it continues to (toward the light).
//! In the papers' notation f(i, o) with i the light direction: `eval(wo, wi)` = f(i = wi,
//! o = wo) in radiance mode.
//!
//! `sample` returns the weight f·|cos θ_i|/pdf, the solid-angle pdf and the lobe it drew
//! from. For a delta lobe the pdf is the discrete probability of choosing that lobe and the
//! weight is the lobe's throughput; `eval` and `pdf` never include delta lobes.
//!
//! Stochastic models (a body term estimated with one microfacet, a random walk between
//! microfacets) are first-class: every call receives a [`RandomSource`], deterministic
//! models simply ignore it, and [`Bsdf::is_stochastic`] says which kind a model is. Their
//! `eval` is an unbiased estimate, their `pdf` is exact, and their `sample` weight is an
//! unbiased estimate of f·|cos|/pdf — except for models that sample by a physical random
//! walk (the multiple-scattering microsurfaces), whose exit density has no closed form:
//! [`Bsdf::pdf_is_exact`] is false for them, `pdf` is a documented proxy used only for
//! multiple importance sampling, and the weight is an unbiased estimate of f·|cos| divided by
//! the walk's own density (so E[weight · g(wi)] = ∫ f |cos| g for any g).

use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::Vec3;

/// Which quantity a path carries. Only refraction distinguishes them: WMLT07's BTDF is not
/// reciprocal, f_t(i,o)/η_o² = f_t(o,i)/η_i² (ERRATA 11).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TransportMode {
    /// Paths traced from the camera; `eval(wo, wi)` = f(i = wi, o = wo).
    #[default]
    Radiance,
    /// Paths traced from the lights; `eval(wo, wi)` = f(i = wo, o = wi).
    Importance,
}

/// Lobe classification flags.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Hash)]
pub struct LobeFlags(pub u8);

impl LobeFlags {
    pub const NONE: LobeFlags = LobeFlags(0);
    pub const REFLECTION: LobeFlags = LobeFlags(1);
    pub const TRANSMISSION: LobeFlags = LobeFlags(2);
    pub const DIFFUSE: LobeFlags = LobeFlags(4);
    pub const GLOSSY: LobeFlags = LobeFlags(8);
    pub const DELTA: LobeFlags = LobeFlags(16);

    pub const DIFFUSE_REFLECTION: LobeFlags = LobeFlags(1 | 4);
    pub const GLOSSY_REFLECTION: LobeFlags = LobeFlags(1 | 8);
    pub const GLOSSY_TRANSMISSION: LobeFlags = LobeFlags(2 | 8);
    pub const DIFFUSE_TRANSMISSION: LobeFlags = LobeFlags(2 | 4);
    pub const DELTA_REFLECTION: LobeFlags = LobeFlags(1 | 16);
    pub const DELTA_TRANSMISSION: LobeFlags = LobeFlags(2 | 16);

    #[inline]
    pub fn contains(self, o: LobeFlags) -> bool {
        self.0 & o.0 == o.0
    }

    #[inline]
    pub fn intersects(self, o: LobeFlags) -> bool {
        self.0 & o.0 != 0
    }

    #[inline]
    pub fn is_delta(self) -> bool {
        self.intersects(LobeFlags::DELTA)
    }

    /// True when the BSDF has a non-delta component (so `eval`/`pdf` are meaningful).
    #[inline]
    pub fn has_smooth_part(self) -> bool {
        self.intersects(LobeFlags(LobeFlags::DIFFUSE.0 | LobeFlags::GLOSSY.0))
    }

    pub fn describe(self) -> String {
        let mut v = Vec::new();
        for (f, n) in [
            (LobeFlags::DELTA, "delta"),
            (LobeFlags::GLOSSY, "glossy"),
            (LobeFlags::DIFFUSE, "diffuse"),
            (LobeFlags::REFLECTION, "reflection"),
            (LobeFlags::TRANSMISSION, "transmission"),
        ] {
            if self.intersects(f) {
                v.push(n);
            }
        }
        v.join("+")
    }
}

impl std::ops::BitOr for LobeFlags {
    type Output = LobeFlags;
    fn bitor(self, o: LobeFlags) -> LobeFlags {
        LobeFlags(self.0 | o.0)
    }
}

/// Per-query context.
#[derive(Clone, Copy, Debug, Default)]
pub struct BsdfContext {
    pub mode: TransportMode,
    /// The caller will not read [`BsdfSample::pdf`] (a path tracer whose only lights are
    /// delta lights, or that does not weight by MIS, never asks for the density of a sampled
    /// direction): a model whose density costs more than its sample may then report a cheap
    /// positive stand-in there (glints [CCM19]: no query of the footprint's lobes). The
    /// weight, `eval` and `pdf` do not change.
    pub skip_sample_pdf: bool,
}

impl BsdfContext {
    pub const RADIANCE: BsdfContext = BsdfContext {
        mode: TransportMode::Radiance,
        skip_sample_pdf: false,
    };
    pub const IMPORTANCE: BsdfContext = BsdfContext {
        mode: TransportMode::Importance,
        skip_sample_pdf: false,
    };

    /// This context for a caller that does not read [`BsdfSample::pdf`].
    pub const fn without_sample_pdf(self) -> BsdfContext {
        BsdfContext {
            skip_sample_pdf: true,
            ..self
        }
    }
}

/// Result of [`Bsdf::sample`].
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// The sampled direction.
    pub wi: Vec3,
    /// f·|cos θ_i| / pdf (for delta lobes: the lobe's throughput; for random-walk samplers,
    /// see [`Bsdf::pdf_is_exact`], f·|cos θ_i| over the walk's own density).
    pub weight: Spectrum,
    /// Solid-angle density of `wi` (for delta lobes: the lobe-selection probability; for
    /// random-walk samplers, the proxy `pdf(wo, wi)`).
    pub pdf: f64,
    /// The lobe that produced the sample.
    pub lobe: LobeFlags,
    /// Relative index η_i/η_o crossed by the sample (1 for reflection), for the
    /// integrator's Russian roulette on radiance.
    pub eta: f64,
}

/// A bidirectional scattering distribution function in the local frame.
pub trait Bsdf: Send + Sync {
    /// The lobes this BSDF has.
    fn flags(&self) -> LobeFlags;

    /// True when `eval` is a stochastic (unbiased) estimate that consumes random numbers.
    fn is_stochastic(&self) -> bool {
        false
    }

    /// True when `eval` (and so `eval_estimate`, whatever its `samples`) returns one value
    /// for a direction pair, whatever the random numbers: closed forms, and models that
    /// evaluate by quadrature while their `sample` weights stay stochastic (so that they
    /// are [`Self::is_stochastic`] for the consistency checks). Tools that average
    /// estimates or keep one random stream in order ask this.
    fn eval_is_deterministic(&self) -> bool {
        !self.is_stochastic()
    }

    /// f(wo, wi) without the cosine factor; excludes delta lobes.
    fn eval(&self, wo: Vec3, wi: Vec3, ctx: &BsdfContext, rng: &mut dyn RandomSource) -> Spectrum;

    /// Draws `wi` for the given `wo`.
    fn sample(&self, wo: Vec3, ctx: &BsdfContext, rng: &mut dyn RandomSource)
        -> Option<BsdfSample>;

    /// Solid-angle density with which `sample` produces `wi` (non-delta lobes only); a proxy
    /// density when [`Bsdf::pdf_is_exact`] is false.
    fn pdf(&self, wo: Vec3, wi: Vec3, ctx: &BsdfContext) -> f64;

    /// True when `pdf` is the exact density with which `sample` draws directions. False for
    /// models that sample by a physical random walk: their `pdf` (which `sample` also
    /// reports) is a positive proxy density that serves only to weight multiple importance
    /// sampling — MIS stays unbiased with any such function of the direction, because the
    /// weights of the two strategies still sum to one — and the validation harness tests
    /// their sampler against their `eval` instead of against `pdf`.
    fn pdf_is_exact(&self) -> bool {
        true
    }

    /// A converged value of f(wo, wi) with its standard error. Deterministic models return
    /// `eval` and zero; stochastic ones average `samples` independent estimates.
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
        mean_and_stderr(samples, || self.eval(wo, wi, ctx, rng))
    }

    /// Typical angular width of the glossy lobes (radians-like scale), used to size
    /// validation bins; 1 for diffuse models.
    fn lobe_width(&self) -> f64 {
        1.0
    }

    /// How far this deterministic model's directional albedo may exceed 1 by construction
    /// (0 for most models): a tabulated energy compensation returns 1 − E_table(μ) of
    /// energy where the lobe itself returns E(μ), and the table's bilinear interpolation
    /// misses E by up to [`COMPENSATION_ERROR`](crate::models::multiple_scattering::albedo_tables::COMPENSATION_ERROR).
    /// The validation's albedo check allows it.
    fn albedo_excess(&self) -> f64 {
        0.0
    }

    /// Relative index η (inside over outside) for transmissive models, else `None`.
    fn relative_ior(&self) -> Option<f64> {
        None
    }

    /// Short description of the model and its parameters.
    fn describe(&self) -> String;
}

/// Mean and standard error of `n` spectrum-valued draws.
pub fn mean_and_stderr(n: usize, mut draw: impl FnMut() -> Spectrum) -> (Spectrum, Spectrum) {
    let n = n.max(2);
    let mut s = Spectrum::ZERO;
    let mut s2 = Spectrum::ZERO;
    for _ in 0..n {
        let v = draw();
        s += v;
        s2 += v * v;
    }
    let nf = n as f64;
    let mean = s / nf;
    let var = (s2 / nf - mean * mean).map(|v| v.max(0.0)) * (nf / (nf - 1.0));
    (mean, (var / nf).map(f64::sqrt))
}
