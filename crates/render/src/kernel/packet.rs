//! The packet kernel: eight camera samples of a tile in flight per thread, their paths kept
//! as lanes (structure of arrays), each step advancing every live path by one segment, a
//! finished path's lane refilled at once from a batch of eight camera rays made together.
//!
//! A step is the scalar integrator's vertex ([`integrator`](crate::integrator)) in phases,
//! each over all eight lanes: intersection (one packet query,
//! [`intersect_lanes`](crate::geometry::SceneGeometry::intersect_lanes)) and the hit
//! records ([`hit_lanes`](crate::geometry::SceneGeometry::hit_lanes)); emission; the
//! shading frame; light samples; the materials' values and densities for them; shadow rays
//! (one packet query); the materials' samples; throughput, roulette and the next rays.
//!
//! Everything in lanes is in f32 lanes in renders — `F32x8Avx2` (AVX registers) in the AVX2
//! build, [`PortableLanes`] (two SSE registers on x86-64, arrays elsewhere; the same bits)
//! in the portable one — and in f64 lanes (`F64x8`'s bits, in SSE2 registers on x86-64) in
//! the test that finds the scalar integrator's image sample for sample. That covers the geometry —
//! rays, hit points, normals, frames, spawned origins, computed by the same one-source
//! functions as the scalar integrator's (the sphere test and record, the camera, the
//! spawning rule with the offset of the lanes' precision, the frame) — and the shading —
//! the directions in the local frame, the materials that have a lane model
//! ([`LaneBsdf`](facette_bsdf::models::LaneBsdf)), environment maps (the radiance and
//! density of rays leaving the scene and the map's light samples,
//! [`EnvironmentMap::sample_lanes`](crate::image::EnvironmentMap::sample_lanes)), light and
//! path weights. In f64 lanes a
//! ray hits what the scalar integrator's ray hits, bit for bit; in f32 lanes it hits the
//! same surfaces up to f32 rounding (shapes without a lane test are tested in f64 on the
//! lane's f32 ray). The random numbers are the scalar integrator's, dimension for
//! dimension, drawn eight lanes at a time ([`SampleLanes`]).
//!
//! A textured material with a lane model reads its textures lane by lane and runs its lane
//! model with the values: textured colors as lanes beside the material's other lanes
//! ([`LaneColors`]), a textured roughness as a model of the lane's own.
//!
//! What has no lane form runs lane by lane inside the same step, through the scalar code:
//! materials without a lane model (and glints) through their
//! f64 [`Bsdf`](facette_bsdf::Bsdf), lights other than environments and point lights (and
//! maps of more than 2²⁴ pixels, which an f32 lane cannot index), area-light emission, ray
//! differentials. On x86-64 the kernel
//! is compiled twice, for the baseline with the SSE2 register lanes (an 8-lane f32
//! operation is two instructions) and for AVX2 + FMA with the AVX register lanes, chosen at
//! run time; the two give the same image bit for bit (tested).

use super::model_calls::ShadingLanes;
use crate::geometry::bvh::lanes_of;
use crate::geometry::ray::offset_origin_lanes;
use crate::geometry::solid_angle_sampling::ShapeSampleLanes;
use crate::geometry::{HitLanes, LaneRays, PacketHit, RayDifferential, Vec3};
use crate::image::ConstantEnvironment;
use crate::integrator::{power_heuristic, Strategy, CAMERA_DIMENSIONS, VERTEX_DIMENSIONS};
use crate::lights::{Environment, Light};
use crate::materials::{LaneTexel, MaterialBsdf, SceneMaterial};
use crate::pixel_footprint::{pixel_shading, PixelRay};
use crate::render::{CameraSampling, PixelSums};
use crate::sampler::lanes::{move_lanes, SampleLanes};
use crate::sampler::{PixelSampler, PrefixedSource, SampleStream};
use crate::scene::Scene;
#[cfg(not(target_arch = "x86_64"))]
use facette_bsdf::lanes::F32x8;
use facette_bsdf::lanes::{channels, Bits32, LFrame, LVec3, Mask, Real};
#[cfg(target_arch = "x86_64")]
use facette_bsdf::lanes::{F32x8Avx2, F32x8Sse2};
use facette_bsdf::math::rng::RandomSource;
use facette_bsdf::math::warp::square_to_uniform_sphere_lanes;
use facette_bsdf::math::Frame;
use facette_bsdf::models::{LaneBsdf, LaneColors, LaneRandom, OwnColors};
use facette_bsdf::{BsdfContext, LobeFlags, Spectrum};
use std::ops::Range;

/// Paths in flight per thread.
pub const LANES: usize = 8;

/// A set of lanes, lane `i` in bit `i`.
type Lanes = u8;

/// Lanes of `A` as lanes of `B` (rounded to `B`'s precision): geometry lanes to shading
/// lanes and back.
#[inline(always)]
fn conv<A: Real, B: Real>(x: A) -> B {
    B::from_fn(|i| x.lane(i))
}

/// [`conv`] for vectors.
#[inline(always)]
fn conv_vec<A: Real, B: Real>(v: LVec3<A>) -> LVec3<B> {
    LVec3::new(conv(v.x), conv(v.y), conv(v.z))
}

/// The mask of a lane set, in lanes of `R` (8 lanes).
#[inline(always)]
fn mask<R: Real>(set: Lanes) -> R::Mask {
    R::Mask::from_lane_bits(set as u32)
}

/// The lane set of a mask of 8 lanes.
#[inline(always)]
fn set_of<M: Mask>(m: M) -> Lanes {
    m.lane_bits() as Lanes
}

/// `v` where the lane is in `set`, else `keep`.
#[inline(always)]
fn merge<R: Real>(set: Lanes, v: R, keep: R) -> R {
    R::select(mask::<R>(set), v, keep)
}

/// A spectrum per lane: three channels of lanes.
type Rgb<S> = [S; 3];

#[inline(always)]
fn rgb_splat<S: Real>(c: Spectrum) -> Rgb<S> {
    channels(|k| S::splat(c[k]))
}

/// The shadow ray from `o` (already offset) to `end`: its unit direction and length
/// (`Ray::spawn_to`'s segment). A degenerate segment gets length 0, so it tests nothing.
#[inline(always)]
fn shadow_segment<G: Real>(o: LVec3<G>, end: LVec3<G>) -> (LVec3<G>, G) {
    let seg = end - o;
    let len = seg.length_squared().sqrt();
    let seg_ok = len.gt(G::zero()) & len.is_finite();
    (seg.scale(G::one() / len), G::select(seg_ok, len, G::zero()))
}

#[inline(always)]
fn rgb_lane<S: Real>(c: &Rgb<S>, i: usize) -> Spectrum {
    Spectrum([c[0].lane(i), c[1].lane(i), c[2].lane(i)])
}

/// Sets lane `i` of a spectrum to `v`.
#[inline(always)]
fn rgb_set<S: Real>(c: &mut Rgb<S>, i: usize, v: Spectrum) {
    for k in 0..3 {
        c[k].set_lane(i, v[k]);
    }
}

/// The eight paths of a thread: shading values in lanes of `S`, rays and points in lanes
/// of `G`.
struct Paths<S: ShadingLanes, G: Real> {
    /// Lanes holding a path.
    live: Lanes,
    /// Each lane's pixel, as an index into the tile's sums.
    slot: [u32; LANES],
    streams: LaneStreams,
    samples: SampleLanes,
    o: LVec3<G>,
    d: LVec3<G>,
    /// The camera ray's differentials (only where materials read footprints).
    rd: [Option<RayDifferential>; LANES],
    /// The camera ray's pixel centre ray (only where materials read pixel footprints).
    pixel: [Option<PixelRay>; LANES],
    l: Rgb<S>,
    beta: Rgb<S>,
    delta_prev: Lanes,
    prev_pdf: S,
    prev_p: LVec3<G>,
    eta_scale: S,
    /// Segments so far (the camera ray is segment 1).
    segment: S::Bits,
}

/// The ray queries' results of the current segment and the materials at its hits, kept
/// across segments so that the queries write only the lanes that hit (see
/// [`SceneGeometry::hit_lanes`]) and a vertex writes only its live lanes' materials.
struct SegmentHits<'s, G: Real> {
    hits: [PacketHit; LANES],
    record: HitLanes<G>,
    vertex: VertexMaterials<'s>,
}

impl<G: Real> Default for SegmentHits<'_, G> {
    fn default() -> Self {
        SegmentHits {
            hits: Default::default(),
            record: HitLanes::default(),
            vertex: VertexMaterials::default(),
        }
    }
}

/// The textured lane materials' values at the hits of a segment: only the textured lanes'
/// entries are written (and read).
#[derive(Default)]
struct LaneTexels {
    /// A textured lane's colors ([`VertexBsdf::Lane`]).
    colors: [LaneColors<f64>; LANES],
    /// A lane's own model ([`VertexBsdf::Owned`]).
    models: [Option<LaneBsdf>; LANES],
}

/// Up to eight camera rays, made together, waiting for lanes.
struct CameraBatch<G: Real> {
    count: usize,
    next: usize,
    slot: [u32; LANES],
    streams: LaneStreams,
    samples: SampleLanes,
    o: LVec3<G>,
    d: LVec3<G>,
    rd: [Option<RayDifferential>; LANES],
    pixel: [Option<PixelRay>; LANES],
}

/// Each lane's [`SampleStream`], made at its first use from the lane's camera sample: a lane
/// whose sample has a lane form ([`SampleLanes`]) draws its numbers in lanes and needs its
/// stream only when a model asks for further numbers (stochastic models, the f64 models
/// lane by lane), so most camera samples never make one (making and moving it cost about
/// 200 instructions a camera sample). A stream made late is the stream made early: it is a
/// pure function of (seed, pixel, sample number), and nothing draws from it before.
struct LaneStreams {
    streams: [SampleStream; LANES],
    /// Each lane's camera sample: pixel x, y and sample number.
    x: [u32; LANES],
    y: [u32; LANES],
    sample: [u32; LANES],
    /// The lanes whose stream is made.
    made: Lanes,
}

impl LaneStreams {
    fn new(sampler: &PixelSampler) -> Self {
        LaneStreams {
            streams: std::array::from_fn(|_| sampler.stream(0, 0, 0)),
            x: [0; LANES],
            y: [0; LANES],
            sample: [0; LANES],
            made: 0,
        }
    }

    /// The first `n` lanes hold the camera samples of `jobs`; their streams are not made.
    #[inline(always)]
    fn assign(&mut self, jobs: &JobLanes, n: usize) {
        (self.x, self.y, self.sample) = (jobs.x, jobs.y, jobs.sample);
        self.made &= !(((1u32 << n) - 1) as Lanes);
    }

    /// The lanes `i` of `set` take lane `src[i]` of `from` (their streams too, where made);
    /// `taken` is the set of those lanes of `from`. Only the camera sample is copied in the
    /// common case, where no stream of `from` is made.
    #[inline(always)]
    fn take<B: Bits32>(
        &mut self,
        set: Lanes,
        from: &mut LaneStreams,
        src: &[u8; LANES],
        taken: Lanes,
    ) {
        move_lanes::<B>(&mut self.x, &from.x, src, set);
        move_lanes::<B>(&mut self.y, &from.y, src, set);
        move_lanes::<B>(&mut self.sample, &from.sample, src, set);
        self.made &= !set;
        if from.made & taken != 0 {
            for i in lanes_of(set) {
                let j = src[i] as usize;
                if from.made & (1 << j) != 0 {
                    std::mem::swap(&mut self.streams[i], &mut from.streams[j]);
                    from.made &= !(1 << j);
                    self.made |= 1 << i;
                }
            }
        }
    }

    /// Makes the streams of `set` that are not made yet.
    #[inline(always)]
    fn make(&mut self, set: Lanes, sampler: &PixelSampler) {
        for i in lanes_of(set & !self.made) {
            let (x, y, s) = (self.x[i], self.y[i], self.sample[i]);
            self.streams[i] = sampler.stream(x as usize, y as usize, s as u64);
        }
        self.made |= set;
    }

    /// Lane `i`'s stream, made if it was not.
    #[inline(always)]
    fn lane(&mut self, i: usize, sampler: &PixelSampler) -> &mut SampleStream {
        self.make(1 << i, sampler);
        &mut self.streams[i]
    }

    /// Every stream, for the sampler's lanes without a lane form (made when assigned:
    /// see [`Kernel::make_batch`]).
    #[inline(always)]
    fn all(&mut self) -> &mut [SampleStream; LANES] {
        &mut self.streams
    }
}

/// The (pixel, sample) jobs of a tile, row by row; `stop` is asked before each row.
struct Jobs<'a> {
    xs: Range<usize>,
    ys: Range<usize>,
    chunk: &'a [u32],
    /// The next job: row, column, index into `chunk`, and the pixel's slot (row-major in
    /// the tile); `k < chunk.len()`.
    y: usize,
    x: usize,
    k: usize,
    slot: u32,
    /// Whether the next job's row is started (its `stop` asked and counted).
    row_started: bool,
    rows_started: usize,
    stop: &'a dyn Fn() -> bool,
    ended: bool,
}

impl<'a> Jobs<'a> {
    fn new(job: &TileJob<'a>) -> Self {
        Jobs {
            xs: job.xs.clone(),
            ys: job.ys.clone(),
            chunk: job.chunk,
            y: job.ys.start,
            x: job.xs.start,
            k: 0,
            slot: 0,
            row_started: false,
            rows_started: 0,
            stop: job.stop,
            ended: job.chunk.is_empty() || job.xs.is_empty(),
        }
    }

    /// The next (up to) eight jobs into `out`; returns how many (0 when none is left).
    #[inline(always)]
    fn next_batch(&mut self, out: &mut JobLanes) -> usize {
        let mut n = 0;
        while n < LANES && !self.ended {
            if !self.row_started {
                if self.y >= self.ys.end || (self.stop)() {
                    self.ended = true;
                    break;
                }
                self.rows_started += 1;
                self.row_started = true;
            }
            out.x[n] = self.x as u32;
            out.y[n] = self.y as u32;
            out.sample[n] = self.chunk[self.k];
            out.slot[n] = self.slot;
            n += 1;
            self.k += 1;
            if self.k == self.chunk.len() {
                self.k = 0;
                self.x += 1;
                self.slot += 1;
                if self.x == self.xs.end {
                    self.x = self.xs.start;
                    self.y += 1;
                    self.row_started = false;
                }
            }
        }
        n
    }
}

/// A batch of jobs: pixel x, y, sample index and slot of each lane (zeros past the
/// batch's count).
#[derive(Default)]
struct JobLanes {
    x: [u32; LANES],
    y: [u32; LANES],
    sample: [u32; LANES],
    slot: [u32; LANES],
}

/// What the render loop gives the kernel.
pub(crate) struct TileJob<'a> {
    pub scene: &'a Scene,
    pub sampler: &'a PixelSampler,
    pub cameras: CameraSampling,
    pub strategy: Strategy,
    pub xs: Range<usize>,
    pub ys: Range<usize>,
    pub chunk: &'a [u32],
    /// Asked before each row is started: stop there.
    pub stop: &'a dyn Fn() -> bool,
}

/// Renders every sample of `job.chunk` for the tile's pixels and adds them to `sums`
/// (row-major, one entry per pixel of the tile: made, zeroed, when `sums` does not have that
/// length, and otherwise added to, so that a tile's sums gather all passes and reach the
/// film once), with the widest lanes this CPU runs; returns the number of rows started (a
/// stop leaves the later rows out: their entries get nothing from this call).
pub(crate) fn render_tile(job: &TileJob, sums: &mut Vec<PixelSums>) -> usize {
    #[cfg(target_arch = "x86_64")]
    if facette_bsdf::lanes::avx2::available() {
        // SAFETY: the CPU has the features the function is compiled for.
        return unsafe { render_tile_avx2(job, sums) };
    }
    render_tile_portable(job, sums)
}

/// [`render_tile`] in the portable build ([`PortableLanes`]), a function of its own so that
/// the tests call this very copy rather than compile another.
#[inline(never)]
pub(crate) fn render_tile_portable(job: &TileJob, sums: &mut Vec<PixelSums>) -> usize {
    render_tile_lanes::<PortableLanes, PortableLanes>(job, sums)
}

/// The portable build's lanes, for shading and geometry alike. On x86-64 the SSE2 register
/// lanes: over the array lanes the kernel had cost LLVM 115–146 s to compile (its SLP
/// vectorizer searching the kernel's large functions for the array loops to fuse), in each
/// build that holds it, and left a third of the code 4-wide and scalar (docs/performance.md,
/// "The test build"). Elsewhere (aarch64) the array lanes, which compute the same bits.
///
/// Geometry (rays, hit records, spawned origins) is in f32 like the shading, as in the AVX2
/// build, whose lanes compute the same bits: an image (and each part of a `--part K/N`
/// run) is the same on every x86-64 CPU. f32 geometry spawns rays with the f32 offset
/// (`geometry::ray`, tested off spheres and meshes far from the origin) and renders the
/// image of f64 geometry within rounding (the test below). With the AVX2 register lanes it
/// costs 1,371 instructions a bench-sphere sample against 1,741 with `F64x8` geometry.
#[cfg(target_arch = "x86_64")]
type PortableLanes = F32x8Sse2;
#[cfg(not(target_arch = "x86_64"))]
type PortableLanes = F32x8;

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn render_tile_avx2(job: &TileJob, sums: &mut Vec<PixelSums>) -> usize {
    render_tile_lanes::<F32x8Avx2, F32x8Avx2>(job, sums)
}

/// [`render_tile`] with shading lanes `S` and geometry lanes `G` (8 lanes each:
/// [`PortableLanes`] for both in the portable build's renders, `F32x8Avx2` for both in the AVX2
/// build's; f64 lanes for both in the test that finds the scalar integrator's image).
#[inline(always)]
pub(crate) fn render_tile_lanes<S: ShadingLanes, G: Real>(
    job: &TileJob,
    sums: &mut Vec<PixelSums>,
) -> usize {
    debug_assert_eq!(S::LANES, LANES);
    let pixels = job.xs.len() * job.ys.len();
    if sums.len() != pixels {
        sums.clear();
        sums.resize(pixels, PixelSums::default());
    }
    let mut jobs = Jobs::new(job);
    let mut batch = CameraBatch::<G> {
        count: 0,
        next: 0,
        slot: [0; LANES],
        streams: LaneStreams::new(job.sampler),
        samples: SampleLanes::default(),
        o: LVec3::zero(),
        d: LVec3::zero(),
        rd: [None; LANES],
        pixel: [None; LANES],
    };
    let mut segment = SegmentHits::default();
    let mut paths = Paths::<S, G> {
        live: 0,
        slot: [0; LANES],
        streams: LaneStreams::new(job.sampler),
        samples: SampleLanes::default(),
        o: LVec3::zero(),
        d: LVec3::zero(),
        rd: [None; LANES],
        pixel: [None; LANES],
        l: [S::zero(); 3],
        beta: [S::one(); 3],
        delta_prev: 0,
        prev_pdf: S::zero(),
        prev_p: LVec3::zero(),
        eta_scale: S::one(),
        segment: S::Bits::splat(1),
    };
    let lane_materials = job.scene.materials.iter().filter_map(|m| m.lane_bsdf());
    let k = Kernel {
        scene: job.scene,
        sampler: job.sampler,
        cameras: job.cameras,
        strategy: job.strategy,
        ctx: crate::integrator::bsdf_context(job.scene, job.strategy),
        lane_materials: lane_materials.clone().next().is_some(),
        lobe_numbers: lane_materials.clone().any(|m| m.reads_lobe_number()),
        area_lights: job.scene.shape_light.iter().any(Option::is_some),
        one_material: job.scene.shape_material.windows(2).all(|w| w[0] == w[1]),
    };
    loop {
        k.refill(&mut paths, &mut batch, &mut jobs);
        if paths.live == 0 {
            break;
        }
        k.step(&mut paths, &mut segment, sums);
    }
    jobs.rows_started
}

/// The scene and settings of a render.
struct Kernel<'a> {
    scene: &'a Scene,
    sampler: &'a PixelSampler,
    cameras: CameraSampling,
    strategy: Strategy,
    /// The f64 models' context: whether a sample's density is read (see
    /// [`crate::integrator::bsdf_context`]).
    ctx: BsdfContext,
    /// Whether some material has a lane model, and whether one of them reads a lobe
    /// number (a textured roughness keeps its material's model kind): which of a vertex's
    /// numbers [`Kernel::vertex_numbers`] draws.
    lane_materials: bool,
    lobe_numbers: bool,
    /// Whether some shape emits (else a hit never finds emission).
    area_lights: bool,
    /// Whether every shape has the same material (then every hit's lanes share it).
    one_material: bool,
}

/// A vertex's numbers drawn ahead, at the start of its segment, for every live lane
/// ([`Kernel::vertex_numbers`]); ½ where nobody reads them.
struct VertexNumbers<S> {
    select: S,
    light: (S, S),
    lobe: S,
    bsdf: (S, S),
}

/// The materials of a vertex: each lane's, the lanes whose material is a lane model, and
/// whether those lanes share one model (then a model's group is found without comparing
/// lanes) — found once, where the materials are looked up.
struct VertexMaterials<'s> {
    /// The live lanes' materials (the other lanes' are left from earlier vertices).
    bsdfs: [VertexBsdf<'s>; LANES],
    lane_models: Lanes,
    one_lane_model: bool,
    /// The lanes of [`VertexBsdf::Lane`] whose colors are textured.
    textured: Lanes,
    texels: LaneTexels,
}

impl Default for VertexMaterials<'_> {
    fn default() -> Self {
        VertexMaterials {
            bsdfs: std::array::from_fn(|_| VertexBsdf::None),
            lane_models: 0,
            one_lane_model: true,
            textured: 0,
            texels: LaneTexels::default(),
        }
    }
}

impl VertexMaterials<'_> {
    /// The lanes of `todo` whose lane model is `model`.
    #[inline(always)]
    fn group_of(&self, model: &LaneBsdf, todo: Lanes) -> Lanes {
        if self.one_lane_model {
            return todo & self.lane_models;
        }
        lanes_of(todo)
            .filter(|&i| matches!(&self.bsdfs[i], VertexBsdf::Lane(m) if std::ptr::eq(*m, model)))
            .fold(0, |s, i| s | (1 << i))
    }

    /// The lane model of `todo`'s first lane, the lanes of `todo` that share it, and
    /// whether their colors are textured; `None` where `todo` is empty or its first lane
    /// has no lane model.
    #[inline(always)]
    fn lane_group(&self, todo: Lanes) -> Option<(&LaneBsdf, Lanes, bool)> {
        if todo == 0 {
            return None;
        }
        let first = todo.trailing_zeros() as usize;
        match &self.bsdfs[first] {
            VertexBsdf::Lane(model) => {
                let group = self.group_of(model, todo);
                Some((model, group, group & self.textured != 0))
            }
            VertexBsdf::Owned => Some((self.texels.models[first].as_ref()?, 1 << first, false)),
            _ => None,
        }
    }

    /// The textured colors of the lanes, as lanes.
    #[inline(always)]
    fn lane_colors<S: Real>(&self) -> LaneColors<S> {
        LaneColors::from_points(|i| &self.texels.colors[i])
    }
}

/// One lane's material at a vertex.
enum VertexBsdf<'s> {
    None,
    /// A material's lane model (with the vertex's colors where the lane is textured).
    Lane(&'s LaneBsdf),
    /// A lane model built for this lane (a textured roughness), in [`LaneTexels::models`].
    Owned,
    Scalar(MaterialBsdf<'s>),
}

impl<'s> Kernel<'s> {
    /// Fills the empty lanes with camera rays, making a new batch when the last is used up.
    #[inline(always)]
    fn refill<S: ShadingLanes, G: Real>(
        &self,
        paths: &mut Paths<S, G>,
        batch: &mut CameraBatch<G>,
        jobs: &mut Jobs,
    ) {
        let mut free = !paths.live;
        let mut filled: Lanes = 0;
        // The free lanes take the batch's next rays in order, a batch at a time: each lane
        // array (ray coordinates, pixel slot, sampler words, camera sample) by one
        // permutation and one blend; only ray differentials, where read, lane by lane.
        while free != 0 {
            if batch.next == batch.count && !self.make_batch::<S, G>(batch, jobs) {
                break;
            }
            let mut from = [0u8; LANES];
            let mut set: Lanes = 0;
            let first = batch.next;
            while free != 0 && batch.next < batch.count {
                let i = free.trailing_zeros() as usize;
                free &= free - 1;
                let j = batch.next;
                batch.next += 1;
                from[i] = j as u8;
                set |= 1 << i;
                if self.cameras.footprints {
                    paths.rd[i] = batch.rd[j];
                    paths.pixel[i] = batch.pixel[j];
                }
            }
            let taken = ((1u32 << batch.next) - (1u32 << first)) as Lanes;
            move_lanes::<S::Bits>(&mut paths.slot, &batch.slot, &from, set);
            paths
                .streams
                .take::<S::Bits>(set, &mut batch.streams, &from, taken);
            paths
                .samples
                .take::<S::Bits>(set, &batch.samples, &from, taken);
            let m = mask::<G>(set);
            paths.o = LVec3::select(m, batch.o.permute(&from), paths.o);
            paths.d = LVec3::select(m, batch.d.permute(&from), paths.d);
            filled |= set;
        }
        if filled == 0 {
            return;
        }
        paths.live |= filled;
        for c in 0..3 {
            paths.l[c] = merge(filled, S::zero(), paths.l[c]);
            paths.beta[c] = merge(filled, S::one(), paths.beta[c]);
        }
        paths.delta_prev |= filled;
        paths.prev_pdf = merge(filled, S::zero(), paths.prev_pdf);
        paths.eta_scale = merge(filled, S::one(), paths.eta_scale);
        paths.prev_p = LVec3::select(mask::<G>(filled), paths.o, paths.prev_p);
        paths.segment = S::Bits::blend_bits(filled, S::Bits::splat(1), paths.segment);
    }

    /// The camera rays of the next (up to) eight jobs; `false` when no job is left.
    #[inline(always)]
    fn make_batch<S: ShadingLanes, G: Real>(
        &self,
        batch: &mut CameraBatch<G>,
        jobs: &mut Jobs,
    ) -> bool {
        let mut lanes = JobLanes::default();
        let n = jobs.next_batch(&mut lanes);
        let (xs, ys, ss, slot) = (lanes.x, lanes.y, lanes.sample, lanes.slot);
        batch.streams.assign(&lanes, n);
        batch.slot = slot;
        batch.count = n;
        batch.next = 0;
        if n == 0 {
            return false;
        }
        batch.samples = self.sampler.lane_words_batch::<S::Bits>(&xs, &ys, &ss, n);
        let active: Lanes = ((1u32 << n) - 1) as Lanes;
        // Samples without a lane form read every number from their streams: made now.
        batch
            .streams
            .make(active & !batch.samples.fast(), self.sampler);
        let scene = self.scene;
        // The filter offset (dimensions 0, 1), then the lens position (2, 3) where read.
        let (u0, u1) = self.sampler.get_lanes::<S, S::Bits>(
            &batch.samples,
            batch.streams.all(),
            S::Bits::splat(0),
            active,
            true,
        );
        let (ox, oy) = scene.film.filter.sample_lanes(u0, u1);
        let fx = G::from_fn(|i| xs[i] as f64 + 0.5) + conv(ox);
        let fy = G::from_fn(|i| ys[i] as f64 + 0.5) + conv(oy);
        let lens = if scene.camera.has_lens() {
            let (l0, l1) = self.sampler.get_lanes::<S, S::Bits>(
                &batch.samples,
                batch.streams.all(),
                S::Bits::splat(2),
                active,
                true,
            );
            (conv(l0), conv(l1))
        } else {
            (G::splat(0.5), G::splat(0.5))
        };
        if self.cameras.footprints {
            for i in 0..n {
                let lens = crate::geometry::Vec2::new(lens.0.lane(i), lens.1.lane(i));
                let (ray, rd) = scene.camera.generate_ray(fx.lane(i), fy.lane(i), lens);
                batch.o.set_lane(i, ray.origin);
                batch.d.set_lane(i, ray.dir);
                batch.rd[i] = Some(rd.scaled(&ray, self.cameras.diff_scale));
                batch.pixel[i] = self
                    .cameras
                    .pixel_footprints
                    .then(|| PixelRay::new(&scene.camera, xs[i], ys[i], lens));
            }
        } else {
            (batch.o, batch.d) = scene.camera.primary_rays(fx, fy, lens);
            batch.rd = [None; LANES];
            batch.pixel = [None; LANES];
        }
        true
    }

    /// MIS weight of emission found by the BSDF sample of the previous vertex, whose
    /// density was `prev_pdf`, against light sampling's density `pl`.
    #[inline(always)]
    fn emission_weight<S: Real>(&self, delta_prev: Lanes, prev_pdf: S, pl: S) -> S {
        let w = match self.strategy {
            Strategy::Mis => power_heuristic_lanes(prev_pdf, pl),
            Strategy::NeeOnly => S::zero(),
            Strategy::BsdfOnly => S::one(),
        };
        merge(delta_prev, S::one(), w)
    }

    /// Adds `beta · le · w` to the lanes of `set`.
    #[inline(always)]
    fn add_radiance<S: ShadingLanes, G: Real>(
        paths: &mut Paths<S, G>,
        set: Lanes,
        le: &Rgb<S>,
        w: S,
    ) {
        for ((l, beta), le) in paths.l.iter_mut().zip(&paths.beta).zip(le) {
            *l = merge(set, *l + *beta * *le * w, *l);
        }
    }

    /// Ends the paths of `set`: their radiance goes to their pixels.
    #[inline(always)]
    fn finish<S: ShadingLanes, G: Real>(
        paths: &mut Paths<S, G>,
        set: Lanes,
        sums: &mut [PixelSums],
    ) {
        // Which lanes' radiance is finite and not negative, for all lanes at once.
        let ok = paths.l.iter().fold(set, |ok, c| {
            ok & set_of(c.is_finite()) & set_of(c.ge(S::zero()))
        });
        // The channels as f64 arrays once, not a lane at a time.
        let l: [[f64; LANES]; 3] =
            std::array::from_fn(|c| std::array::from_fn(|i| paths.l[c].lane(i)));
        for i in lanes_of(set) {
            let sum = &mut sums[paths.slot[i] as usize];
            if ok & (1 << i) != 0 {
                sum.add_valid(Spectrum([l[0][i], l[1][i], l[2][i]]));
            } else {
                sum.add_invalid();
            }
        }
        paths.live &= !set;
    }

    /// Advances every live lane by one path segment.
    #[inline(always)]
    fn step<S: ShadingLanes, G: Real>(
        &self,
        paths: &mut Paths<S, G>,
        segment: &mut SegmentHits<'s, G>,
        sums: &mut [PixelSums],
    ) {
        let scene = self.scene;
        let block = paths
            .segment
            .wrapping_add(S::Bits::splat(u32::MAX))
            .wrapping_mul(S::Bits::splat(VERTEX_DIMENSIONS))
            .wrapping_add(S::Bits::splat(CAMERA_DIMENSIONS));
        let numbers = self.vertex_numbers(paths, block);
        let rays = LaneRays::new(paths.o, paths.d, G::splat(f64::INFINITY), paths.live);
        let (hit_set, hit_t) = scene.geometry.intersect_lanes(&rays, &mut segment.hits);
        let missed = paths.live & !hit_set;
        if missed != 0 {
            self.environment(paths, missed);
            Self::finish(paths, missed, sums);
        }
        if paths.live == 0 {
            return;
        }
        scene
            .geometry
            .hit_lanes(&rays, &segment.hits, (hit_set, hit_t), &mut segment.record);
        let hl = &segment.record;
        self.area_emission(paths, hl);
        // segment ≥ max_depth (the count starts at 1, so max_depth 0 ends every path too).
        let deep = paths
            .segment
            .above_bits(scene.integrator.max_depth.saturating_sub(1))
            & paths.live;
        if deep != 0 {
            Self::finish(paths, deep, sums);
        }
        if paths.live == 0 {
            return;
        }
        // The materials.
        let vertex = &mut segment.vertex;
        let (mut lane_models, mut textured): (Lanes, Lanes) = (0, 0);
        let mut one_lane_model = true;
        let mut first_model: Option<&LaneBsdf> = None;
        let mut smooth: Lanes = 0;
        let mut no_bsdf: Lanes = 0;
        // Lanes that shade in their pixel centre's frame (pixel footprints).
        let mut reframed: Lanes = 0;
        let mut centre_frames: [Option<Frame>; LANES] = [None; LANES];
        // Most vertices' lanes share one untextured lane material (a single object, or
        // paths in step): its lanes are set at once.
        let live = paths.live;
        let material_of = |i: usize| scene.shape_material[hl.shape[i] as usize];
        let shared = material_of(live.trailing_zeros() as usize);
        let shared_lane = match &scene.materials[shared as usize] {
            m if m.is_textured() => None,
            m => m.lane_bsdf(),
        };
        let per_lane = match shared_lane {
            Some(lane) if self.one_material || lanes_of(live).all(|i| material_of(i) == shared) => {
                for i in lanes_of(live) {
                    vertex.bsdfs[i] = VertexBsdf::Lane(lane);
                }
                lane_models = live;
                if lane.flags().has_smooth_part() {
                    smooth = live;
                }
                0
            }
            _ => live,
        };
        for i in lanes_of(per_lane) {
            let material = scene.shape_material[hl.shape[i] as usize] as usize;
            let m = &scene.materials[material];
            vertex.bsdfs[i] = match m.lane_bsdf() {
                Some(lane) => {
                    let bsdf = if m.is_textured() {
                        let (uv, derivs, _) = self.surface_details(paths, hl, m, i);
                        match m.lane_texel(uv, derivs) {
                            Some(LaneTexel::Colors(c)) => {
                                vertex.texels.colors[i] = c;
                                textured |= 1 << i;
                                VertexBsdf::Lane(lane)
                            }
                            Some(LaneTexel::Model(own)) => {
                                one_lane_model = false;
                                vertex.texels.models[i] = Some(own);
                                VertexBsdf::Owned
                            }
                            None => {
                                no_bsdf |= 1 << i;
                                continue;
                            }
                        }
                    } else {
                        VertexBsdf::Lane(lane)
                    };
                    lane_models |= 1 << i;
                    match first_model {
                        None => first_model = Some(lane),
                        Some(f) => one_lane_model &= std::ptr::eq(f, lane),
                    }
                    if lane.flags().has_smooth_part() {
                        smooth |= 1 << i;
                    }
                    bsdf
                }
                None => {
                    let (uv, derivs, frame) = self.surface_details(paths, hl, m, i);
                    if let Some(f) = frame {
                        centre_frames[i] = Some(f);
                        reframed |= 1 << i;
                    }
                    match m.bsdf(uv, derivs) {
                        Some(b) => {
                            if b.flags().has_smooth_part() {
                                smooth |= 1 << i;
                            }
                            VertexBsdf::Scalar(b)
                        }
                        None => {
                            no_bsdf |= 1 << i;
                            continue;
                        }
                    }
                }
            };
        }
        if no_bsdf != 0 {
            Self::finish(paths, no_bsdf, sums);
        }
        vertex.lane_models = lane_models;
        vertex.one_lane_model = one_lane_model;
        vertex.textured = textured;
        let vertex = &segment.vertex;
        let mut frame = LFrame::from_normal_tangent(hl.ns, hl.dpdu);
        for i in lanes_of(reframed & paths.live) {
            if let Some(f) = centre_frames[i] {
                frame.s.set_lane(i, f.s);
                frame.t.set_lane(i, f.t);
                frame.n.set_lane(i, f.n);
            }
        }
        let wo = conv_vec::<G, S>(frame.to_local(-paths.d));
        if self.strategy != Strategy::BsdfOnly {
            let set = smooth & paths.live;
            self.next_event(paths, hl, &frame, wo, vertex, set, &numbers);
        }
        self.continue_paths(paths, hl, &frame, wo, vertex, block, &numbers, sums);
    }

    /// The numbers of the vertex at the end of this segment that every lane with a lane
    /// material draws (light selection and position, lobe, direction; not the roulette's,
    /// drawn from depth 5 on), drawn for every live lane before the ray query: they depend
    /// only on the lane's sample and the vertex's dimension block, and their hash chains
    /// (Sobol: four dependent 10-cycle `vpmulld`s a scramble) then run beside the query's
    /// floating-point work instead of stalling the shading that reads them. Lanes that miss,
    /// or do not read a number, leave it unused; draws have no state (each names its
    /// dimension), so the values are those drawn where they are used.
    #[inline(always)]
    fn vertex_numbers<S: ShadingLanes, G: Real>(
        &self,
        paths: &mut Paths<S, G>,
        block: S::Bits,
    ) -> VertexNumbers<S> {
        // No closures here: a closure is compiled with its defining function's instruction
        // set, and this one is generic, without the AVX2 build's (see `lanes::channels`).
        let (selector, live) = (&self.scene.selector, paths.live);
        let nee = self.strategy != Strategy::BsdfOnly;
        let half = (S::splat(0.5), S::splat(0.5));
        VertexNumbers {
            select: if nee && selector.reads_selection_number() {
                self.draw(paths, block, 0, live, false).0
            } else {
                half.0
            },
            light: if nee && selector.reads_position_numbers() {
                self.draw(paths, block, 1, live, true)
            } else {
                half
            },
            lobe: if self.lobe_numbers {
                self.draw(paths, block, 3, live, false).0
            } else {
                half.0
            },
            bsdf: if self.lane_materials {
                self.draw(paths, block, 4, live, true)
            } else {
                half
            },
        }
    }

    /// The number of dimension `block + offset` (and the next where `pair`) of each lane
    /// of `set` (the others hold ½).
    #[inline(always)]
    fn draw<S: ShadingLanes, G: Real>(
        &self,
        paths: &mut Paths<S, G>,
        block: S::Bits,
        offset: u32,
        set: Lanes,
        pair: bool,
    ) -> (S, S) {
        self.sampler.get_lanes::<S, S::Bits>(
            &paths.samples,
            paths.streams.all(),
            block.wrapping_add(S::Bits::splat(offset)),
            set,
            pair,
        )
    }

    /// Lane `i`'s texture coordinates and footprint where its material `m` reads them (what
    /// the scalar integrator computes at the same hit), zeros otherwise; and, where `m`
    /// shades a camera ray's hit with its pixel's footprint, the pixel centre's shading
    /// frame, which the lane shades in ([`crate::pixel_footprint`]).
    #[inline(always)]
    fn surface_details<S: ShadingLanes, G: Real>(
        &self,
        paths: &Paths<S, G>,
        hl: &HitLanes<G>,
        m: &SceneMaterial,
        i: usize,
    ) -> (crate::geometry::Vec2, [f64; 4], Option<Frame>) {
        let mut hit = hl.surface_hit(i);
        let mut derivs = [0.0; 4];
        if m.reads_surface_details() {
            self.scene.geometry.complete_hit(&mut hit);
            if let (Some(d), 1) = (&paths.rd[i], paths.segment.lane(i)) {
                let centre = paths.pixel[i]
                    .filter(|_| m.reads_pixel_footprint())
                    .and_then(|p| pixel_shading(self.scene, &hit, paths.d.lane(i), &p));
                if let Some(c) = centre {
                    return (c.uv, c.derivs, Some(c.frame));
                }
                derivs = hit.uv_derivatives(d);
            }
        }
        (hit.uv, derivs, None)
    }

    /// Emission seen by the rays of `missed` leaving the scene.
    #[inline(always)]
    fn environment<S: ShadingLanes, G: Real>(&self, paths: &mut Paths<S, G>, missed: Lanes) {
        let scene = self.scene;
        let Some(env) = scene.environment else { return };
        let Light::Environment(e) = &scene.lights[env as usize] else {
            return;
        };
        let p_select = scene.selector.probability(env as usize);
        if let Environment::Constant(c) = e {
            // Every valid direction sees the same radiance, at the density 1/4π.
            let valid = paths.d.length_squared().gt(G::zero())
                & paths.d.x.is_finite()
                & paths.d.y.is_finite()
                & paths.d.z.is_finite();
            let set = missed & set_of(valid);
            let pl = S::splat(p_select * constant_pdf(c));
            let w = self.emission_weight(paths.delta_prev, paths.prev_pdf, pl);
            Self::add_radiance(paths, set, &rgb_splat(c.mean_radiance()), w);
            return;
        }
        if let Environment::Map(map) = e {
            if map.serves_lanes::<S>() {
                // Every lane's look-up at once; the black ones (zero luminance) add nothing.
                let (le, pdf) = S::eval_environment(map, conv_vec::<G, S>(paths.d));
                let lit = le[0].gt(S::zero()) | le[1].gt(S::zero()) | le[2].gt(S::zero());
                let set = missed & set_of(lit);
                if set != 0 {
                    let pl = S::splat(p_select) * pdf;
                    let w = self.emission_weight(paths.delta_prev, paths.prev_pdf, pl);
                    Self::add_radiance(paths, set, &le, w);
                }
                return;
            }
        }
        for i in lanes_of(missed) {
            let dir = paths.d.lane(i);
            let (le, pdf) = e.eval_pdf(dir);
            if le.is_black() {
                continue;
            }
            let pl = p_select * pdf;
            let w = self
                .emission_weight(
                    paths.delta_prev & (1 << i),
                    S::splat(paths.prev_pdf.lane(i)),
                    S::splat(pl),
                )
                .lane(i);
            let beta = rgb_lane(&paths.beta, i);
            let l = rgb_lane(&paths.l, i) + beta * le * w;
            rgb_set(&mut paths.l, i, l);
        }
    }

    /// Emission of the area lights the hits of `hl` lie on.
    #[inline(always)]
    fn area_emission<S: ShadingLanes, G: Real>(&self, paths: &mut Paths<S, G>, hl: &HitLanes<G>) {
        if !self.area_lights {
            return;
        }
        let scene = self.scene;
        for i in lanes_of(hl.lanes & paths.live) {
            let Some(li) = scene.shape_light[hl.shape[i] as usize] else {
                continue;
            };
            let light = &scene.lights[li as usize];
            let (ng, dir) = (hl.ng.lane(i), paths.d.lane(i));
            let le = light.emitted(ng, -dir);
            if le.is_black() {
                continue;
            }
            let pl = scene.selector.probability(li as usize)
                * light.pdf_area_hit(
                    &scene.geometry,
                    paths.prev_p.lane(i),
                    hl.p.lane(i),
                    ng,
                    hl.prim[i],
                );
            let w = match self.strategy {
                _ if paths.delta_prev & (1 << i) != 0 => 1.0,
                Strategy::Mis => power_heuristic(paths.prev_pdf.lane(i), pl),
                Strategy::NeeOnly => 0.0,
                Strategy::BsdfOnly => 1.0,
            };
            let l = rgb_lane(&paths.l, i) + rgb_lane(&paths.beta, i) * le * w;
            rgb_set(&mut paths.l, i, l);
        }
    }

    /// Next-event estimation for the lanes of `set`: a light sample each, the materials'
    /// values and densities, one packet of shadow rays.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn next_event<S: ShadingLanes, G: Real>(
        &self,
        paths: &mut Paths<S, G>,
        hl: &HitLanes<G>,
        frame: &LFrame<G>,
        wo: LVec3<S>,
        vertex: &VertexMaterials,
        set: Lanes,
        numbers: &VertexNumbers<S>,
    ) {
        if set == 0 {
            return;
        }
        let scene = self.scene;
        let selector = &scene.selector;
        let u_select = numbers.select;
        let (u0, u1) = numbers.light;
        // The light of each lane.
        let mut light_of = [usize::MAX; LANES];
        let mut p_select = [0.0; LANES];
        let mut chosen: Lanes = 0;
        if selector.reads_selection_number() {
            for i in lanes_of(set) {
                if let Some((k, p)) = selector.select(u_select.lane(i)) {
                    light_of[i] = k;
                    p_select[i] = p;
                    chosen |= 1 << i;
                }
            }
        } else if let Some((k, p)) = selector.select(0.5) {
            // One light can be chosen: every lane's, whatever its number (½ above).
            light_of = [k; LANES];
            p_select = [p; LANES];
            chosen = set;
        }
        // Light samples: direction (world), radiance, density, the shadow ray's origin and
        // length, delta lights.
        let mut wi = LVec3::<G>::zero();
        let mut le: Rgb<S> = [S::zero(); 3];
        let mut pdf_light = S::zero();
        let mut shadow_o = LVec3::<G>::zero();
        let mut shadow_d = LVec3::<G>::zero();
        let mut shadow_t = G::zero();
        let mut delta: Lanes = 0;
        let mut sampled: Lanes = 0;
        let mut todo = chosen;
        let one_light = !selector.reads_selection_number();
        // A light's samples drawn lane by lane in f64: the lights without a lane form, and
        // the lanes an area light's shape draws nothing for in lanes (rectangles and
        // triangles always, a sphere from inside it).
        macro_rules! sample_lane_by_lane {
            ($light:expr, $lanes:expr) => {
                for i in lanes_of($lanes) {
                    let u = crate::geometry::Vec2::new(u0.lane(i), u1.lane(i));
                    let p = hl.p.lane(i);
                    let Some(ls) = $light.sample(&scene.geometry, p, u) else {
                        continue;
                    };
                    if ls.radiance.is_black() {
                        continue;
                    }
                    // The shadow ray offset for the lanes' precision.
                    let shadow = ls.shadow.ray::<G>(p, hl.ng.lane(i));
                    wi.set_lane(i, ls.wi);
                    shadow_o.set_lane(i, shadow.origin);
                    shadow_d.set_lane(i, shadow.dir);
                    shadow_t.set_lane(i, shadow.t_max);
                    rgb_set(&mut le, i, ls.radiance);
                    pdf_light.set_lane(i, ls.pdf);
                    if ls.delta {
                        delta |= 1 << i;
                    }
                    sampled |= 1 << i;
                }
            };
        }
        while todo != 0 {
            let k = light_of[todo.trailing_zeros() as usize];
            let group = if one_light {
                todo
            } else {
                lanes_of(todo)
                    .filter(|&i| light_of[i] == k)
                    .fold(0, |s, i| s | (1 << i))
            };
            todo &= !group;
            let m = mask::<G>(group);
            match &scene.lights[k] {
                Light::Environment(Environment::Constant(c)) if !c.mean_radiance().is_black() => {
                    let dir = conv_vec::<S, G>(square_to_uniform_sphere_lanes(u0, u1));
                    // Ray::spawn: offset along the normal, the direction made unit.
                    let o = offset_origin_lanes(hl.p, hl.ng, dir);
                    wi = LVec3::select(m, dir, wi);
                    shadow_o = LVec3::select(m, o, shadow_o);
                    shadow_d = LVec3::select(m, dir.normalize(), shadow_d);
                    shadow_t = G::select(m, G::splat(f64::INFINITY), shadow_t);
                    let radiance = rgb_splat::<S>(c.mean_radiance());
                    for ch in 0..3 {
                        le[ch] = merge(group, radiance[ch], le[ch]);
                    }
                    pdf_light = merge(group, S::splat(constant_pdf(c)), pdf_light);
                    sampled |= group;
                }
                Light::Point {
                    position,
                    intensity,
                } => {
                    let target = LVec3::splat(*position);
                    let to = target - hl.p;
                    let dist2 = to.length_squared();
                    let dir = to.scale(G::one() / dist2.sqrt());
                    let ok = group & set_of(dist2.gt(G::zero()));
                    // Ray::spawn_to: offset towards the light, then the segment to it.
                    let o = offset_origin_lanes(hl.p, hl.ng, to);
                    let (seg_d, seg_t) = shadow_segment(o, target);
                    let m = mask::<G>(ok);
                    wi = LVec3::select(m, dir, wi);
                    shadow_o = LVec3::select(m, o, shadow_o);
                    shadow_d = LVec3::select(m, seg_d, shadow_d);
                    shadow_t = G::select(m, seg_t, shadow_t);
                    let inv = conv::<G, S>(G::one() / dist2);
                    for ch in 0..3 {
                        le[ch] = merge(ok, S::splat(intensity[ch]) * inv, le[ch]);
                    }
                    pdf_light = merge(ok, S::one(), pdf_light);
                    delta |= ok;
                    sampled |= ok;
                }
                Light::Environment(Environment::Map(map)) if map.serves_lanes::<S>() => {
                    let s = S::sample_environment(map, u0, u1, mask::<S>(group));
                    let [r, g, b] = s.radiance;
                    // A map of scale 0 has density but no radiance: no shadow ray for it.
                    let lit = r.gt(S::zero()) | g.gt(S::zero()) | b.gt(S::zero());
                    let ok = group & set_of(s.drawn & lit);
                    let m = mask::<G>(ok);
                    let dir = conv_vec::<S, G>(s.direction);
                    // Ray::spawn: offset along the normal, the direction made unit.
                    let o = offset_origin_lanes(hl.p, hl.ng, dir);
                    wi = LVec3::select(m, dir, wi);
                    shadow_o = LVec3::select(m, o, shadow_o);
                    shadow_d = LVec3::select(m, dir.normalize(), shadow_d);
                    shadow_t = G::select(m, G::splat(f64::INFINITY), shadow_t);
                    for (le, &radiance) in le.iter_mut().zip(&s.radiance) {
                        *le = merge(ok, radiance, *le);
                    }
                    pdf_light = merge(ok, s.pdf, pdf_light);
                    sampled |= ok;
                }
                light @ Light::Area {
                    shape,
                    radiance,
                    two_sided,
                } => {
                    // `Light::sample` of an area light: the shape's sample in lanes where it
                    // has a lane form, the other lanes one by one.
                    let s = match scene.geometry.shape(*shape) {
                        Some(shape) => {
                            shape.sample_from_lanes(hl.p, conv::<S, G>(u0), conv::<S, G>(u1))
                        }
                        None => ShapeSampleLanes::none(),
                    };
                    let drawn = group & set_of(s.drawn);
                    sample_lane_by_lane!(light, group & !drawn);
                    if drawn == 0 {
                        continue;
                    }
                    let d = s.point - hl.p;
                    let dist = d.length_squared().sqrt();
                    let dir = d.scale(G::one() / dist);
                    let cos_l = s.normal.dot(-dir);
                    let faces = if *two_sided {
                        cos_l.abs().gt(G::splat(1e-12))
                    } else {
                        cos_l.gt(G::splat(1e-12))
                    };
                    let valid = s.pdf.gt(G::zero()) & s.pdf.is_finite() & dist.gt(G::zero());
                    let ok = if radiance.is_black() {
                        0
                    } else {
                        drawn & set_of(valid & faces)
                    };
                    // ShadowEnd::Surface: both ends offset, each towards the other.
                    let o = offset_origin_lanes(hl.p, hl.ng, d);
                    let (seg_d, seg_t) =
                        shadow_segment(o, offset_origin_lanes(s.point, s.normal, -d));
                    let m = mask::<G>(ok);
                    wi = LVec3::select(m, dir, wi);
                    shadow_o = LVec3::select(m, o, shadow_o);
                    shadow_d = LVec3::select(m, seg_d, shadow_d);
                    shadow_t = G::select(m, seg_t, shadow_t);
                    let radiance = rgb_splat::<S>(*radiance);
                    for ch in 0..3 {
                        le[ch] = merge(ok, radiance[ch], le[ch]);
                    }
                    pdf_light = merge(ok, conv::<G, S>(s.pdf), pdf_light);
                    sampled |= ok;
                }
                light => sample_lane_by_lane!(light, group),
            }
        }
        let wi_local_g = frame.to_local(wi);
        let side = set_of((wi.dot(hl.ng) * wi_local_g.z).gt(G::zero()));
        let mut candidates = sampled & side;
        if candidates == 0 {
            return;
        }
        let wi_local = conv_vec::<G, S>(wi_local_g);
        // The materials' values (f·|cos θ_i|) and densities.
        let mut f: Rgb<S> = [S::zero(); 3];
        let mut pdf = S::zero();
        self.eval_materials(paths, vertex, wo, wi_local, candidates, &mut f, &mut pdf);
        let black = set_of(f[0].eq(S::zero()) & f[1].eq(S::zero()) & f[2].eq(S::zero()));
        candidates &= !black;
        if candidates == 0 {
            return;
        }
        let shadows = LaneRays::new(shadow_o, shadow_d, shadow_t, candidates);
        let visible = candidates & !scene.geometry.occluded_lanes(&shadows);
        if visible == 0 {
            return;
        }
        let pl = S::from_fn(|i| p_select[i]) * pdf_light;
        let w = if self.strategy == Strategy::NeeOnly {
            S::one()
        } else {
            merge(delta, S::one(), power_heuristic_lanes(pl, pdf))
        };
        let scale = w / pl;
        for c in 0..3 {
            let add = paths.l[c] + paths.beta[c] * (f[c] * le[c] * scale);
            paths.l[c] = merge(visible, add, paths.l[c]);
        }
    }

    /// The materials' `f·|cos θ_i|` and densities for the pairs (wo, wi) of `set`: one lane
    /// call per lane model present, the f64 models lane by lane.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn eval_materials<S: ShadingLanes, G: Real>(
        &self,
        paths: &mut Paths<S, G>,
        vertex: &VertexMaterials,
        wo: LVec3<S>,
        wi: LVec3<S>,
        set: Lanes,
        f: &mut Rgb<S>,
        pdf: &mut S,
    ) {
        let cos = wi.z.abs();
        let mut todo = set;
        while todo != 0 {
            if let Some((model, group, textured)) = vertex.lane_group(todo) {
                todo &= !group;
                let mut free = FreeNumbers {
                    streams: &mut paths.streams,
                    sampler: self.sampler,
                    group,
                };
                let (v, p) = if textured {
                    S::eval_pdf(model, &vertex.lane_colors::<S>(), wo, wi, &mut free)
                } else {
                    S::eval_pdf(model, &OwnColors, wo, wi, &mut free)
                };
                for c in 0..3 {
                    f[c] = merge(group, v[c] * cos, f[c]);
                }
                *pdf = merge(group, p, *pdf);
                continue;
            }
            let first = todo.trailing_zeros() as usize;
            match &vertex.bsdfs[first] {
                VertexBsdf::Scalar(bsdf) => {
                    todo &= !(1 << first);
                    let ctx = BsdfContext::RADIANCE;
                    let (o, i) = (wo.lane(first), wi.lane(first));
                    let rng = paths.streams.lane(first, self.sampler).rng();
                    let v = bsdf.eval(o, i, &ctx, rng) * i.z.abs();
                    if !v.is_black() {
                        rgb_set(f, first, v);
                        let p = bsdf.pdf(o, i, &ctx);
                        *pdf = S::from_fn(|j| if j == first { p } else { pdf.lane(j) });
                    }
                }
                _ => todo &= !(1 << first),
            }
        }
    }

    /// The materials' samples, throughput, Russian roulette and the next rays; the paths
    /// that end are finished.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn continue_paths<S: ShadingLanes, G: Real>(
        &self,
        paths: &mut Paths<S, G>,
        hl: &HitLanes<G>,
        frame: &LFrame<G>,
        wo: LVec3<S>,
        vertex: &VertexMaterials,
        block: S::Bits,
        numbers: &VertexNumbers<S>,
        sums: &mut [PixelSums],
    ) {
        let live = paths.live;
        let mut wi = LVec3::<S>::zero();
        let mut weight: Rgb<S> = [S::zero(); 3];
        let mut pdf = S::zero();
        let mut eta = S::one();
        let mut delta: Lanes = 0;
        let mut transmitted: Lanes = 0;
        let mut ok: Lanes = 0;
        // Lane models: the lobe number where a model reads it, the direction pair.
        let lane_set = vertex.lane_models & live;
        if lane_set != 0 {
            let u_lobe = numbers.lobe;
            let (u0, u1) = numbers.bsdf;
            let mut todo = lane_set;
            while let Some((model, group, textured)) = vertex.lane_group(todo) {
                todo &= !group;
                let mut free = FreeNumbers {
                    streams: &mut paths.streams,
                    sampler: self.sampler,
                    group,
                };
                let s = if textured {
                    let colors = vertex.lane_colors::<S>();
                    S::sample(model, &colors, wo, u_lobe, u0, u1, &mut free)
                } else {
                    S::sample(model, &OwnColors, wo, u_lobe, u0, u1, &mut free)
                };
                let m = mask::<S>(group);
                wi = LVec3::select(m, s.wi, wi);
                for (w, sw) in weight.iter_mut().zip(s.weight) {
                    *w = merge(group, sw, *w);
                }
                pdf = merge(group, s.pdf, pdf);
                eta = merge(group, s.eta, eta);
                transmitted |= group & set_of(s.transmitted);
                ok |= group & set_of(s.ok);
            }
        }
        // The f64 models, lane by lane, from their vertex's dimensions then the free stream.
        let ctx = self.ctx;
        for i in lanes_of(live & !lane_set) {
            let VertexBsdf::Scalar(bsdf) = &vertex.bsdfs[i] else {
                continue;
            };
            let stream = paths.streams.lane(i, self.sampler);
            let mut source = PrefixedSource::new(stream, block.lane(i) + 3);
            let Some(s) = bsdf.sample(wo.lane(i), &ctx, &mut source) else {
                continue;
            };
            wi.set_lane(i, s.wi);
            rgb_set(&mut weight, i, s.weight);
            pdf.set_lane(i, s.pdf);
            eta.set_lane(i, s.eta);
            if s.lobe.is_delta() {
                delta |= 1 << i;
            }
            if s.lobe.intersects(LobeFlags::TRANSMISSION) {
                transmitted |= 1 << i;
            }
            ok |= 1 << i;
        }
        // The ray's direction is made unit in its lanes (f32 models give lengths 1 ± 1e-7).
        let wi_world = frame.to_world(conv_vec::<S, G>(wi)).normalize();
        let consistent = set_of((wi_world.dot(hl.ng) * conv::<S, G>(wi.z)).gt(G::zero()));
        let black =
            set_of(weight[0].eq(S::zero()) & weight[1].eq(S::zero()) & weight[2].eq(S::zero()));
        let go = live & ok & consistent & !black;
        let ended = live & !go;
        if ended != 0 {
            Self::finish(paths, ended, sums);
        }
        if go == 0 {
            return;
        }
        for (beta, w) in paths.beta.iter_mut().zip(weight) {
            *beta = merge(go, *beta * w, *beta);
        }
        paths.delta_prev = (paths.delta_prev & !go) | (delta & go);
        paths.prev_pdf = merge(go, pdf, paths.prev_pdf);
        paths.prev_p = LVec3::select(mask::<G>(go), hl.p, paths.prev_p);
        let refracted = go & transmitted;
        paths.eta_scale = merge(refracted, paths.eta_scale * (eta * eta), paths.eta_scale);
        let one = S::Bits::splat(1);
        paths.segment = S::Bits::blend_bits(go, paths.segment.wrapping_add(one), paths.segment);
        // Russian roulette after rr_depth segments.
        let rr = go & paths.segment.above_bits(self.scene.integrator.rr_depth);
        let mut killed: Lanes = 0;
        if rr != 0 {
            let q = paths.beta[0].max(paths.beta[1]).max(paths.beta[2]) * paths.eta_scale;
            let q = q.min(S::splat(0.95));
            let u = self.draw(paths, block, 6, rr, false).0;
            let survive = set_of(q.gt(S::zero()) & u.lt(q));
            killed = rr & !survive;
            let kept = rr & survive;
            for c in 0..3 {
                paths.beta[c] = merge(kept, paths.beta[c] / q, paths.beta[c]);
            }
        }
        let next = go & !killed;
        let m = mask::<G>(next);
        paths.o = LVec3::select(m, offset_origin_lanes(hl.p, hl.ng, wi_world), paths.o);
        paths.d = LVec3::select(m, wi_world, paths.d);
        if killed != 0 {
            Self::finish(paths, killed, sums);
        }
    }
}

/// A lane model's further random numbers: each lane's free PCG stream, as the scalar
/// integrator's stochastic models draw them, for the lanes of the model's group that ask.
struct FreeNumbers<'a> {
    streams: &'a mut LaneStreams,
    sampler: &'a PixelSampler,
    group: Lanes,
}

impl<S: Real> LaneRandom<S> for FreeNumbers<'_> {
    #[inline(always)]
    fn next_2d(&mut self, lanes: S::Mask) -> (S, S) {
        let mut u = [[0.0; 2]; LANES];
        for i in lanes_of(self.group) {
            if lanes.lane(i) {
                let d = self.streams.lane(i, self.sampler).rng().next_2d();
                u[i] = [d.x, d.y];
            }
        }
        (S::from_fn(|i| u[i][0]), S::from_fn(|i| u[i][1]))
    }
}

/// The constant environment's density of a direction: uniform over the sphere.
#[inline(always)]
fn constant_pdf(c: &ConstantEnvironment) -> f64 {
    c.pdf(Vec3::Z)
}

/// [`power_heuristic`] over lanes.
#[inline(always)]
fn power_heuristic_lanes<S: Real>(a: S, b: S) -> S {
    let (a2, b2) = (a * a, b * b);
    let sum = a2 + b2;
    S::select(sum.eq(S::zero()), S::zero(), a2 / sum)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::radiance;
    use crate::sampler::SamplerKind;
    use crate::scene::load_scene_str;
    /// The f64 lanes of the tests: on x86-64 the SSE2 register form, which computes the
    /// array lanes' (`F64x8`, and so one `f64`'s) bits and costs LLVM a fraction of their
    /// compile time (about 90 s for this instantiation over arrays; docs/performance.md,
    /// "The test build").
    #[cfg(target_arch = "x86_64")]
    type F64Lanes = facette_bsdf::lanes::F64x8Sse2;
    #[cfg(not(target_arch = "x86_64"))]
    type F64Lanes = facette_bsdf::lanes::F64x8;

    /// The kernel in f64 lanes (shading and geometry), a function of its own for the
    /// tests. `render_tile_lanes` is `#[inline(always)]` (the AVX2 build needs its body
    /// compiled inside `render_tile_avx2`); inlined into these tests' loops over samplers,
    /// estimators and pixels, LLVM spent 12 of the crate's 13 minutes of compile rotating
    /// their loops. The tests' other renders call the library's own copies
    /// ([`render_tile_portable`], `render_tile_avx2`) rather than compile more.
    #[inline(never)]
    fn render_tile_f64(job: &TileJob, sums: &mut Vec<PixelSums>) -> usize {
        render_tile_lanes::<F64Lanes, F64Lanes>(job, sums)
    }

    const SCENE: &str = r#"
        [camera]
        position = [0, 0.8, 4]
        target = [0, 0, 0]
        [film]
        width = 24
        height = 16
        [materials]
        floor = { type = "lambert", reflectance = { texture = "checker", a = [0.2, 0.3, 0.4], b = 0.8, scale = 6 } }
        gold = { type = "conductor", distribution = "ggx", alpha = 0.3, material = "Au" }
        glass = { type = "dielectric", distribution = "beckmann", alpha = 0.3, ior = 1.5, specular_transmittance = { texture = "checker", a = 0.6, b = [1.0, 0.9, 0.8], scale = 5 } }
        clay = { type = "oren-nayar", reflectance = 0.6, sigma = 0.35 }
        plastic = { type = "il", kd = { texture = "checker", a = [0.7, 0.28, 0.1], b = [0.1, 0.5, 0.9], scale = 4 }, ni = 1.5, distribution = "beckmann", alpha = 0.3, masking = "smith" }
        brushed = { type = "conductor", distribution = "beckmann", alpha_u = { texture = "checker", a = 0.1, b = 0.5, scale = 4 }, alpha_v = 0.3, material = "Al", specular_reflectance = { texture = "checker", a = 0.7, b = 1.0, scale = 3 } }
        [[objects]]
        shape = "sphere"
        center = [0.5, 0.7, -0.6]
        radius = 0.4
        material = "plastic"
        [[objects]]
        shape = "sphere"
        center = [-0.6, 0.8, -0.5]
        radius = 0.35
        material = "brushed"
        [[objects]]
        shape = "rectangle"
        transform = [{ rotate = { axis = [1, 0, 0], angle = -90 } }, { scale = 4 }, { translate = [0, -0.5, 0] }]
        material = "floor"
        [[objects]]
        shape = "sphere"
        center = [-1, 0, 0]
        radius = 0.5
        material = "gold"
        [[objects]]
        shape = "sphere"
        center = [0, 0, 0]
        radius = 0.5
        material = "glass"
        [[objects]]
        shape = "sphere"
        center = [1, 0, 0]
        radius = 0.5
        material = "clay"
        [[objects]]
        shape = "rectangle"
        transform = [{ scale = 0.5 }, { rotate = { axis = [1, 0, 0], angle = 90 } }, { translate = [0, 2, 0.5] }]
        emission = 3.0
        [[lights]]
        type = "point"
        position = [1, 2, 2]
        intensity = 4
        [[lights]]
        type = "constant"
        radiance = 0.5
    "#;

    /// The whole frame of `scene` as one tile, without footprints.
    fn whole_frame<'a>(
        scene: &'a Scene,
        sampler: &'a PixelSampler,
        strategy: Strategy,
        chunk: &'a [u32],
        stop: &'a dyn Fn() -> bool,
    ) -> TileJob<'a> {
        TileJob {
            scene,
            sampler,
            cameras: CameraSampling {
                footprints: false,
                diff_scale: 1.0,
                pixel_footprints: false,
            },
            strategy,
            xs: 0..scene.film.width,
            ys: 0..scene.film.height,
            chunk,
            stop,
        }
    }

    /// With f64 shading lanes the packet kernel is the scalar integrator in another order:
    /// every pixel agrees to 1e-9 for every sampler and estimator (the lane models differ
    /// from the f64 models only in how they write the sampling weight and the dielectric's
    /// Fresnel term; the stochastic IL body draws the same free-stream numbers); f32 lanes
    /// render every sample too. Textured lane materials (colors of Lambert, IL, a dielectric
    /// and a conductor, a conductor's roughness) run their lane models with the textures'
    /// values, where the scalar integrator rebuilds their f64 models.
    #[test]
    fn f64_lanes_reproduce_the_scalar_integrator_sample_for_sample() {
        let scene = load_scene_str(SCENE, std::path::Path::new("t.toml")).unwrap();
        let textured_lane_models = scene
            .materials
            .iter()
            .filter(|m| m.is_textured() && m.lane_bsdf().is_some())
            .count();
        assert_eq!(textured_lane_models, 4);
        let (w, h) = (scene.film.width, scene.film.height);
        let cameras = CameraSampling {
            footprints: false,
            diff_scale: 1.0,
            pixel_footprints: false,
        };
        let chunk: Vec<u32> = (0..8).collect();
        let never = || false;
        for kind in [
            SamplerKind::Sobol,
            SamplerKind::Independent,
            SamplerKind::Stratified,
        ] {
            for strategy in [Strategy::Mis, Strategy::NeeOnly, Strategy::BsdfOnly] {
                let sampler = PixelSampler::new(kind, 4, w, h, 8);
                let job = whole_frame(&scene, &sampler, strategy, &chunk, &never);
                let mut lanes = Vec::new();
                assert_eq!(render_tile_f64(&job, &mut lanes), h);
                let mut f32_lanes = Vec::new();
                render_tile_portable(&job, &mut f32_lanes);
                let mut worst: f64 = 0.0;
                for y in 0..h {
                    for x in 0..w {
                        let mut scalar = PixelSums::default();
                        for &s in &chunk {
                            let mut stream = sampler.stream(x, y, s as u64);
                            let (ray, rd, pixel) = cameras.ray(&scene, &mut stream, x, y);
                            scalar.add(radiance(&scene, ray, rd, pixel, &mut stream, strategy));
                        }
                        let (a, b) = (scalar.sums(), lanes[y * w + x].sums());
                        for c in 0..3 {
                            worst = worst.max((a[c] - b[c]).abs() / a[c].abs().max(1e-3));
                        }
                        assert_eq!(lanes[y * w + x].count(), 8);
                        assert_eq!(f32_lanes[y * w + x].count(), 8);
                    }
                }
                assert!(
                    worst < 1e-9,
                    "{kind:?} {strategy:?}: largest relative difference {worst:e}"
                );
            }
        }
    }

    /// The portable build's f32 lanes (f32 shading, and f32 geometry: rays, hit records and
    /// spawned origins, with the f32 spawning offset) render the image of f64 lanes, which
    /// are the scalar integrator's (the test above): every sample, the same paths up to where
    /// f32 rounding changes a hit or a choice, the image means within 1e-3 for every sampler
    /// and estimator, fewer than 5 % of the pixels off by more than 1e-2 (a sample whose path
    /// took another turn after a few refractions through the glass sphere), and no pixel NaN
    /// or negative. (Until 2026-12-07 this compared f32 with f64 geometry under f32 shading:
    /// one more instantiation of the kernel, two minutes of the test build.)
    #[test]
    fn f32_lanes_render_the_image_of_f64_lanes() {
        let scene = load_scene_str(SCENE, std::path::Path::new("t.toml")).unwrap();
        let (w, h) = (scene.film.width, scene.film.height);
        let chunk: Vec<u32> = (0..16).collect();
        let never = || false;
        for kind in [SamplerKind::Sobol, SamplerKind::Independent] {
            for strategy in [Strategy::Mis, Strategy::NeeOnly, Strategy::BsdfOnly] {
                let sampler = PixelSampler::new(kind, 9, w, h, 16);
                let job = whole_frame(&scene, &sampler, strategy, &chunk, &never);
                let (mut f64_lanes, mut f32_lanes) = (Vec::new(), Vec::new());
                render_tile_f64(&job, &mut f64_lanes);
                render_tile_portable(&job, &mut f32_lanes);
                let mean = |image: &[PixelSums]| -> [f64; 3] {
                    let mut m = [0.0; 3];
                    for p in image {
                        assert_eq!(p.count(), 16);
                        let s = p.sums();
                        for c in 0..3 {
                            assert!(s[c].is_finite() && s[c] >= 0.0, "{s:?}");
                            m[c] += s[c];
                        }
                    }
                    m
                };
                let (a, b) = (mean(&f64_lanes), mean(&f32_lanes));
                for c in 0..3 {
                    let rel = (a[c] - b[c]).abs() / a[c];
                    assert!(
                        rel < 1e-3,
                        "{kind:?} {strategy:?}: channel {c} off by {rel:e}"
                    );
                }
                // Rounding differences grow through the glass sphere's refractions to 1e-4;
                // a pixel off by more than 1e-2 has a sample whose path took another turn.
                let differ = f64_lanes
                    .iter()
                    .zip(&f32_lanes)
                    .filter(|(p, q)| {
                        let (a, b) = (p.sums(), q.sums());
                        (0..3).any(|c| (a[c] - b[c]).abs() > 1e-2 * a[c].max(1e-2))
                    })
                    .count();
                assert!(
                    differ * 20 < w * h,
                    "{kind:?} {strategy:?}: {differ} of {} pixels differ",
                    w * h
                );
            }
        }
    }

    /// The renders' AVX2 build, with its register lanes (`F32x8Avx2`), computes the bits of
    /// the portable build's SSE2 lanes (`F32x8Sse2`): every pixel's sums, for every sampler and
    /// estimator, on a scene with every lane model, textures, both distributions, a
    /// conductor's complex Fresnel, glass, an area light and a point light.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn the_avx2_build_renders_the_portable_builds_image_bit_for_bit() {
        if !facette_bsdf::lanes::avx2::available() {
            eprintln!("this CPU has no AVX2 + FMA: only the portable build runs here");
            return;
        }
        let scene = load_scene_str(SCENE, std::path::Path::new("t.toml")).unwrap();
        let (w, h) = (scene.film.width, scene.film.height);
        let chunk: Vec<u32> = (0..8).collect();
        let never = || false;
        for kind in [SamplerKind::Sobol, SamplerKind::Independent] {
            for strategy in [Strategy::Mis, Strategy::NeeOnly, Strategy::BsdfOnly] {
                let sampler = PixelSampler::new(kind, 5, w, h, 8);
                let job = whole_frame(&scene, &sampler, strategy, &chunk, &never);
                let (mut portable, mut avx2) = (Vec::new(), Vec::new());
                render_tile_portable(&job, &mut portable);
                // SAFETY: the CPU has AVX2 and FMA (tested above).
                unsafe { render_tile_avx2(&job, &mut avx2) };
                assert_eq!(portable.len(), w * h);
                for (k, (p, q)) in portable.iter().zip(&avx2).enumerate() {
                    assert_eq!(p.count(), q.count());
                    let (a, b) = (p.sums(), q.sums());
                    assert!(
                        (0..3).all(|c| a[c].to_bits() == b[c].to_bits()),
                        "{kind:?} {strategy:?}, pixel {k}: {a:?} against {b:?}"
                    );
                }
            }
        }
    }

    /// A stop before a row leaves that row and the later ones out; a second call adds to the
    /// sums of the first.
    #[test]
    fn a_stop_ends_the_tile_at_a_row() {
        let scene = load_scene_str(SCENE, std::path::Path::new("t.toml")).unwrap();
        let sampler = PixelSampler::new(SamplerKind::Sobol, 1, 24, 16, 2);
        let asked = std::cell::Cell::new(0);
        let stop = || {
            asked.set(asked.get() + 1);
            asked.get() > 3
        };
        let job = TileJob {
            scene: &scene,
            sampler: &sampler,
            cameras: CameraSampling {
                footprints: false,
                diff_scale: 1.0,
                pixel_footprints: false,
            },
            strategy: Strategy::Mis,
            xs: 2..10,
            ys: 0..16,
            chunk: &[0, 1],
            stop: &stop,
        };
        let mut sums = Vec::new();
        assert_eq!(render_tile_portable(&job, &mut sums), 3);
        assert_eq!(sums.len(), 16 * 8);
        let counts = |sums: &[PixelSums]| sums.iter().map(|p| p.count()).collect::<Vec<_>>();
        let rows = |a: u32, b: u32| [vec![a; 3 * 8], vec![b; 13 * 8]].concat();
        assert_eq!(counts(&sums), rows(2, 0));
        // Three more rows before the next stop: the first three get their second pass.
        asked.set(0);
        assert_eq!(render_tile_portable(&job, &mut sums), 3);
        assert_eq!(counts(&sums), rows(4, 0));
    }
}
