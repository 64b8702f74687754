//! No heap allocation per camera sample: a render allocates per pass and per tile (the
//! tile's pixel sums), never per sample or per path vertex. A counting global allocator
//! measures the allocations of two renders that differ only in their sample count and
//! attributes the difference to the extra samples.

use facette_render::kernel::Kernel;
use facette_render::render::{render, RenderOptions};
use facette_render::scene::load_scene_str;
use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// The system allocator, counting the allocations made.
struct Counting;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: forwarded with the caller's layout.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` was allocated by `System` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: forwarded with the caller's pointer and layout.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// A scene with the renderer's hot paths: a rough dielectric (refraction, stochastic
/// choice of lobe), a rough conductor, a diffuse plane, a sphere light (NEE with MIS), an
/// environment light and a triangle mesh.
const SCENE: &str = r#"
[camera]
position = [0, 1, 5]
target = [0, 0, 0]
fov = 40

[film]
width = 32
height = 32

[integrator]
max_depth = 8

[materials]
glass = { type = "dielectric", distribution = "ggx", alpha = 0.3, ior = 1.5 }
gold = { type = "conductor", distribution = "beckmann", alpha = 0.2, material = "Au" }
white = { type = "lambert", reflectance = 0.7 }

[[objects]]
shape = "sphere"
center = [-0.8, 0, 0]
radius = 0.7
material = "glass"

[[objects]]
shape = "sphere"
center = [0.8, 0, 0]
radius = 0.7
material = "gold"

[[objects]]
shape = "rectangle"
transform = [{ rotate = { axis = [1, 0, 0], angle = -90 } }, { scale = 4 }, { translate = [0, -0.7, 0] }]
material = "white"

[[objects]]
shape = "sphere"
center = [0, 3, 1]
radius = 0.4
emission = 10

[[objects]]
shape = "torus-knot"
triangles = 200
transform = [{ scale = 0.3 }, { translate = [0, 0.8, -1] }]
material = "white"

[[lights]]
type = "constant"
radiance = 0.2
"#;

/// Allocations made by one single-threaded render of `spp` samples per pixel.
fn allocations(spp: usize, kernel: Kernel) -> u64 {
    let scene = load_scene_str(SCENE, Path::new("test.toml")).unwrap_or_else(|e| panic!("{e}"));
    let opts = RenderOptions {
        spp: Some(spp),
        threads: Some(1),
        kernel: Some(kernel),
        ..Default::default()
    };
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    let (_, stats) = render(&scene, &opts, &AtomicBool::new(false), &|_, _| {}).unwrap();
    let after = ALLOCATIONS.load(Ordering::Relaxed);
    assert_eq!(stats.samples, (32 * 32 * spp) as u64);
    after - before
}

#[test]
fn a_render_allocates_nothing_per_sample() {
    // 17 and 20 passes of one 32 × 32 tile: the few per-pass allocations cancel out to a
    // handful, and the rest of the difference is what the 32 × 32 × 224 extra samples
    // allocate (one per sample or per vertex would be ≥ 229,376).
    for kernel in [Kernel::Scalar, Kernel::Packet] {
        let few = allocations(32, kernel);
        let many = allocations(256, kernel);
        let extra_samples = (32 * 32 * (256 - 32)) as f64;
        let per_sample = many.saturating_sub(few) as f64 / extra_samples;
        println!(
            "{kernel:?}: allocations {few} at 32 spp, {many} at 256 spp ({per_sample:.2e} per sample)"
        );
        assert!(
            per_sample < 1e-3,
            "{kernel:?}: {per_sample} heap allocations per extra camera sample ({few} → {many})"
        );
    }
}
