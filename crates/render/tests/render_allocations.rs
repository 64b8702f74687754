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
use std::sync::Mutex;

/// Held by each test for its whole run: the counter is global, so the tests of this file
/// must not allocate while another measures.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

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

/// The lane materials of [`SCENE`] with textured parameters: colors (the glass's
/// transmittance, the plane's reflectance) and a roughness (the conductor's).
fn textured_scene() -> String {
    SCENE
        .replace(
            "ior = 1.5 }",
            "ior = 1.5, specular_transmittance = { texture = \"checker\", a = 0.7, b = 1.0, scale = 6 } }",
        )
        .replace(
            "alpha = 0.2, material",
            "alpha = { texture = \"checker\", a = 0.1, b = 0.4, scale = 8 }, material",
        )
        .replace(
            "reflectance = 0.7 }",
            "reflectance = { texture = \"checker\", a = [0.2, 0.5, 0.7], b = 0.8, scale = 10 } }",
        )
}

/// Allocations made by one single-threaded render of `spp` samples per pixel.
fn allocations(spp: usize, kernel: Kernel) -> u64 {
    allocations_of(SCENE, spp, kernel)
}

/// [`allocations`] of the scene `source`.
fn allocations_of(source: &str, spp: usize, kernel: Kernel) -> u64 {
    let scene = load_scene_str(source, Path::new("test.toml")).unwrap_or_else(|e| panic!("{e}"));
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
    let _alone = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
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

/// Textured lane materials read their textures into lane parameters in the packet kernel:
/// no recipe rebuilt and no model allocated per hit either. (The scalar kernel still
/// rebuilds a textured material per hit, see `SceneMaterial::bsdf`.)
#[test]
fn a_packet_render_of_textured_lane_materials_allocates_nothing_per_sample() {
    let _alone = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let source = textured_scene();
    let scene = load_scene_str(&source, Path::new("test.toml")).unwrap_or_else(|e| panic!("{e}"));
    let textured = scene
        .materials
        .iter()
        .filter(|m| m.is_textured() && m.lane_bsdf().is_some())
        .count();
    assert_eq!(textured, 3, "the textured lane materials");
    let few = allocations_of(&source, 32, Kernel::Packet);
    let many = allocations_of(&source, 256, Kernel::Packet);
    let per_sample = many.saturating_sub(few) as f64 / (32 * 32 * (256 - 32)) as f64;
    println!("textured, packet: allocations {few} at 32 spp, {many} at 256 spp");
    assert!(
        per_sample < 1e-3,
        "{per_sample} heap allocations per extra camera sample ({few} → {many})"
    );
    // The scalar kernel's rebuild per hit is what the count would catch.
    let scalar_few = allocations_of(&source, 4, Kernel::Scalar);
    let scalar_many = allocations_of(&source, 8, Kernel::Scalar);
    assert!(
        scalar_many - scalar_few > 32 * 32 * 4,
        "the scalar kernel's textured hits allocate ({scalar_few} → {scalar_many})"
    );
}
