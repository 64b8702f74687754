//! The packet kernel's calls into the lane models, each compiled as a function of its own.
//!
//! The lane models' code is `#[inline(always)]` so that it compiles with the instruction
//! set of the function it lands in (AVX2 + FMA in the kernel). Inlined into the kernel's
//! loops, though, every model with both distributions and Beckmann's inverse-CDF sampler
//! made the whole bounce one function of a size where LLVM's loop and memory passes (LICM's
//! predecessor walks, MemorySSA renaming), which grow faster than linearly with it, kept the
//! render crate's test build busy for over 30 minutes on one core. Here each model call is
//! one function per lane type, compiled for AVX2 + FMA where the CPU has them: a call per
//! model group and bounce, nothing next to the model's own work. The environment map's
//! lane look-up and sampler are called the same way, in every build: inlined into the
//! kernel's function they made the render crate's builds much slower (its test build
//! about twice as long).

use facette_bsdf::lanes::{Bits32, LVec3, Real};
#[cfg(not(target_arch = "x86_64"))]
use facette_bsdf::lanes::{F32x8, F64x8, U32x8};
#[cfg(target_arch = "x86_64")]
use facette_bsdf::lanes::{F32x8Avx2, F32x8Sse2, F64x8Sse2, U32x8Avx2, U32x8Sse2};
use facette_bsdf::models::{ColorSource, LaneBsdf, LaneRandom, LaneSample};

use crate::image::environment::{EnvSampleLanes, EnvironmentMap};

/// A lane type the kernel shades with, and how it calls the lane models: by default their
/// baseline out-of-line functions.
pub(crate) trait ShadingLanes: Real {
    /// The 32-bit integer lanes of the same build (the samplers' hashes).
    type Bits: Bits32;

    /// [`LaneBsdf::eval_pdf`], out of line.
    #[inline(always)]
    fn eval_pdf(
        model: &LaneBsdf,
        colors: &impl ColorSource<Self>,
        wo: LVec3<Self>,
        wi: LVec3<Self>,
        rng: &mut impl LaneRandom<Self>,
    ) -> ([Self; 3], Self) {
        model.eval_pdf_out_of_line(colors, wo, wi, rng)
    }

    /// [`LaneBsdf::sample`], out of line.
    #[inline(always)]
    fn sample(
        model: &LaneBsdf,
        colors: &impl ColorSource<Self>,
        wo: LVec3<Self>,
        u_lobe: Self,
        u0: Self,
        u1: Self,
        rng: &mut impl LaneRandom<Self>,
    ) -> LaneSample<Self> {
        model.sample_out_of_line(colors, wo, u_lobe, u0, u1, rng)
    }

    /// [`EnvironmentMap::eval_pdf_lanes`], out of line.
    #[inline(always)]
    fn eval_environment(map: &EnvironmentMap, d: LVec3<Self>) -> ([Self; 3], Self) {
        eval_environment_out_of_line(map, d)
    }

    /// [`EnvironmentMap::sample_lanes`], out of line.
    #[inline(always)]
    fn sample_environment(
        map: &EnvironmentMap,
        u0: Self,
        u1: Self,
        set: Self::Mask,
    ) -> EnvSampleLanes<Self> {
        sample_environment_out_of_line(map, u0, u1, set)
    }
}

/// The baseline builds' environment look-up, a function of its own (inlined, the map's code
/// in the kernel's function doubled the render crate's test build time).
#[inline(never)]
fn eval_environment_out_of_line<R: Real>(map: &EnvironmentMap, d: LVec3<R>) -> ([R; 3], R) {
    map.eval_pdf_lanes(d)
}

/// The baseline builds' environment sampler, a function of its own.
#[inline(never)]
fn sample_environment_out_of_line<R: Real>(
    map: &EnvironmentMap,
    u0: R,
    u1: R,
    set: R::Mask,
) -> EnvSampleLanes<R> {
    map.sample_lanes(u0, u1, set)
}

/// f64 array lanes (the test that finds the scalar integrator's image, off x86-64).
#[cfg(not(target_arch = "x86_64"))]
impl ShadingLanes for F64x8 {
    type Bits = U32x8;
}

/// f64 SSE2 register lanes (the test that finds the scalar integrator's image, on x86-64).
#[cfg(target_arch = "x86_64")]
impl ShadingLanes for F64x8Sse2 {
    type Bits = U32x8Sse2;
}

/// f32 array lanes: the portable build's off x86-64.
#[cfg(not(target_arch = "x86_64"))]
impl ShadingLanes for F32x8 {
    type Bits = U32x8;
}

/// f32 SSE2 register lanes: the portable build's on x86-64 (where the CPU has no AVX2).
#[cfg(target_arch = "x86_64")]
impl ShadingLanes for F32x8Sse2 {
    type Bits = U32x8Sse2;
}

/// f32 register lanes (renders where the CPU has AVX2 and FMA): each model call compiled
/// for AVX2 + FMA.
#[cfg(target_arch = "x86_64")]
impl ShadingLanes for F32x8Avx2 {
    type Bits = U32x8Avx2;

    #[inline(always)]
    fn eval_pdf(
        model: &LaneBsdf,
        colors: &impl ColorSource<Self>,
        wo: LVec3<Self>,
        wi: LVec3<Self>,
        rng: &mut impl LaneRandom<Self>,
    ) -> ([Self; 3], Self) {
        // SAFETY: register lanes exist only where the CPU has AVX2 and FMA (the rule of
        // `lanes::avx2`), the features the function is compiled for.
        unsafe { eval_pdf_avx2(model, colors, wo, wi, rng) }
    }

    #[inline(always)]
    fn sample(
        model: &LaneBsdf,
        colors: &impl ColorSource<Self>,
        wo: LVec3<Self>,
        u_lobe: Self,
        u0: Self,
        u1: Self,
        rng: &mut impl LaneRandom<Self>,
    ) -> LaneSample<Self> {
        // SAFETY: as in `eval_pdf`.
        unsafe { sample_avx2(model, colors, wo, u_lobe, u0, u1, rng) }
    }

    #[inline(always)]
    fn eval_environment(map: &EnvironmentMap, d: LVec3<Self>) -> ([Self; 3], Self) {
        // SAFETY: as in `eval_pdf`.
        unsafe { eval_environment_avx2(map, d) }
    }

    #[inline(always)]
    fn sample_environment(
        map: &EnvironmentMap,
        u0: Self,
        u1: Self,
        set: Self::Mask,
    ) -> EnvSampleLanes<Self> {
        // SAFETY: as in `eval_pdf`.
        unsafe { sample_environment_avx2(map, u0, u1, set) }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline(never)]
fn eval_environment_avx2(map: &EnvironmentMap, d: LVec3<F32x8Avx2>) -> ([F32x8Avx2; 3], F32x8Avx2) {
    map.eval_pdf_lanes(d)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline(never)]
fn sample_environment_avx2(
    map: &EnvironmentMap,
    u0: F32x8Avx2,
    u1: F32x8Avx2,
    set: <F32x8Avx2 as Real>::Mask,
) -> EnvSampleLanes<F32x8Avx2> {
    map.sample_lanes(u0, u1, set)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline(never)]
fn eval_pdf_avx2(
    model: &LaneBsdf,
    colors: &impl ColorSource<F32x8Avx2>,
    wo: LVec3<F32x8Avx2>,
    wi: LVec3<F32x8Avx2>,
    rng: &mut impl LaneRandom<F32x8Avx2>,
) -> ([F32x8Avx2; 3], F32x8Avx2) {
    model.eval_pdf_with(colors, wo, wi, rng)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline(never)]
fn sample_avx2(
    model: &LaneBsdf,
    colors: &impl ColorSource<F32x8Avx2>,
    wo: LVec3<F32x8Avx2>,
    u_lobe: F32x8Avx2,
    u0: F32x8Avx2,
    u1: F32x8Avx2,
    rng: &mut impl LaneRandom<F32x8Avx2>,
) -> LaneSample<F32x8Avx2> {
    model.sample_with(colors, wo, u_lobe, u0, u1, rng)
}
