//! The packet kernel: eight camera samples of a row of pixels in flight per thread, each
//! step advancing every live path by one segment, a finished path's lane refilled at once
//! from the row's remaining (pixel, sample) jobs so that the lanes stay full.
//!
//! A step is the scalar integrator's vertex ([`integrator`](crate::integrator)) in phases,
//! each over all lanes: intersection (one packet query for the eight rays,
//! [`intersect_packet`](crate::geometry::SceneGeometry::intersect_packet)), emission and
//! the vertex's frame (per lane); light samples (per lane); the material's value and
//! density for every light sample (one call over eight lanes per material that has a lane
//! model, `facette_bsdf::lanes::LaneBsdf`; the f64 model lane by lane otherwise); shadow
//! rays (one packet query,
//! [`occluded_packet`](crate::geometry::SceneGeometry::occluded_packet)); the material's
//! samples (one call over eight lanes again); throughput, roulette and the next ray (per
//! lane).
//! The random numbers are the scalar integrator's, dimension for dimension, from the same
//! sample streams, so the two kernels' images differ only by the f32 rounding of the lane
//! models (and, where a rounding moves a path across a decision, by that path).
//!
//! The packet queries find each lane's hit in f64, exactly as a one-ray query does
//! (spheres four lanes at a time by their one-source test); lights, the camera, the
//! sampler and the film stay f64 and per lane in this version. On x86-64 the step is
//! compiled twice, for the baseline (SSE2: an 8-lane operation is two instructions) and
//! for AVX2 + FMA, chosen at run time.

use crate::geometry::scene_geometry::PacketHit;
use crate::geometry::{HitDetail, Ray, RayDifferential, SurfaceHit, Vec3};
use crate::integrator::{
    light_numbers, power_heuristic, Strategy, CAMERA_DIMENSIONS, VERTEX_DIMENSIONS,
};
use crate::lights::{Light, LightSample};
use crate::materials::MaterialBsdf;
use crate::render::{CameraSampling, PixelSums};
use crate::sampler::{PixelSampler, PrefixedSource, SampleStream};
use crate::scene::Scene;
use facette_bsdf::lanes::{F32x8, LVec3, Mask, Real};
use facette_bsdf::math::Frame;
use facette_bsdf::{BsdfContext, LobeFlags, Spectrum};
use std::ops::Range;

/// Paths in flight per thread.
pub const LANES: usize = 8;

/// One lane's path.
struct Path {
    /// The pixel's index in the row.
    slot: usize,
    stream: SampleStream,
    ray: Ray,
    rd: Option<RayDifferential>,
    l: Spectrum,
    beta: Spectrum,
    delta_prev: bool,
    prev_pdf: f64,
    prev_p: Vec3,
    eta_scale: f64,
    /// Segments so far (the camera ray is segment 1).
    segment: u32,
}

/// What a lane's vertex has after intersection.
struct Vertex<'s> {
    hit: SurfaceHit,
    frame: Frame,
    wo: Vec3,
    material: u32,
    /// The f64 model of a material without a lane model.
    scalar: Option<MaterialBsdf<'s>>,
    flags: LobeFlags,
}

/// A light sample waiting for the material's value and density.
struct LightCandidate {
    ls: LightSample,
    wi: Vec3,
    p_select: f64,
    /// f·|cos θ_i| and the material's density of wi.
    f: Spectrum,
    pdf: f64,
}

/// A material's sample for one lane.
#[derive(Clone, Copy)]
struct MaterialSample {
    wi: Vec3,
    weight: Spectrum,
    pdf: f64,
    eta: f64,
    delta: bool,
    transmitted: bool,
}

/// Renders every sample of `chunk` for the pixels `xs` of row `y` into `sums` (one entry
/// per pixel), with the widest lanes this CPU runs.
pub(crate) fn render_row(
    scene: &Scene,
    sampler: &PixelSampler,
    cameras: CameraSampling,
    strategy: Strategy,
    (xs, y): (Range<usize>, usize),
    chunk: &[u32],
    sums: &mut [PixelSums],
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU has the features the function is compiled for.
        unsafe { render_row_avx2(scene, sampler, cameras, strategy, (xs, y), chunk, sums) };
        return;
    }
    render_row_lanes::<F32x8>(scene, sampler, cameras, strategy, (xs, y), chunk, sums);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn render_row_avx2(
    scene: &Scene,
    sampler: &PixelSampler,
    cameras: CameraSampling,
    strategy: Strategy,
    row: (Range<usize>, usize),
    chunk: &[u32],
    sums: &mut [PixelSums],
) {
    render_row_lanes::<F32x8>(scene, sampler, cameras, strategy, row, chunk, sums);
}

/// [`render_row`] with lane type `R` (the tests also run `f64` and `f32` lanes).
#[inline(always)]
pub(crate) fn render_row_lanes<R: Real>(
    scene: &Scene,
    sampler: &PixelSampler,
    cameras: CameraSampling,
    strategy: Strategy,
    (xs, y): (Range<usize>, usize),
    chunk: &[u32],
    sums: &mut [PixelSums],
) {
    let x0 = xs.start;
    let mut jobs = xs.flat_map(|x| chunk.iter().map(move |&s| (x, s)));
    let mut lanes: [Option<Path>; LANES] = Default::default();
    loop {
        // Refill the empty lanes; stop when no job is left and every lane is empty.
        for lane in lanes.iter_mut().filter(|l| l.is_none()) {
            let Some((x, s)) = jobs.next() else { break };
            let mut stream = sampler.stream(x, y, s as u64);
            let (ray, rd) = cameras.ray(scene, &mut stream, x, y);
            *lane = Some(Path {
                slot: x - x0,
                stream,
                prev_p: ray.origin,
                ray,
                rd,
                l: Spectrum::ZERO,
                beta: Spectrum::ONE,
                delta_prev: true,
                prev_pdf: 0.0,
                eta_scale: 1.0,
                segment: 1,
            });
        }
        if lanes.iter().all(Option::is_none) {
            return;
        }
        step::<R>(scene, strategy, &mut lanes, sums);
    }
}

/// Ends lane `lane`'s path: its radiance goes to its pixel.
#[inline]
fn finish(lane: &mut Option<Path>, sums: &mut [PixelSums]) {
    if let Some(p) = lane.take() {
        sums[p.slot].add(p.l);
    }
}

/// Advances every lane by one path segment.
#[inline(always)]
fn step<R: Real>(
    scene: &Scene,
    strategy: Strategy,
    lanes: &mut [Option<Path>; LANES],
    sums: &mut [PixelSums],
) {
    let rays: [Option<Ray>; LANES] = std::array::from_fn(|k| lanes[k].as_ref().map(|p| p.ray));
    let hits = scene.geometry.intersect_packet(&rays);
    let mut vertices: [Option<Vertex>; LANES] = Default::default();
    for ((lane, vertex), hit) in lanes.iter_mut().zip(vertices.iter_mut()).zip(hits) {
        let Some(path) = lane else { continue };
        *vertex = arrive(scene, strategy, path, hit);
        if vertex.is_none() {
            finish(lane, sums);
        }
    }
    // Light samples, then the materials' values and densities for them.
    let mut lights: [Option<LightCandidate>; LANES] = Default::default();
    for k in 0..LANES {
        if let (Some(path), Some(v)) = (&mut lanes[k], &vertices[k]) {
            if v.flags.has_smooth_part() && strategy != Strategy::BsdfOnly {
                lights[k] = sample_light(scene, path, v);
            }
        }
    }
    eval_materials::<R>(scene, lanes, &vertices, &mut lights);
    let shadows: [Option<Ray>; LANES] = std::array::from_fn(|k| match &lights[k] {
        Some(c) if lanes[k].is_some() && !c.f.is_black() => Some(c.ls.shadow),
        _ => None,
    });
    let occluded = scene.geometry.occluded_packet(&shadows);
    for k in 0..LANES {
        if let (Some(path), Some(c), Some(_)) = (&mut lanes[k], &lights[k], &shadows[k]) {
            if occluded & (1 << k) == 0 {
                let pl = c.p_select * c.ls.pdf;
                let w = if c.ls.delta || strategy == Strategy::NeeOnly {
                    1.0
                } else {
                    power_heuristic(pl, c.pdf)
                };
                path.l += path.beta * c.f * c.ls.radiance * (w / pl);
            }
        }
    }
    // The materials' samples, then the next segment.
    let samples = sample_materials::<R>(scene, lanes, &vertices);
    for k in 0..LANES {
        let (Some(path), Some(v)) = (&mut lanes[k], &vertices[k]) else {
            continue;
        };
        if !continue_path(scene, path, v, samples[k]) {
            finish(&mut lanes[k], sums);
        }
    }
}

/// Adds what the lane's ray sees emitted at its hit `hit` (or in the environment where it
/// has none); the vertex to shade, or `None` where the path ends.
#[inline]
fn arrive<'s>(
    scene: &'s Scene,
    strategy: Strategy,
    path: &mut Path,
    hit: Option<PacketHit>,
) -> Option<Vertex<'s>> {
    let ray = path.ray;
    let mis = |path: &Path, pl: f64| match strategy {
        _ if path.delta_prev => 1.0,
        Strategy::Mis => power_heuristic(path.prev_pdf, pl),
        Strategy::NeeOnly => 0.0,
        Strategy::BsdfOnly => 1.0,
    };
    let Some(hit) = hit else {
        if let Some(env) = scene.environment {
            if let Light::Environment(e) = &scene.lights[env as usize] {
                let pl = scene.selector.probability(env as usize) * e.pdf(ray.dir);
                path.l += path.beta * e.eval(ray.dir) * mis(path, pl);
            }
        }
        return None;
    };
    let mut hit = scene
        .geometry
        .packet_hit_record(&ray, hit, HitDetail::Shading);
    if let Some(li) = scene.shape_light[hit.shape as usize] {
        let light = &scene.lights[li as usize];
        let le = light.emitted(hit.ng, -ray.dir);
        if !le.is_black() {
            let pl = scene.selector.probability(li as usize)
                * light.pdf_area_hit(&scene.geometry, path.prev_p, hit.p, hit.ng, hit.prim);
            path.l += path.beta * le * mis(path, pl);
        }
    }
    if path.segment >= scene.integrator.max_depth {
        return None;
    }
    let material = scene.shape_material[hit.shape as usize];
    let m = &scene.materials[material as usize];
    let (scalar, flags) = match m.lane_bsdf() {
        Some(lane) => (None, lane.flags()),
        None => {
            let mut derivs = [0.0; 4];
            if m.reads_surface_details() {
                scene.geometry.complete_hit(&mut hit);
                if let (Some(d), 1) = (&path.rd, path.segment) {
                    derivs = hit.uv_derivatives(d);
                }
            }
            let bsdf = m.bsdf(hit.uv, derivs)?;
            let flags = bsdf.flags();
            (Some(bsdf), flags)
        }
    };
    let frame = hit.shading_frame();
    Some(Vertex {
        wo: frame.to_local(-ray.dir),
        hit,
        frame,
        material,
        scalar,
        flags,
    })
}

/// The first dimension of the lane's current vertex block.
#[inline]
fn block(path: &Path) -> u32 {
    CAMERA_DIMENSIONS + (path.segment - 1) * VERTEX_DIMENSIONS
}

/// One light sample from the vertex's light-selection and light-position numbers; an f64
/// material is evaluated at once.
#[inline]
fn sample_light(scene: &Scene, path: &mut Path, v: &Vertex) -> Option<LightCandidate> {
    let first = block(path);
    let (u_select, u) = light_numbers(scene, &mut path.stream, first);
    let (k, p_select) = scene.selector.select(u_select)?;
    let ls = scene.lights[k].sample(&scene.geometry, v.hit.p, v.hit.ng, u)?;
    if ls.radiance.is_black() {
        return None;
    }
    let wi = v.frame.to_local(ls.wi);
    if !(ls.wi.dot(v.hit.ng) * wi.z > 0.0) {
        return None;
    }
    let mut c = LightCandidate {
        ls,
        wi,
        p_select,
        f: Spectrum::ZERO,
        pdf: 0.0,
    };
    if let Some(bsdf) = &v.scalar {
        let ctx = BsdfContext::RADIANCE;
        c.f = bsdf.eval(v.wo, wi, &ctx, path.stream.rng()) * wi.z.abs();
        if !c.f.is_black() {
            c.pdf = bsdf.pdf(v.wo, wi, &ctx);
        }
    }
    Some(c)
}

/// The lanes of `vertices` whose material is `material` and that satisfy `want`, as a
/// bit set.
#[inline]
fn lanes_of(
    vertices: &[Option<Vertex>; LANES],
    material: u32,
    want: impl Fn(usize) -> bool,
) -> u32 {
    let mut set = 0;
    for (k, v) in vertices.iter().enumerate() {
        if matches!(v, Some(v) if v.material == material && v.scalar.is_none()) && want(k) {
            set |= 1 << k;
        }
    }
    set
}

/// Each lane-model material present among `set`'s lanes once, with its lanes.
#[inline]
fn material_groups<'a>(
    vertices: &'a [Option<Vertex<'_>>; LANES],
    set: u32,
) -> impl Iterator<Item = (u32, u32)> + 'a {
    let mut left = set;
    std::iter::from_fn(move || {
        let k = (0..LANES).find(|k| left & (1 << k) != 0)?;
        let material = vertices[k].as_ref()?.material;
        let group = left & lanes_of(vertices, material, |_| true);
        left &= !group;
        Some((material, group))
    })
}

/// A direction per lane, (0, 0, 1) where the lane is not in `set` (a harmless input).
#[inline(always)]
fn gather<R: Real>(base: usize, set: u32, dir: impl Fn(usize) -> Vec3) -> LVec3<R> {
    LVec3::from_fn(|i| {
        if set & (1 << (base + i)) != 0 {
            dir(base + i)
        } else {
            Vec3::Z
        }
    })
}

/// The lane models' values and densities for the light samples.
#[inline(always)]
fn eval_materials<R: Real>(
    scene: &Scene,
    lanes: &[Option<Path>; LANES],
    vertices: &[Option<Vertex>; LANES],
    lights: &mut [Option<LightCandidate>; LANES],
) {
    let waiting = (0..LANES).fold(0, |set, k| {
        let lane_model = matches!(&vertices[k], Some(v) if v.scalar.is_none());
        set | (((lane_model && lights[k].is_some() && lanes[k].is_some()) as u32) << k)
    });
    for (material, group) in material_groups(vertices, waiting) {
        let model = scene.materials[material as usize]
            .lane_bsdf()
            .expect("a lane-model group");
        for base in (0..LANES).step_by(R::LANES) {
            if group >> base & ((1 << R::LANES) - 1) == 0 {
                continue;
            }
            let wo = gather::<R>(base, group, |k| {
                vertices[k].as_ref().map_or(Vec3::Z, |v| v.wo)
            });
            let wi = gather::<R>(base, group, |k| {
                lights[k].as_ref().map_or(Vec3::Z, |c| c.wi)
            });
            let (f, pdf) = model.eval_pdf(wo, wi);
            for i in 0..R::LANES {
                let k = base + i;
                if group & (1 << k) == 0 {
                    continue;
                }
                if let Some(c) = &mut lights[k] {
                    let cos = c.wi.z.abs();
                    c.f = Spectrum([f[0].lane(i) * cos, f[1].lane(i) * cos, f[2].lane(i) * cos]);
                    c.pdf = pdf.lane(i);
                }
            }
        }
    }
}

/// Every live lane's material sample: the lane models in one call per material, the f64
/// models lane by lane.
#[inline(always)]
fn sample_materials<R: Real>(
    scene: &Scene,
    lanes: &mut [Option<Path>; LANES],
    vertices: &[Option<Vertex>; LANES],
) -> [Option<MaterialSample>; LANES] {
    let mut out: [Option<MaterialSample>; LANES] = [None; LANES];
    // The lobe number and the direction numbers of each vertex.
    let mut numbers = [[0.0; 3]; LANES];
    let ctx = BsdfContext::RADIANCE;
    let mut lane_set = 0;
    for k in 0..LANES {
        let (Some(path), Some(v)) = (&mut lanes[k], &vertices[k]) else {
            continue;
        };
        let first = block(path) + 3;
        match &v.scalar {
            Some(bsdf) => {
                let mut source = PrefixedSource::new(&mut path.stream, first);
                out[k] = bsdf
                    .sample(v.wo, &ctx, &mut source)
                    .map(|s| MaterialSample {
                        wi: s.wi,
                        weight: s.weight,
                        pdf: s.pdf,
                        eta: s.eta,
                        delta: s.lobe.is_delta(),
                        transmitted: s.lobe.intersects(LobeFlags::TRANSMISSION),
                    });
            }
            None => {
                // The lane model says whether it reads a lobe number (one-lobe models do
                // not: the dimension is left undrawn).
                let reads_lobe = scene.materials[v.material as usize]
                    .lane_bsdf()
                    .is_some_and(|m| m.reads_lobe_number());
                path.stream.set_dimension(first);
                let lobe = path.stream.get_1d_where(reads_lobe);
                let dir = path.stream.get_2d();
                numbers[k] = [lobe, dir.x, dir.y];
                lane_set |= 1 << k;
            }
        }
    }
    for (material, group) in material_groups(vertices, lane_set) {
        let model = scene.materials[material as usize]
            .lane_bsdf()
            .expect("a lane-model group");
        for base in (0..LANES).step_by(R::LANES) {
            if group >> base & ((1 << R::LANES) - 1) == 0 {
                continue;
            }
            let wo = gather::<R>(base, group, |k| {
                vertices[k].as_ref().map_or(Vec3::Z, |v| v.wo)
            });
            let u = |j: usize| R::from_fn(|i| numbers[base + i][j]);
            let s = model.sample(wo, u(0), u(1), u(2));
            for i in 0..R::LANES {
                let k = base + i;
                if group & (1 << k) != 0 && s.ok.lane(i) {
                    out[k] = Some(MaterialSample {
                        wi: s.wi.lane(i),
                        weight: Spectrum([
                            s.weight[0].lane(i),
                            s.weight[1].lane(i),
                            s.weight[2].lane(i),
                        ]),
                        pdf: s.pdf.lane(i),
                        eta: s.eta.lane(i),
                        delta: false,
                        transmitted: s.transmitted.lane(i),
                    });
                }
            }
        }
    }
    out
}

/// Takes the material's sample: throughput, Russian roulette and the next ray. `false`
/// where the path ends.
#[inline]
fn continue_path(scene: &Scene, path: &mut Path, v: &Vertex, s: Option<MaterialSample>) -> bool {
    let Some(s) = s else { return false };
    // f32 lanes return directions of length 1 ± 1e-7: the f64 ray needs a unit one.
    let wi = v.frame.to_world(s.wi).normalize_or_zero();
    if !(wi.dot(v.hit.ng) * s.wi.z > 0.0) || s.weight.is_black() {
        return false;
    }
    path.beta *= s.weight;
    path.delta_prev = s.delta;
    path.prev_pdf = s.pdf;
    path.prev_p = v.hit.p;
    if s.transmitted {
        path.eta_scale *= s.eta * s.eta;
    }
    let rr_dimension = block(path) + 6;
    path.segment += 1;
    if path.segment > scene.integrator.rr_depth {
        let q = (path.beta.max_component() * path.eta_scale).min(0.95);
        path.stream.set_dimension(rr_dimension);
        if !(q > 0.0) || path.stream.get_1d() >= q {
            return false;
        }
        path.beta /= q;
    }
    path.ray = v.hit.spawn_ray(wi);
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::radiance;
    use crate::sampler::SamplerKind;
    use crate::scene::load_scene_str;

    const SCENE: &str = r#"
        [camera]
        position = [0, 0.8, 4]
        target = [0, 0, 0]
        [film]
        width = 24
        height = 16
        [materials]
        floor = { type = "lambert", reflectance = 0.5 }
        gold = { type = "conductor", distribution = "ggx", alpha = 0.3, material = "Au" }
        glass = { type = "dielectric", distribution = "beckmann", alpha = 0.3, ior = 1.5 }
        clay = { type = "oren-nayar", reflectance = 0.6, sigma = 0.35 }
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
        [[lights]]
        type = "point"
        position = [1, 2, 2]
        intensity = 4
        [[lights]]
        type = "constant"
        radiance = 0.5
    "#;

    /// With f64 lanes the packet kernel is the scalar integrator in another order: every
    /// pixel agrees to 1e-9 (the lane models differ from the f64 models only in how they
    /// write the sampling weight and the dielectric's Fresnel term).
    #[test]
    fn f64_lanes_reproduce_the_scalar_integrator_sample_for_sample() {
        let scene = load_scene_str(SCENE, std::path::Path::new("t.toml")).unwrap();
        let (w, h) = (scene.film.width, scene.film.height);
        let sampler = PixelSampler::new(SamplerKind::Sobol, 4, w, h, 8);
        let cameras = CameraSampling {
            footprints: false,
            diff_scale: 1.0,
        };
        let chunk: Vec<u32> = (0..8).collect();
        let mut worst: f64 = 0.0;
        for y in 0..h {
            let mut lanes = vec![PixelSums::default(); w];
            render_row_lanes::<f64>(
                &scene,
                &sampler,
                cameras,
                Strategy::Mis,
                (0..w, y),
                &chunk,
                &mut lanes,
            );
            let mut f32_lanes = vec![PixelSums::default(); w];
            render_row_lanes::<F32x8>(
                &scene,
                &sampler,
                cameras,
                Strategy::Mis,
                (0..w, y),
                &chunk,
                &mut f32_lanes,
            );
            for x in 0..w {
                let mut scalar = PixelSums::default();
                for &s in &chunk {
                    let mut stream = sampler.stream(x, y, s as u64);
                    let (ray, rd) = cameras.ray(&scene, &mut stream, x, y);
                    scalar.add(radiance(&scene, ray, rd, &mut stream, Strategy::Mis));
                }
                let (a, b) = (scalar.sums(), lanes[x].sums());
                for c in 0..3 {
                    worst = worst.max((a[c] - b[c]).abs() / a[c].abs().max(1e-3));
                }
                assert_eq!(f32_lanes[x].count(), 8);
            }
        }
        assert!(worst < 1e-9, "largest relative difference {worst:e}");
    }
}
