//! The packet kernel against the scalar one on a scene with every lane model (Lambert,
//! GGX and anisotropic Beckmann conductors with exact and Schlick Fresnel, GGX and Beckmann
//! dielectrics) beside materials that run through their f64 models lane by lane
//! (Oren–Nayar, interfaced Lambertian, a smooth dielectric), under an area light, a point
//! light and a constant sky. Both kernels draw the same numbers from the same streams, so
//! most pixels agree to the f32 rounding of the lane models; where a rounding moves a path
//! across a decision the two differ by noise. Both are checked: the share of pixels that
//! agree closely, and every 8 × 8 block's mean within its noise.

use facette_render::film::Film;
use facette_render::kernel::Kernel;
use facette_render::render::{render, RenderOptions};
use facette_render::scene::{load_scene_str, Scene};
use std::path::Path;
use std::sync::atomic::AtomicBool;

const SCENE: &str = r#"
    [camera]
    position = [0, 1.2, 5]
    target = [0, 0.3, 0]
    fov = 50
    [film]
    width = 48
    height = 32
    [integrator]
    max_depth = 10
    [materials]
    white = { type = "lambert", reflectance = [0.7, 0.6, 0.5] }
    gold = { type = "conductor", distribution = "ggx", alpha = 0.25, material = "Au" }
    brushed = { type = "conductor", distribution = "beckmann", alpha_u = 0.1, alpha_v = 0.4, material = "Al" }
    schlick = { type = "conductor", distribution = "ggx", alpha = 0.5, material = "Cu", fresnel = "schlick" }
    glass = { type = "dielectric", distribution = "ggx", alpha = 0.2, ior = 1.5 }
    frosted = { type = "dielectric", distribution = "beckmann", alpha = 0.4, ior = 1.33 }
    clay = { type = "oren-nayar", reflectance = 0.6, sigma = 0.35 }
    coated = { type = "il", kd = [0.2, 0.4, 0.6], ni = 1.5, alpha = 0.3 }
    smooth = { type = "dielectric", alpha = 0, ior = 1.5 }
    [[objects]]
    shape = "rectangle"
    transform = [{ rotate = { axis = [1, 0, 0], angle = -90 } }, { scale = 4 }, { translate = [0, -0.5, 0] }]
    material = "white"
    [[objects]]
    shape = "sphere"
    center = [-1.6, 0, 0]
    radius = 0.5
    material = "gold"
    [[objects]]
    shape = "sphere"
    center = [-0.5, 0, -0.3]
    radius = 0.5
    material = "glass"
    [[objects]]
    shape = "sphere"
    center = [0.6, 0, 0]
    radius = 0.5
    material = "brushed"
    [[objects]]
    shape = "sphere"
    center = [1.7, 0, -0.3]
    radius = 0.5
    material = "frosted"
    [[objects]]
    shape = "sphere"
    center = [-1.1, 1.0, -1]
    radius = 0.4
    material = "clay"
    [[objects]]
    shape = "sphere"
    center = [0.0, 1.0, -1]
    radius = 0.4
    material = "coated"
    [[objects]]
    shape = "sphere"
    center = [1.1, 1.0, -1]
    radius = 0.4
    material = "schlick"
    [[objects]]
    shape = "sphere"
    center = [0.2, 0.2, 1.2]
    radius = 0.2
    material = "smooth"
    [[objects]]
    shape = "rectangle"
    transform = [{ scale = 0.75 }, { rotate = { axis = [1, 0, 0], angle = 90 } }, { translate = [0, 3, 1] }]
    emission = 4.0
    [[lights]]
    type = "point"
    position = [2, 2, 2]
    intensity = 3
    [[lights]]
    type = "constant"
    radiance = 0.3
"#;

fn render_with(scene: &Scene, kernel: Kernel, spp: usize) -> Film {
    let opts = RenderOptions {
        spp: Some(spp),
        seed: 3,
        kernel: Some(kernel),
        ..Default::default()
    };
    let (film, stats) = render(scene, &opts, &AtomicBool::new(false), &|_, _| {}).unwrap();
    assert_eq!(
        stats.discarded, 0,
        "{kernel:?}: NaN, Inf or negative samples"
    );
    film
}

#[test]
fn packet_and_scalar_kernels_render_the_same_image() {
    let scene = load_scene_str(SCENE, Path::new("packet.toml")).unwrap_or_else(|e| panic!("{e}"));
    let mut lane_models: Vec<&str> = scene
        .materials
        .iter()
        .filter(|m| m.lane_bsdf().is_some())
        .map(|m| m.name.as_str())
        .collect();
    lane_models.sort_unstable();
    // "black" is the emitter's implicit material.
    assert_eq!(
        lane_models,
        ["black", "brushed", "coated", "frosted", "glass", "gold", "schlick", "white"],
        "the materials with lane models"
    );
    compare_kernels(&scene);
}

/// The same scene under an environment map (a procedural sky with a sun, 64 × 32) in place
/// of the constant sky: the packet kernel samples the map and looks up escaped rays in f32
/// lanes, the scalar kernel in f64.
#[test]
fn packet_and_scalar_kernels_render_the_same_image_under_an_environment_map() {
    let dir = std::env::temp_dir().join(format!("facette-packet-env-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = SCENE.replace(
        "type = \"constant\"\n    radiance = 0.3",
        "type = \"environment\"\n    file = \"sky.exr\"\n    \
         sky = { sun_direction = [0.5, 0.7, 0.9], sun_angular_radius = 8, sun_radiance = 30, width = 64, height = 32 }",
    );
    assert_ne!(text, SCENE);
    let scene =
        load_scene_str(&text, &dir.join("packet-env.toml")).unwrap_or_else(|e| panic!("{e}"));
    compare_kernels(&scene);
    std::fs::remove_dir_all(&dir).ok();
}

/// The same scene with two sphere lights and an elliptic disk light besides the rectangle:
/// the packet kernel samples spheres (by their cone) and disks (by area) in f32 lanes, the
/// scalar kernel in f64. One sphere overlaps the clay sphere, so some shading points lie
/// inside it and are sampled by area, lane by lane.
#[test]
fn packet_and_scalar_kernels_render_the_same_image_with_sphere_and_disk_lights() {
    let text = format!(
        "{SCENE}
    [[objects]]
    shape = \"sphere\"
    center = [-0.2, 2.2, 0.6]
    radius = 0.25
    emission = 8.0
    [[objects]]
    shape = \"sphere\"
    center = [-1.1, 1.35, -1]
    radius = 0.2
    emission = [6.0, 3.0, 1.0]
    [[objects]]
    shape = \"disk\"
    transform = [{{ scale = [0.3, 0.2, 1] }}, {{ rotate = {{ axis = [1, 0, 0], angle = 110 }} }}, {{ translate = [1.2, 2.4, 0.8] }}]
    emission = 5.0
"
    );
    let scene =
        load_scene_str(&text, Path::new("packet-spheres.toml")).unwrap_or_else(|e| panic!("{e}"));
    use facette_render::geometry::shape::Shape;
    let kinds: Vec<&str> = scene
        .lights
        .iter()
        .filter_map(|l| match l {
            facette_render::lights::Light::Area { shape, .. } => {
                match scene.geometry.shape(*shape) {
                    Some(Shape::Sphere(_)) => Some("sphere"),
                    Some(Shape::Disk(_)) => Some("disk"),
                    Some(Shape::Rectangle(_)) => Some("rectangle"),
                    _ => None,
                }
            }
            _ => None,
        })
        .collect();
    assert_eq!(
        kinds,
        ["rectangle", "sphere", "sphere", "disk"],
        "the area lights"
    );
    compare_kernels(&scene);
}

/// The two kernels' images at 32 spp: most pixels agree closely (the same paths), and every
/// 8 × 8 block's mean within its noise.
fn compare_kernels(scene: &Scene) {
    let spp = 32;
    let scalar = render_with(scene, Kernel::Scalar, spp);
    let packet = render_with(scene, Kernel::Packet, spp);
    assert_eq!(scalar.counts, packet.counts);
    // Pixels whose sums agree to 1e-3 (relative): the paths matched sample for sample.
    let close = (0..scalar.counts.len())
        .filter(|&i| {
            (0..3).all(|c| {
                let (a, b) = (scalar.sums[i][c], packet.sums[i][c]);
                (a - b).abs() <= 1e-3 * a.abs().max(b.abs()).max(1e-3)
            })
        })
        .count();
    let share = close as f64 / scalar.counts.len() as f64;
    // Block means within their noise (the two are correlated, which only makes this
    // stricter than needed).
    let mut worst_z: f64 = 0.0;
    for by in (0..32).step_by(8) {
        for bx in (0..48).step_by(8) {
            let (ma, ea) = scalar.block_mean(bx, by, 8, 8);
            let (mb, eb) = packet.block_mean(bx, by, 8, 8);
            for c in 0..3 {
                let se = (ea[c] * ea[c] + eb[c] * eb[c]).sqrt().max(1e-4);
                worst_z = worst_z.max((ma[c] - mb[c]).abs() / se);
            }
        }
    }
    println!(
        "pixels agreeing to 1e-3: {:.1} %, largest block |z| = {worst_z:.2}",
        100.0 * share
    );
    assert!(share > 0.8, "only {:.1} % of pixels agree", 100.0 * share);
    assert!(
        worst_z < 4.0,
        "a block differs by {worst_z:.2} standard errors"
    );
}

#[test]
fn packet_kernel_is_deterministic_across_thread_counts() {
    let scene = load_scene_str(SCENE, Path::new("packet.toml")).unwrap_or_else(|e| panic!("{e}"));
    let run = |threads| {
        let opts = RenderOptions {
            spp: Some(4),
            seed: 9,
            threads: Some(threads),
            kernel: Some(Kernel::Packet),
            ..Default::default()
        };
        render(&scene, &opts, &AtomicBool::new(false), &|_, _| {})
            .unwrap()
            .0
    };
    assert_eq!(run(1).image().data(), run(2).image().data());
}

#[test]
fn unknown_kernel_names_are_errors_that_list_the_valid_ones() {
    let src = SCENE.replace("max_depth = 10", "max_depth = 10\n    kernel = \"simd\"");
    let e = load_scene_str(&src, Path::new("packet.toml"))
        .err()
        .expect("an error")
        .to_string();
    assert!(
        e.contains("unknown kernel `simd`") && e.contains("scalar, packet"),
        "{e}"
    );
    assert!(e.contains("packet.toml:"), "no file:line in {e}");
}
