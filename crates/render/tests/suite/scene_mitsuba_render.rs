//! Mitsuba 3 XML scenes rendered: the same image as the TOML version of a scene, analytic
//! values (furnace, a Lambertian plane under a point light), the example scenes without
//! NaN, and the glint plugin.

use crate::common::*;
use facette_render::geometry::{Vec2, Vec3};
use facette_render::image::RgbImage;
use facette_render::render::{render, RenderOptions};
use facette_render::scene::{load_scene, load_scene_str, load_scene_with, LoadOptions, Scene};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

fn render_image(s: &Scene, spp: usize) -> RgbImage {
    let opts = RenderOptions {
        spp: Some(spp),
        seed: 5,
        ..Default::default()
    };
    let (film, stats) = render(s, &opts, &AtomicBool::new(false), &|_, _| {}).unwrap();
    assert_eq!(stats.discarded, 0);
    film.image()
}

#[test]
fn the_xml_and_toml_versions_of_a_scene_render_the_same_image() {
    let xml = r#"<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="4"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 2, 5" target="0, 0.3, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="16"/><rfilter type="box"/></film>
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><rotate x="1" angle="-90"/><scale value="4"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" x="0" y="0.5" z="0"/><float name="radius" value="0.5"/>
        <bsdf type="roughconductor"><string name="material" value="Au"/><float name="alpha" value="0.3"/></bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" x="1.2" y="0.4" z="0.3"/><float name="radius" value="0.4"/>
        <bsdf type="roughdielectric"><float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/><float name="alpha" value="0.2"/></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/><translate y="3"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
        <emitter type="area"><rgb name="radiance" value="8"/></emitter>
    </shape>
    <emitter type="constant"><rgb name="radiance" value="0.2"/></emitter>
</scene>"#;
    let toml = r#"
[camera]
position = [0, 2, 5]
target = [0, 0.3, 0]
fov = 45
[film]
width = 24
height = 16
spp = 4
filter = "box"
sampler = "independent"
[integrator]
max_depth = 4
[[objects]]
shape = "rectangle"
transform = [{ rotate = { axis = [1, 0, 0], angle = -90 } }, { scale = 4 }]
material = { type = "lambert", reflectance = 0.6 }
[[objects]]
shape = "sphere"
center = [0, 0.5, 0]
radius = 0.5
material = { type = "conductor", material = "Au", distribution = "beckmann", g1 = "rational", alpha = 0.3 }
[[objects]]
shape = "sphere"
center = [1.2, 0.4, 0.3]
radius = 0.4
material = { type = "dielectric", ior = 1.5, ext_ior = 1, distribution = "beckmann", g1 = "rational", alpha = 0.2 }
[[objects]]
shape = "rectangle"
transform = [{ scale = 0.5 }, { rotate = { axis = [1, 0, 0], angle = 90 } }, { translate = [0, 3, 0] }]
emission = 8
[[lights]]
type = "constant"
radiance = 0.2
"#;
    let a = render_image(&load(xml), 64);
    let b = render_image(&load_scene_str(toml, Path::new("same.toml")).unwrap(), 64);
    let mut worst = 0.0f64;
    for (p, q) in a.data().iter().zip(b.data()) {
        for c in 0..3 {
            worst = worst.max((p[c] - q[c]).abs() as f64 / (q[c] as f64).max(1e-3));
        }
    }
    println!("XML vs TOML: largest relative pixel difference {worst:.2e}");
    // Same scene, same seed: the same samples, so the images agree to rounding.
    assert!(worst < 1e-5, "largest relative pixel difference {worst}");
}

#[test]
fn furnace_and_a_point_lit_plane_match_their_analytic_values() {
    // White furnace: flat IL with K_d = 1 (Mitsuba's nonlinear plastic) reflects exactly 1,
    // inside a unit constant environment every pixel is 1.
    let s = load(&scene_xml(
        r#"<shape type="sphere"><float name="radius" value="1.2"/>
        <bsdf type="plastic"><rgb name="diffuse_reflectance" value="1"/><boolean name="nonlinear" value="true"/></bsdf></shape>
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>"#,
    ));
    let img = render_image(&s, 64);
    let mean = img.data().iter().map(|p| p[1] as f64).sum::<f64>() / img.data().len() as f64;
    println!("furnace: mean {mean:.5}");
    assert!((mean - 1.0).abs() < 5e-3, "furnace mean {mean}");
    // A Lambertian plane under a point light, seen from straight above: each pixel is the
    // average over its footprint (box filter) of K_d/π · I cos θ / r².
    let (kd, intensity) = (0.6, 10.0);
    let light = Vec3::new(0.7, 2.0, -0.4);
    let s = load(&format!(
        r#"<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="2"/></integrator>
    <sensor type="perspective"><float name="fov" value="20"/>
        <transform name="to_world"><lookat origin="0, 6, 0" target="0, 0, 0" up="0, 0, -1"/></transform>
        <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/><rfilter type="box"/></film>
    </sensor>
    <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><scale value="20"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="{kd}"/></bsdf></shape>
    <emitter type="point"><point name="position" x="{}" y="{}" z="{}"/><rgb name="intensity" value="{intensity}"/></emitter>
</scene>"#,
        light.x, light.y, light.z
    ));
    // 512 samples bring the noise of the footprint average to ~0.1 %.
    let img = render_image(&s, 512);
    let mut worst = 0.0f64;
    for y in (1..32).step_by(5) {
        for x in (1..32).step_by(5) {
            let mut expected = 0.0;
            for k in 0..256 {
                let (sx, sy) = ((k % 16) as f64 + 0.5, (k / 16) as f64 + 0.5);
                let (ray, _) =
                    s.camera
                        .generate_ray(x as f64 + sx / 16.0, y as f64 + sy / 16.0, Vec2::ZERO);
                let p = ray.origin + ray.dir * (-ray.origin.y / ray.dir.y);
                let d = light - p;
                expected += kd / PI * intensity * d.y / d.length().powi(3) / 256.0;
            }
            worst = worst.max((img.get(x, y)[0] as f64 / expected - 1.0).abs());
        }
    }
    println!("point-lit plane: worst relative error {worst:.2e}");
    assert!(worst < 5e-3, "worst relative error {worst}");
}

#[test]
fn the_example_scenes_render_without_nan() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/mitsuba");
    let mut names: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "xml"))
        .collect();
    names.sort();
    assert!(!names.is_empty());
    for path in names {
        // Every example takes its size and sample count as parameters.
        let options = LoadOptions {
            defines: [("width", "32"), ("height", "20"), ("spp", "4")]
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
        };
        let s = load_scene_with(&path, &options).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            s.warnings.is_empty(),
            "{}: {:?}",
            path.display(),
            s.warnings
        );
        let img = render_image(&s, 4);
        let bad = img
            .data()
            .iter()
            .flatten()
            .filter(|v| !v.is_finite() || **v < 0.0)
            .count();
        assert_eq!(bad, 0, "{}", path.display());
        assert!(
            img.data().iter().any(|p| p[1] > 0.0),
            "{}: black",
            path.display()
        );
    }
    // load_scene dispatches on the extension.
    assert!(load_scene(&dir.join("missing.xml"))
        .err()
        .expect("an error")
        .to_string()
        .contains("missing.xml"));
}

/// facette's glint material as a Mitsuba plugin: parameters named as in TOML, a normal map
/// file resolved next to the scene, and its keys listed when one is wrong.
#[test]
fn glint_plugin_renders_from_a_generated_map_or_a_file() {
    let sphere = |bsdf: &str| {
        scene_xml(&format!(
            r#"<shape type="sphere">{bsdf}</shape>
    <emitter type="point"><point name="position" x="0" y="2" z="4"/><rgb name="intensity" value="40"/></emitter>"#
        ))
    };
    let s = load(&sphere(
        r#"<bsdf type="glint"><string name="generate" value="bumpy"/><integer name="resolution" value="32"/><float name="uv_scale" value="2"/><string name="material" value="Al"/></bsdf>"#,
    ));
    let mean = render_image(&s, 2).mean();
    assert!(mean[0] > 0.0 && mean.is_finite(), "{mean:?}");

    let dir = tempfile::tempdir().unwrap();
    // A flat 2×2 tangent-space normal map (every normal (0, 0, 1)).
    let mut img = image::RgbImage::new(2, 2);
    for p in img.pixels_mut() {
        *p = image::Rgb([128, 128, 255]);
    }
    img.save(dir.path().join("flat.png")).unwrap();
    let s = load_in(
        dir.path(),
        &sphere(r#"<bsdf type="glint"><string name="normal_map" value="flat.png"/></bsdf>"#),
        &[],
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(render_image(&s, 1).mean().is_finite());

    let e = error(&sphere(
        r#"<bsdf type="glint"><string name="generate" value="bumpy"/><float name="roughnes" value="0.1"/></bsdf>"#,
    ));
    assert!(e.contains("roughnes") && e.contains("scene.xml:"), "{e}");
}
