//! Glints [CCM19] in the renderer: the per-hit footprint from ray differentials or of the
//! whole pixel, the white furnace of a very rough orb (CCM19 Fig. 3) with exact and
//! approximate masking, normal map files in scenes, and the example scenes loading.

use facette_bsdf::models::glint::{generate, NormalMapKind};
use facette_render::film::Film;
use facette_render::image::write_normal_map;
use facette_render::integrator::Strategy;
use facette_render::kernel::Kernel;
use facette_render::render::{render, RenderOptions};
use facette_render::scene::{load_scene, load_scene_str, Scene};
use std::path::Path;
use std::sync::atomic::AtomicBool;

fn run(scene: &Scene, spp: usize) -> Film {
    run_with(scene, spp, None)
}

fn run_with(scene: &Scene, spp: usize, kernel: Option<Kernel>) -> Film {
    run_seeded(scene, spp, kernel, 3)
}

fn run_seeded(scene: &Scene, spp: usize, kernel: Option<Kernel>, seed: u64) -> Film {
    let opts = RenderOptions {
        spp: Some(spp),
        seed,
        strategy: Strategy::Mis,
        kernel,
        ..Default::default()
    };
    let (film, stats) = render(scene, &opts, &AtomicBool::new(false), &|_, _| {}).unwrap();
    assert_eq!(stats.discarded, 0, "no sample may be NaN/Inf/negative");
    film
}

fn grey(c: [f64; 3]) -> f64 {
    (c[0] + c[1] + c[2]) / 3.0
}

fn furnace(masking: &str) -> String {
    format!(
        r#"
        [camera]
        position = [0, 0, 4]
        target = [0, 0, 0]
        fov = 32
        [film]
        width = 20
        height = 20
        filter = "box"
        [integrator]
        max_depth = 64
        rr_depth = 64
        [[objects]]
        shape = "sphere"
        radius = 1
        material = {{ type = "glint", generate = "bumpy", resolution = 128, seed = 1, uv_scale = 2, masking = "{masking}", masking_lobes = 256 }}
        [[lights]]
        type = "constant"
        radiance = 1.0
        "#
    )
}

/// CCM19 Fig. 3: the exact P-BRDF (F = 1) in a unit constant environment never exceeds 1
/// beyond noise; the gap to 1 is printed for exact and approximate masking.
#[test]
fn white_furnace_of_a_very_rough_orb() {
    for masking in ["exact", "approx"] {
        let s = load_scene_str(&furnace(masking), Path::new("t.toml")).unwrap();
        let film = run(&s, 24);
        // The sphere covers the central pixels (radius 1 at distance 4, fov 32°: ~ 14 px).
        let (mean, err) = film.block_mean(6, 6, 14, 14);
        let img = film.image();
        let worst = img
            .data()
            .iter()
            .map(|p| p[0] as f64)
            .fold(0.0f64, f64::max);
        println!(
            "glint furnace ({masking} masking): centre 8×8 mean {:.4} ± {:.4} (gap to 1: {:.4}), brightest pixel {worst:.3}",
            grey(mean),
            grey(err),
            1.0 - grey(mean)
        );
        assert!(
            grey(mean) <= 1.0 + 4.0 * grey(err),
            "{masking}: {mean:?} ± {err:?}"
        );
        assert!(grey(mean) > 0.5, "{masking}: {mean:?}");
    }
}

#[test]
fn a_normal_map_file_renders_and_bad_files_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let map = generate(NormalMapKind::Scratched, 64, 4).unwrap();
    write_normal_map(dir.path().join("scratches.png"), &map).unwrap();
    std::fs::write(dir.path().join("broken.png"), b"\x89PNG\r\n\x1a\nxx").unwrap();
    let src = |file: &str| {
        format!(
            r#"
            [camera]
            position = [0, 0, 4]
            target = [0, 0, 0]
            fov = 32
            [film]
            width = 16
            height = 16
            [[objects]]
            shape = "sphere"
            radius = 1
            material = {{ type = "glint", normal_map = "{file}", uv_scale = 2, material = "Al" }}
            [[lights]]
            type = "point"
            position = [2, 2, 4]
            intensity = 20
            "#
        )
    };
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, src("scratches.png")).unwrap();
    let s = load_scene(&path).unwrap();
    let film = run(&s, 4);
    let (mean, _) = film.block_mean(0, 0, 16, 16);
    assert!(grey(mean) > 0.0 && grey(mean).is_finite(), "{mean:?}");
    for (file, msg) in [("broken.png", "broken.png"), ("nothing.exr", "nothing.exr")] {
        std::fs::write(&path, src(file)).unwrap();
        let e = match load_scene(&path) {
            Ok(_) => panic!("{file} loaded"),
            Err(e) => e.to_string(),
        };
        assert!(e.contains(msg), "{e}");
    }
}

#[test]
fn example_glint_scenes_load() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    for f in [
        "glint-scratched-sphere.toml",
        "glint-brushed-plate.toml",
        "glint-rough-furnace.toml",
    ] {
        load_scene(&root.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
    }
}

/// A scratched sphere under a point light, 48² pixels, about six texels a pixel.
fn scratched(footprint: &str) -> Scene {
    scratched_with(&format!(r#", footprint = "{footprint}""#))
}

/// The grey value of each pixel.
fn render_with(scene: &Scene, spp: usize, kernel: Kernel) -> Vec<f64> {
    let film = run_with(scene, spp, Some(kernel));
    film.sums
        .iter()
        .zip(&film.counts)
        .map(|(s, &n)| grey(*s) / n as f64)
        .collect()
}

/// Root-mean-square difference of two images relative to the first one's mean.
fn relative_rms(a: &[f64], b: &[f64]) -> f64 {
    let mean = a.iter().sum::<f64>() / a.len() as f64;
    let ms = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64;
    ms.sqrt() / mean
}

/// `footprint = "pixel"`: every sample of a pixel shades the pixel's patch in the frame of
/// the pixel's centre, so under a point light the image depends far less on the sample
/// count (the samples differ only in their view and light directions) than with the
/// samples' own shrinking footprints; the scalar and the packet kernel agree.
#[test]
fn pixel_footprints_depend_less_on_the_sample_count_and_agree_between_kernels() {
    let pixel = scratched("pixel");
    let one = render_with(&pixel, 1, Kernel::Packet);
    let sixteen = render_with(&pixel, 16, Kernel::Packet);
    let scalar = render_with(&pixel, 16, Kernel::Scalar);
    let ray = scratched("ray");
    let ray_one = render_with(&ray, 1, Kernel::Packet);
    let ray_sixteen = render_with(&ray, 16, Kernel::Packet);
    let (d_pixel, d_ray) = (
        relative_rms(&sixteen, &one),
        relative_rms(&ray_sixteen, &ray_one),
    );
    let d_kernels = relative_rms(&sixteen, &scalar);
    println!(
        "1 vs 16 spp, relative RMS: pixel footprints {d_pixel:.4}, ray footprints {d_ray:.4}; \
         packet vs scalar kernel (pixel, 16 spp) {d_kernels:.2e}"
    );
    // Measured: 1.67 against 20.1 (relative to the mean of an image whose few highlight
    // pixels are 10³ times the rest; at 48² the light direction turns by about σ_ε across
    // a pixel, so even the pixel's patch sees each sample's highlight a little apart).
    assert!(d_pixel < 0.2 * d_ray, "{d_pixel} vs {d_ray}");
    assert!(d_kernels < 1e-2, "{d_kernels}");
}

/// The scratched sphere of [`scratched`] with `extra` keys added to its material (approximate
/// masking, ray footprints unless `extra` says otherwise).
fn scratched_with(extra: &str) -> Scene {
    let src = format!(
        r#"
        [camera]
        position = [0, 0, 4]
        target = [0, 0, 0]
        fov = 35
        [film]
        width = 48
        height = 48
        [integrator]
        max_depth = 2
        [[objects]]
        shape = "sphere"
        radius = 1
        material = {{ type = "glint", generate = "scratched", resolution = 256, seed = 3, uv_scale = 2, material = "Al", masking = "approx"{extra} }}
        [[lights]]
        type = "point"
        position = [3, 3, 4]
        intensity = 40
        "#
    );
    load_scene_str(&src, Path::new("t.toml")).unwrap()
}

fn rms(a: &[f64], b: &[f64]) -> f64 {
    (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
}

/// Issue 20's convergence criterion in small, at the scale of
/// `scenes/glint-scratched-sphere.toml` (about 6.7 texels a pixel, ray footprints): against
/// the brute-force reference at 4096 spp, the glint image at 256 spp on the default lattice
/// (four lobes a texel) is within 1.5× the reference's own error at 256 spp, and the finer
/// the lattice the nearer (docs/glints.md measures the full scene with
/// `scripts/glint_convergence.py`: 0.404, 0.160, 0.064 against the reference's 0.148). At
/// this size the paper's lattice is within the bound too (measured 0.122 against 0.223; n = 2
/// 0.101, n = 4 0.077): the bias of one lobe per texel shows in the full scene's highlight.
#[test]
fn the_glint_image_converges_to_the_brute_force_reference() {
    let reference = |spp| {
        render_with(
            &scratched_with(r#", evaluation = "reference""#),
            spp,
            Kernel::Packet,
        )
    };
    let truth = reference(4096);
    let err = |extra: &str| {
        rms(
            &truth,
            &render_with(&scratched_with(extra), 256, Kernel::Packet),
        )
    };
    let (paper, default, fine) = (
        err(", seed_subdivision = 1"),
        err(""),
        err(", seed_subdivision = 4"),
    );
    let own = rms(&truth, &reference(256));
    println!(
        "RMSE against the reference at 4096 spp, 256 spp each: reference {own:.4}, \
         glint n = 1 {paper:.4}, n = 2 (default) {default:.4}, n = 4 {fine:.4}"
    );
    assert!(default < 1.5 * own, "{default} vs {own}");
    assert!(
        fine < default && default < paper,
        "{paper} {default} {fine}"
    );
}

/// A glint sphere under a wide area light and a dim environment (both strategies of MIS
/// weigh the glints there) with `mis_pdf = mode`.
fn glint_under_area_light(mode: &str) -> Scene {
    let src = format!(
        r#"
        [camera]
        position = [0, 0, 4]
        target = [0, 0, 0]
        fov = 32
        [film]
        width = 24
        height = 24
        filter = "box"
        [integrator]
        max_depth = 3
        [[objects]]
        shape = "sphere"
        radius = 1
        material = {{ type = "glint", generate = "bumpy", resolution = 64, seed = 2, uv_scale = 2, roughness_floor = 0.04, masking = "approx", mis_pdf = "{mode}" }}
        [[objects]]
        shape = "sphere"
        center = [2, 2.5, 2]
        radius = 0.8
        emission = 4.0
        [[lights]]
        type = "constant"
        radiance = 0.2
        "#
    );
    load_scene_str(&src, Path::new("t.toml")).unwrap()
}

/// `mis_pdf = "filtered"` reports a proxy density to MIS, which stays unbiased (its weights
/// still sum to one): the sphere's mean radiance agrees with `mis_pdf = "exact"` within
/// their standard errors (independent seeds), and the two images do differ (the weights
/// changed). Where the only lights are delta lights the renderer does not read a sample's
/// density at all ([`facette_render::integrator`]; the glint tests check that the sample is
/// otherwise the same).
#[test]
fn the_filtered_mis_density_renders_the_same_mean() {
    let exact = run_seeded(&glint_under_area_light("exact"), 128, None, 1);
    let filtered = run_seeded(&glint_under_area_light("filtered"), 128, None, 2);
    // The sphere covers the central pixels (radius 1 at distance 4, fov 32°: ~ 17 px).
    let (me, ee) = exact.block_mean(5, 5, 19, 19);
    let (mf, ef) = filtered.block_mean(5, 5, 19, 19);
    let (me, ee, mf, ef) = (grey(me), grey(ee), grey(mf), grey(ef));
    let z = (mf - me) / (ee * ee + ef * ef).sqrt();
    println!("mean radiance: exact MIS density {me:.5} ± {ee:.5}, filtered {mf:.5} ± {ef:.5} ({z:+.2} standard errors)");
    assert!(z.abs() < 4.0, "{me} ± {ee} vs {mf} ± {ef}");
    assert!(me > 0.05, "{me}");
    let (a, b) = (exact.image(), filtered.image());
    assert!(a.data() != b.data());
}
