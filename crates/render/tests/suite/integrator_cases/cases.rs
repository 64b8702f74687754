// The integrator's test cases, compiled once per kernel (render_integrator.rs and
// render_integrator_packet.rs set `KERNEL`); the docs are in those files.

use facette_render::film::Film;
use facette_render::integrator::Strategy;
use facette_render::kernel::Kernel;
use facette_render::render::{render, RenderOptions};
use facette_render::scene::{load_scene_str, Scene};
use std::f64::consts::PI;
use std::path::Path;
use std::sync::atomic::AtomicBool;

fn scene(src: &str) -> Scene {
    load_scene_str(src, Path::new("test.toml")).unwrap_or_else(|e| panic!("{e}"))
}

fn run(scene: &Scene, spp: usize, seed: u64, strategy: Strategy, threads: Option<usize>) -> Film {
    let opts = RenderOptions {
        spp: Some(spp),
        seed,
        threads,
        strategy,
        kernel: Some(KERNEL),
        ..Default::default()
    };
    let (film, stats) = render(scene, &opts, &AtomicBool::new(false), &|_, _| {}).unwrap();
    assert_eq!(stats.discarded, 0, "no sample may be NaN/Inf/negative");
    assert!(!stats.interrupted);
    film
}

fn grey(c: [f64; 3]) -> f64 {
    (c[0] + c[1] + c[2]) / 3.0
}

/// A rough white conductor (GGX α = 1.5, F = 1) in the furnace: single scattering loses
/// most of the light; the random walk (scattering = "multiple") and the compensation
/// (energy = "compensated") render 1 — the rendered form of the issue's white furnace.
#[test]
fn rough_white_conductor_furnace_multiple_scattering_and_compensation() {
    let furnace = |material: &str| {
        let s = scene(&format!(
            r#"
            [camera]
            position = [0, 0, 3]
            target = [0, 0, 0]
            fov = 30
            [film]
            width = 24
            height = 24
            filter = "box"
            [[objects]]
            shape = "sphere"
            radius = 1
            material = {material}
            [[lights]]
            type = "constant"
            radiance = 1.0
            "#
        ));
        let film = run(&s, 64, 11, Strategy::Mis, None);
        let (mean, err) = film.block_mean(0, 0, 24, 24);
        println!(
            "furnace {material}: mean {:.4} ± {:.4}",
            grey(mean),
            grey(err)
        );
        (grey(mean), grey(err))
    };
    let (single, _) = furnace(
        r#"{ type = "conductor", distribution = "ggx", alpha = 1.5, masking = "smith-correlated" }"#,
    );
    assert!(single < 0.5, "single scattering loses energy: {single}");
    for m in [
        r#"{ type = "conductor", distribution = "ggx", alpha = 1.5, scattering = "multiple" }"#,
        r#"{ type = "conductor", distribution = "ggx", alpha = 1.5, masking = "smith-correlated", energy = "compensated" }"#,
    ] {
        let (mean, err) = furnace(m);
        assert!((mean - 1.0).abs() < 4.0 * err + 3e-3, "{m}: {mean} ± {err}");
    }
}

/// A sphere of white Lambert inside a unit constant environment: every pixel is 1, with
/// paths long enough that no energy is cut.
#[test]
fn white_furnace_renders_one_everywhere() {
    for material in [
        r#"{ type = "lambert", reflectance = 1.0 }"#,
        // The flat interfaced Lambertian with a white substrate conserves energy exactly.
        r#"{ type = "il", kd = 1.0, ni = 1.5, alpha = 0 }"#,
    ] {
        let s = scene(&format!(
            r#"
            [camera]
            position = [0, 0, 4]
            target = [0, 0, 0]
            fov = 35
            [film]
            width = 24
            height = 24
            filter = "box"
            [integrator]
            max_depth = 200
            rr_depth = 200
            [[objects]]
            shape = "sphere"
            radius = 1
            material = {material}
            [[lights]]
            type = "constant"
            radiance = 1.0
            "#
        ));
        let film = run(&s, 64, 7, Strategy::Mis, None);
        let (mean, err) = film.block_mean(0, 0, 24, 24);
        assert!(
            (grey(mean) - 1.0).abs() < 4.0 * grey(err) + 1e-3,
            "{material}: image mean {mean:?} ± {err:?}"
        );
        let img = film.image();
        let mut worst = 0.0f64;
        for p in img.data() {
            worst = worst.max((p[0] as f64 - 1.0).abs());
        }
        // Per pixel (64 samples): the MIS estimate is never far from 1.
        assert!(worst < 0.25, "{material}: worst pixel deviates by {worst}");
        println!(
            "furnace {material}: mean {:.5} ± {:.5}, worst pixel |L − 1| = {worst:.3}",
            grey(mean),
            grey(err)
        );
    }
}

/// Camera straight down at a Lambertian plane; returns for each sampled pixel the rendered
/// value and the world point its centre sees.
fn plane_scene(light: &str, kd: f64, width: usize) -> Scene {
    scene(&format!(
        r#"
        [camera]
        position = [0, 6, 0]
        target = [0, 0, 0]
        up = [0, 0, -1]
        fov = 60
        [film]
        width = {width}
        height = {width}
        filter = "box"
        [integrator]
        max_depth = 2
        [[objects]]
        shape = "rectangle"
        transform = [{{ rotate = {{ axis = [1, 0, 0], angle = -90 }} }}, {{ scale = 20 }}]
        material = {{ type = "lambert", reflectance = {kd} }}
        {light}
        "#
    ))
}

fn plane_point(s: &Scene, x: usize, y: usize) -> glam::DVec3 {
    let (ray, _) = s
        .camera
        .generate_ray(x as f64 + 0.5, y as f64 + 0.5, glam::DVec2::ZERO);
    let t = -ray.origin.y / ray.dir.y;
    ray.origin + ray.dir * t
}

#[test]
fn lambertian_plane_under_a_point_light_matches_kd_over_pi_i_cos_over_r2() {
    let (kd, intensity) = (0.6, 10.0);
    let light_pos = glam::DVec3::new(0.7, 2.0, -0.4);
    let s = plane_scene(
        &format!(
            "[[lights]]\ntype = \"point\"\nposition = [{}, {}, {}]\nintensity = {intensity}",
            light_pos.x, light_pos.y, light_pos.z
        ),
        kd,
        64,
    );
    // A box filter over a small pixel: the pixel value is the footprint average, within
    // 0.1 % of the centre value here; 1024 samples bring the footprint noise to ~0.1 %.
    let film = run(&s, 1024, 1, Strategy::Mis, None);
    let img = film.image();
    let mut worst = 0.0f64;
    for y in (2..64).step_by(5) {
        for x in (2..64).step_by(5) {
            let p = plane_point(&s, x, y);
            let d = light_pos - p;
            let r2 = d.length_squared();
            let cos = d.y / r2.sqrt();
            let expected = kd / PI * intensity * cos / r2;
            let got = img.get(x, y)[0] as f64;
            worst = worst.max((got / expected - 1.0).abs());
        }
    }
    println!("point light: worst relative error {worst:.2e}");
    assert!(worst < 5e-3, "worst relative error {worst}");
}

#[test]
fn spot_light_is_a_point_light_inside_its_beam_and_dark_outside_its_cutoff() {
    let (kd, intensity) = (0.5, 8.0);
    let pos = glam::DVec3::new(0.0, 2.0, 0.0);
    let (beam, cutoff) = (20.0f64, 30.0f64);
    let s = plane_scene(
        &format!(
            "[[lights]]\ntype = \"spot\"\nposition = [0, 2, 0]\ndirection = [0, -1, 0]\nintensity = {intensity}\nbeam_width = {beam}\ncutoff_angle = {cutoff}"
        ),
        kd,
        48,
    );
    let film = run(&s, 4, 1, Strategy::Mis, None);
    let img = film.image();
    let (mut inside, mut outside, mut between) = (0, 0, 0);
    for y in 0..48 {
        for x in 0..48 {
            // Pixel corners decide whether the whole footprint is on one side of an edge.
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)].map(|(dx, dy)| {
                let (ray, _) =
                    s.camera
                        .generate_ray(x as f64 + dx, y as f64 + dy, glam::DVec2::ZERO);
                let p = ray.origin + ray.dir * (-ray.origin.y / ray.dir.y);
                (pos - p).normalize().y.acos().to_degrees()
            });
            let (lo, hi) = corners
                .iter()
                .fold((f64::MAX, 0.0f64), |(l, h), a| (l.min(*a), h.max(*a)));
            let got = img.get(x, y)[0] as f64;
            if hi < beam {
                let p = plane_point(&s, x, y);
                let d = pos - p;
                let expected = kd / PI * intensity * (d.y / d.length()) / d.length_squared();
                assert!(
                    (got / expected - 1.0).abs() < 0.02,
                    "({x}, {y}): {got} vs {expected}"
                );
                inside += 1;
            } else if lo > cutoff {
                assert_eq!(got, 0.0, "({x}, {y}) is outside the cutoff");
                outside += 1;
            } else if lo > beam && hi < cutoff {
                between += 1;
                let p = plane_point(&s, x, y);
                let d = pos - p;
                let full = kd / PI * intensity * (d.y / d.length()) / d.length_squared();
                assert!(
                    got > 0.0 && got < full,
                    "({x}, {y}): falloff {got} vs full {full}"
                );
            }
        }
    }
    assert!(
        inside > 50 && outside > 50 && between > 20,
        "{inside} {outside} {between}"
    );
}

#[test]
fn lambertian_plane_under_a_directional_light_is_kd_over_pi_e_cos() {
    let (kd, e) = (0.8, 3.0);
    let dir = glam::DVec3::new(1.0, -2.0, 0.5).normalize();
    let s = plane_scene(
        &format!(
            "[[lights]]\ntype = \"directional\"\ndirection = [{}, {}, {}]\nirradiance = {e}",
            dir.x, dir.y, dir.z
        ),
        kd,
        16,
    );
    let film = run(&s, 4, 1, Strategy::Mis, None);
    let expected = kd / PI * e * (-dir.y);
    for p in film.image().data() {
        assert!(
            (p[1] as f64 / expected - 1.0).abs() < 1e-5,
            "{} vs {expected}",
            p[1]
        );
    }
}

/// A Lambertian plane under a downward-facing disk light of radius R at height h, seen
/// through a narrow camera at the point right below the centre: L = kd · L_e · R²/(h² + R²).
/// All three estimators must find it.
#[test]
fn disk_light_irradiance_is_matched_by_each_estimator() {
    let (kd, le, r, h) = (0.5, 4.0, 0.5, 1.0);
    let s = scene(&format!(
        r#"
        [camera]
        position = [3, 2, 0]
        target = [0, 0, 0]
        fov = 0.2
        [film]
        width = 8
        height = 8
        filter = "box"
        [integrator]
        max_depth = 2
        [[objects]]
        shape = "rectangle"
        transform = [{{ rotate = {{ axis = [1, 0, 0], angle = -90 }} }}, {{ scale = 20 }}]
        material = {{ type = "lambert", reflectance = {kd} }}
        [[objects]]
        shape = "disk"
        transform = [{{ rotate = {{ axis = [1, 0, 0], angle = 90 }} }}, {{ scale = {r} }}, {{ translate = [0, {h}, 0] }}]
        emission = {le}
        "#
    ));
    let expected = kd * le * r * r / (h * h + r * r);
    for strategy in [Strategy::Mis, Strategy::NeeOnly, Strategy::BsdfOnly] {
        let film = run(&s, 2048, 3, strategy, None);
        let (m, e) = film.block_mean(0, 0, 8, 8);
        let (m, e) = (grey(m), grey(e));
        println!("disk light {strategy:?}: {m:.5} ± {e:.5} (expected {expected:.5})");
        // The footprint (0.01 wide) changes the irradiance by < 1e-4 relative.
        assert!(
            (m - expected).abs() < 4.5 * e + 2e-4 * expected,
            "{strategy:?}: {m} ± {e} vs {expected}"
        );
    }
}

/// The three estimators (NEE only, BSDF only, MIS) agree on every 8×8 block of a 32×32
/// render at 512 spp; returns the largest |z| found.
fn estimators_agree(src: &str) -> f64 {
    let s = scene(src);
    let films: Vec<(Strategy, Film)> = [Strategy::Mis, Strategy::NeeOnly, Strategy::BsdfOnly]
        .into_iter()
        .map(|st| (st, run(&s, 512, 11, st, None)))
        .collect();
    let mut worst_z = 0.0f64;
    for by in 0..4 {
        for bx in 0..4 {
            let blocks: Vec<([f64; 3], [f64; 3])> = films
                .iter()
                .map(|(_, f)| f.block_mean(bx * 8, by * 8, bx * 8 + 8, by * 8 + 8))
                .collect();
            for i in 0..3 {
                for j in i + 1..3 {
                    for c in 0..3 {
                        let (a, b) = (blocks[i], blocks[j]);
                        let se = (a.1[c].powi(2) + b.1[c].powi(2)).sqrt();
                        let diff = (a.0[c] - b.0[c]).abs();
                        // Identical blocks (black ones included) agree whatever their error.
                        let z = if diff == 0.0 {
                            0.0
                        } else {
                            diff / (se + 1e-9 * a.0[c].abs())
                        };
                        worst_z = worst_z.max(z);
                        assert!(
                            z < 4.5,
                            "block ({bx}, {by}) channel {c}: {:?} {} ± {} vs {:?} {} ± {}",
                            films[i].0,
                            a.0[c],
                            a.1[c],
                            films[j].0,
                            b.0[c],
                            b.1[c]
                        );
                    }
                }
            }
        }
    }
    worst_z
}

/// A glossy conductor, a rough dielectric, an interfaced-Lambertian sphere and a Lambertian
/// floor under an area light and a sky map: the three estimators agree on every 8×8 block.
#[test]
fn nee_only_bsdf_only_and_mis_agree_block_by_block() {
    let src = r#"
        [camera]
        position = [0, 1.2, 4]
        target = [0, 0.4, 0]
        fov = 50
        [film]
        width = 32
        height = 32
        filter = "box"
        [integrator]
        max_depth = 4
        [materials]
        metal = { type = "conductor", material = "Cu", distribution = "ggx", alpha = 0.35 }
        glass = { type = "dielectric", distribution = "beckmann", alpha = 0.4, ior = 1.5 }
        il = { type = "il", kd = [0.7, 0.4, 0.2], ni = 1.5, alpha = 0.3 }
        floor = { type = "lambert", reflectance = 0.5 }
        [[objects]]
        shape = "sphere"
        center = [-0.9, 0.4, 0]
        radius = 0.4
        material = "metal"
        [[objects]]
        shape = "sphere"
        center = [0, 0.4, 0]
        radius = 0.4
        material = "glass"
        [[objects]]
        shape = "sphere"
        center = [0.9, 0.4, 0]
        radius = 0.4
        material = "il"
        [[objects]]
        shape = "rectangle"
        transform = [{ rotate = { axis = [1, 0, 0], angle = -90 } }, { scale = 4 }]
        material = "floor"
        [[objects]]
        shape = "rectangle"
        transform = [{ rotate = { axis = [1, 0, 0], angle = 90 } }, { scale = 1.5 }, { translate = [0, 3, 1] }]
        emission = 2.0
        [[lights]]
        type = "environment"
        sky = { width = 64, height = 32, sun_angular_radius = 8, sun_radiance = 10 }
    "#;
    let worst_z = estimators_agree(src);
    println!("estimators agree: largest |z| over 16 blocks × 3 pairs × 3 channels = {worst_z:.2}");
}

/// Every kind of area light — a sphere (cone sampling), a rectangle (spherical
/// rectangle), a small cube mesh (spherical triangles, a triangle chosen by area) and a
/// two-sided disk — over glossy and diffuse surfaces: the three
/// estimators agree on every 8×8 block, so each light's sampler and the pdf MIS uses for
/// a BSDF sample that hits it are consistent.
#[test]
fn every_area_light_shape_agrees_across_estimators() {
    let src = r#"
        [camera]
        position = [0, 1.5, 4.5]
        target = [0, 0.3, 0]
        fov = 55
        [film]
        width = 32
        height = 32
        filter = "box"
        [integrator]
        max_depth = 3
        [materials]
        metal = { type = "conductor", material = "Au", distribution = "ggx", alpha = 0.25 }
        floor = { type = "lambert", reflectance = 0.5 }
        [[objects]]
        shape = "sphere"
        center = [-0.6, 0.45, 0]
        radius = 0.45
        material = "metal"
        [[objects]]
        shape = "rectangle"
        transform = [{ rotate = { axis = [1, 0, 0], angle = -90 } }, { scale = 4 }]
        material = "floor"
        [[objects]]
        shape = "sphere"
        center = [0.9, 0.6, 0.2]
        radius = 0.25
        emission = 6.0
        [[objects]]
        shape = "rectangle"
        transform = [{ rotate = { axis = [1, 0, 0], angle = 90 } }, { scale = [0.6, 0.3, 1] }, { translate = [0, 2.2, 0.5] }]
        emission = 3.0
        [[objects]]
        shape = "cube"
        transform = [{ scale = 0.15 }, { rotate = { axis = [0, 1, 0], angle = 30 } }, { translate = [-1.4, 0.4, 0.9] }]
        emission = [4.0, 2.0, 1.0]
        [[objects]]
        shape = "disk"
        transform = [{ rotate = { axis = [0, 1, 0], angle = -60 } }, { scale = 0.3 }, { translate = [1.6, 0.5, -0.4] }]
        emission = 2.0
        two_sided = true
        [[lights]]
        type = "constant"
        radiance = 0.1
    "#;
    let worst_z = estimators_agree(src);
    println!("every area light: largest |z| = {worst_z:.2}");
}

#[test]
fn the_image_depends_on_the_seed_not_on_the_thread_count() {
    let src = r#"
        [camera]
        position = [0, 0.5, 3]
        target = [0, 0, 0]
        [film]
        width = 40
        height = 30
        [[objects]]
        shape = "sphere"
        radius = 0.7
        material = { type = "il", kd = 0.6, ni = 1.4, alpha = 0.4, scattering = "multiple", masking = "v-cavity" }
        [[lights]]
        type = "point"
        position = [1, 2, 2]
        intensity = 5
        [[lights]]
        type = "constant"
        radiance = 0.3
    "#;
    let s = scene(src);
    let a = run(&s, 6, 5, Strategy::Mis, Some(1));
    let b = run(&s, 6, 5, Strategy::Mis, Some(2));
    let c = run(&s, 6, 6, Strategy::Mis, Some(2));
    assert_eq!(a.image().data(), b.image().data(), "1 and 2 threads differ");
    assert_ne!(
        a.image().data(),
        c.image().data(),
        "the seed changes nothing"
    );
}

/// Rendering the samples in two parts (even and odd indices) and adding the films gives
/// the full render exactly.
#[test]
fn parts_of_the_samples_merge_into_the_full_render() {
    let src = r#"
        [camera]
        position = [0, 0.5, 3]
        target = [0, 0, 0]
        [film]
        width = 16
        height = 12
        [[objects]]
        shape = "sphere"
        radius = 0.7
        material = { type = "conductor", alpha = 0.3 }
        [[lights]]
        type = "constant"
        radiance = 1
    "#;
    let s = scene(src);
    let full = run(&s, 8, 2, Strategy::Mis, None);
    let part = |k| {
        let opts = RenderOptions {
            spp: Some(8),
            seed: 2,
            part: Some((k, 2)),
            kernel: Some(KERNEL),
            ..Default::default()
        };
        render(&s, &opts, &AtomicBool::new(false), &|_, _| {})
            .unwrap()
            .0
    };
    let (p0, p1) = (part(0), part(1));
    for i in 0..full.counts.len() {
        assert_eq!(p0.counts[i] + p1.counts[i], full.counts[i]);
        for c in 0..3 {
            let merged = p0.sums[i][c] + p1.sums[i][c];
            assert!((merged - full.sums[i][c]).abs() <= 1e-12 * full.sums[i][c].abs().max(1.0));
        }
    }
}
