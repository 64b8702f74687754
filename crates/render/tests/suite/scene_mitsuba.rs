//! Mitsuba 3 XML scenes: every supported construct maps onto the values facette renders
//! (camera rays, lights, materials, transforms, textures, checked against hand-computed
//! values), `$name` defaults and `-D` overrides, `<include>` and `<ref>`, and the upgrade
//! of old files. Errors are in `scene_mitsuba_errors.rs`, rendered images in
//! `scene_mitsuba_render.rs`.

use crate::common::*;
use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::{BsdfContext, Spectrum};
use facette_render::geometry::{Shape, Vec2, Vec3};
use facette_render::image::{write_image, RgbImage};
use facette_render::lights::{Environment, Light};
use facette_render::scene::{load_scene_with, LoadOptions};
use std::f64::consts::PI;
use std::path::Path;

#[test]
fn defaults_are_substituted_and_command_line_defines_override_them() {
    let dir = tempfile::tempdir().unwrap();
    let xml = r#"<scene version="3.0.0">
    <default name="w" value="24"/>
    <default name="spp" value="3"/>
    <default name="r" value="0.25"/>
    <sensor type="perspective">
        <float name="fov" value="30"/>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm"><integer name="width" value="$w"/><integer name="height" value="8"/></film>
    </sensor>
    <shape type="sphere"><float name="radius" value="$r"/><point name="center" value="0, 0, $r"/></shape>
</scene>"#;
    let s = load_in(dir.path(), xml, &[]).unwrap();
    assert_eq!((s.film.width, s.film.spp), (24, 3));
    let s = load_in(dir.path(), xml, &[("w", "40"), ("r", "0.5")]).unwrap();
    assert_eq!(s.film.width, 40, "-D overrides <default>");
    match &s.geometry.shapes()[0] {
        Shape::Sphere(sp) => {
            assert_eq!(sp.radius(), 0.5);
            assert!(close(sp.center(), Vec3::new(0.0, 0.0, 0.5)));
        }
        _ => panic!("not a sphere"),
    }
    // An unused -D is a warning; an undefined $name an error naming it and its line.
    let s = load_in(dir.path(), xml, &[("nope", "1")]).unwrap();
    assert!(
        s.warnings.iter().any(|w| w.contains("-D nope=1")),
        "{:?}",
        s.warnings
    );
    let e = load_in(
        dir.path(),
        &xml.replace("value=\"$spp\"", "value=\"$sp\""),
        &[],
    )
    .err()
    .expect("an error");
    assert!(
        e.contains("scene.xml:7") && e.contains("undefined parameter `$sp`"),
        "{e}"
    );
    // A substituted value is checked like a written one.
    let e = load_in(dir.path(), xml, &[("w", "wide")])
        .err()
        .expect("an error");
    assert!(
        e.contains("scene.xml:8") && e.contains("\"wide\" is not an integer"),
        "{e}"
    );
}

#[test]
fn include_and_ref_share_one_material() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("parts")).unwrap();
    write(
        &dir.path().join("parts"),
        "materials.xml",
        r#"<scene version="3.0.0">
    <bsdf type="diffuse" id="red"><rgb name="reflectance" value="0.8, 0.1, 0.1"/></bsdf>
    <include filename="more.xml"/>
</scene>"#,
    );
    write(
        &dir.path().join("parts"),
        "more.xml",
        r#"<bsdf type="roughconductor" id="gold"><string name="material" value="Au"/></bsdf>"#,
    );
    let xml = scene_xml(
        r#"<include filename="parts/materials.xml"/>
    <shape type="sphere"><ref id="red"/></shape>
    <shape type="sphere"><point name="center" x="2" y="0" z="0"/><ref name="bsdf" id="red"/></shape>
    <shape type="sphere"><point name="center" x="-2" y="0" z="0"/><ref id="gold"/></shape>"#,
    );
    let s = load_in(dir.path(), &xml, &[]).unwrap();
    assert_eq!(
        s.shape_material[0], s.shape_material[1],
        "one material for one id"
    );
    let red = material_index(&s, "red");
    assert_eq!(s.shape_material[0] as usize, red);
    assert_material(
        &s,
        red,
        "type = \"lambert\"\nreflectance = [0.8, 0.1, 0.1]",
        Vec2::ZERO,
    );
    let gold = material_index(&s, "gold");
    assert_eq!(s.shape_material[2] as usize, gold);
    assert_material(
        &s,
        gold,
        "type = \"conductor\"\nmaterial = \"Au\"\ndistribution = \"beckmann\"\ng1 = \"rational\"\nalpha = 0.1",
        Vec2::ZERO,
    );
}

#[test]
fn the_sensor_gives_mitsubas_camera_rays() {
    let s = load(&scene_xml(""));
    let cam = &s.camera;
    assert_eq!((s.film.width, s.film.height, s.film.spp), (16, 12, 4));
    // Centre ray toward the target; the left and right image edges 20° off the axis.
    let (r, _) = cam.generate_ray(8.0, 6.0, Vec2::ZERO);
    assert!(close(r.origin, Vec3::new(0.0, 0.0, 5.0)) && close(r.dir, -Vec3::Z));
    let (r, _) = cam.generate_ray(0.0, 6.0, Vec2::ZERO);
    assert!((r.dir.angle_between(-Vec3::Z).to_degrees() - 20.0).abs() < 1e-9);
    // Looking down −z with +y up, world −x is on the left of the image (not mirrored).
    assert!(r.dir.x < 0.0);
    let (r, _) = cam.generate_ray(8.0, 0.0, Vec2::ZERO);
    assert!(r.dir.y > 0.0, "row 0 is the top");
    // fov_axis y, and Mitsuba's default film (768×576, Gaussian of radius 4σ = 2).
    let s = load(
        r#"<scene version="3.0.0"><sensor type="perspective"><float name="fov" value="30"/><string name="fov_axis" value="y"/></sensor></scene>"#,
    );
    assert_eq!((s.film.width, s.film.height, s.film.spp), (768, 576, 4));
    assert_eq!(
        s.film.filter,
        facette_render::film::Filter::gaussian(0.5, 2.0)
    );
    let (r, _) = s.camera.generate_ray(384.0, 0.0, Vec2::ZERO);
    assert!((r.dir.angle_between(Vec3::Z).to_degrees() - 15.0).abs() < 1e-9);
    // A Gaussian rfilter with its own stddev keeps Mitsuba's 4σ radius.
    let s = load(
        r#"<scene version="3.0.0"><sensor type="perspective"><film type="hdrfilm">
        <rfilter type="gaussian"><float name="stddev" value="0.3"/></rfilter></film></sensor></scene>"#,
    );
    assert_eq!(
        s.film.filter,
        facette_render::film::Filter::gaussian(0.3, 4.0 * 0.3)
    );
    // focal_length: 50 mm on the 36×24 mm diagonal, x_fov = 38.1848° at 768×576 (what
    // Mitsuba 3 reports).
    let s = load(
        r#"<scene version="3.0.0"><sensor type="perspective"><string name="focal_length" value="50mm"/></sensor></scene>"#,
    );
    let (r, _) = s.camera.generate_ray(0.0, 288.0, Vec2::ZERO);
    assert!((2.0 * r.dir.angle_between(Vec3::Z).to_degrees() - 38.1848).abs() < 1e-3);
    // A mirroring to_world mirrors the image, as in Mitsuba.
    let s = load(&scene_xml("").replace(
        "<transform name=\"to_world\">",
        "<transform name=\"to_world\"><scale x=\"-1\"/>",
    ));
    let (r, _) = s.camera.generate_ray(0.0, 6.0, Vec2::ZERO);
    assert!(r.dir.x > 0.0);
    // Box filter, thin lens.
    let s = load(
        r#"<scene version="3.0.0"><sensor type="thinlens"><float name="fov" value="30"/>
        <float name="aperture_radius" value="0.2"/><float name="focus_distance" value="3"/>
        <film type="hdrfilm"><rfilter type="box"/></film></sensor></scene>"#,
    );
    assert_eq!(s.film.filter, facette_render::film::Filter::Box);
    let (a, _) = s.camera.generate_ray(100.0, 100.0, Vec2::new(0.1, 0.9));
    let (b, _) = s.camera.generate_ray(100.0, 100.0, Vec2::new(0.8, 0.3));
    assert!((a.origin - b.origin).length() > 0.01, "the lens is sampled");
    let pa = a.origin + a.dir * (3.0 / a.dir.z);
    let pb = b.origin + b.dir * (3.0 / b.dir.z);
    assert!(close(pa, pb), "rays meet on the focal plane");
}

#[test]
fn integrator_settings_follow_mitsubas_depth_convention() {
    let s = load(&scene_xml(
        r#"<integrator type="path"><integer name="max_depth" value="3"/><integer name="rr_depth" value="2"/></integrator>"#,
    ));
    assert_eq!((s.integrator.max_depth, s.integrator.rr_depth), (3, 2));
    let s = load(&scene_xml(
        r#"<integrator type="path"><integer name="max_depth" value="-1"/></integrator>"#,
    ));
    assert_eq!((s.integrator.max_depth, s.integrator.rr_depth), (1024, 5));
    let s = load(&scene_xml(""));
    assert_eq!(s.integrator.max_depth, 1024, "Mitsuba's default: unlimited");
}

#[test]
fn transforms_place_shapes_like_mitsuba() {
    let s = load(&scene_xml(
        r#"<shape type="sphere">
        <point name="center" x="1" y="0" z="0"/>
        <float name="radius" value="0.5"/>
        <transform name="to_world">
            <scale value="2"/>
            <rotate z="1" angle="90"/>
            <translate x="0" y="0" z="-3"/>
        </transform>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><matrix value="2 0 0 1  0 3 0 0  0 0 1 0  0 0 0 1"/></transform>
        <boolean name="flip_normals" value="true"/>
    </shape>
    <shape type="disk"><transform name="to_world"><lookat origin="0, 1, 0" target="0, 1, 1"/></transform></shape>
    <shape type="cube"><transform name="to_world"><translate value="0, 5, 0"/></transform></shape>"#,
    ));
    let shapes = s.geometry.shapes();
    match &shapes[0] {
        // (1, 0, 0)·scale 2 → (2, 0, 0), rotated 90° about z → (0, 2, 0), then z − 3.
        Shape::Sphere(sp) => {
            assert!(
                close(sp.center(), Vec3::new(0.0, 2.0, -3.0)),
                "{}",
                sp.center()
            );
            assert!((sp.radius() - 1.0).abs() < 1e-12);
        }
        _ => panic!("sphere expected"),
    }
    match &shapes[1] {
        Shape::Rectangle(r) => {
            assert!((r.area() - 24.0).abs() < 1e-12);
            assert!(close(r.normal(), -Vec3::Z), "flip_normals");
            assert!(close(r.to_world().point(Vec3::ZERO), Vec3::X));
        }
        _ => panic!("rectangle expected"),
    }
    assert!(matches!(shapes[2], Shape::Disk(_)));
    match &shapes[3] {
        Shape::Mesh(m) => {
            let b = m.bounds();
            assert!(
                close(b.min, Vec3::new(-1.0, 4.0, -1.0)) && close(b.max, Vec3::new(1.0, 6.0, 1.0))
            );
        }
        _ => panic!("cube expected"),
    }
    // Shapes without a BSDF get Mitsuba's diffuse 0.5.
    assert_material(
        &s,
        s.shape_material[0] as usize,
        "type = \"lambert\"\nreflectance = 0.5",
        Vec2::ZERO,
    );
}

#[test]
fn mesh_files_load_with_mitsubas_normals_and_uvs() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "tri.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\nf 1/1 3/3 2/2\nf 1/1 2/2 4/4\nf 1/1 4/4 3/3\nf 2/2 3/3 4/4\n",
    );
    write(
        dir.path(),
        "tri.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
    );
    let xml = scene_xml(
        r#"<shape type="obj"><string name="filename" value="tri.obj"/></shape>
    <shape type="obj"><string name="filename" value="tri.obj"/><boolean name="face_normals" value="true"/><boolean name="flip_tex_coords" value="false"/></shape>
    <shape type="ply"><string name="filename" value="tri.ply"/></shape>"#,
    );
    let s = load_in(dir.path(), &xml, &[]).unwrap();
    let mesh = |i: usize| match &s.geometry.shapes()[i] {
        Shape::Mesh(m) => m.clone(),
        _ => panic!("mesh expected"),
    };
    // No normals in the file: angle-weighted vertex normals, as Mitsuba computes them;
    // the corner at the origin (three right angles) points along −(1, 1, 1).
    let m = mesh(0);
    let origin = m.positions().iter().position(|p| *p == Vec3::ZERO).unwrap();
    assert!(close(m.normals().unwrap()[origin], -Vec3::ONE.normalize()));
    // OBJ v is flipped by default (Mitsuba's flip_tex_coords), not with it off.
    let v_of = |m: &facette_render::geometry::TriangleMesh, p: Vec3| {
        let i = m.positions().iter().position(|q| *q == p).unwrap();
        m.uvs().unwrap()[i]
    };
    assert_eq!(v_of(&m, Vec3::Y), Vec2::new(0.0, 0.0));
    let flat = mesh(1);
    assert!(flat.normals().is_none(), "face_normals drops the normals");
    assert_eq!(v_of(&flat, Vec3::Y), Vec2::new(0.0, 1.0));
    assert_eq!(mesh(2).triangle_count(), 1);
}

/// A scene given by a relative path finds the files it names next to itself (once, not
/// under its directory twice).
#[test]
fn files_of_a_scene_given_by_a_relative_path_are_found() {
    let dir = tempfile::tempdir_in(".").unwrap();
    write(
        dir.path(),
        "tri.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    let xml = scene_xml(r#"<shape type="obj"><string name="filename" value="tri.obj"/></shape>"#);
    write(dir.path(), "scene.xml", &xml);
    let relative = Path::new(dir.path().file_name().unwrap()).join("scene.xml");
    assert!(relative.is_relative());
    let s = load_scene_with(&relative, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!(s
        .geometry
        .shapes()
        .iter()
        .any(|sh| matches!(sh, Shape::Mesh(m) if m.triangle_count() == 1)));
}

#[test]
fn emitters_map_to_lights_with_their_values() {
    let dir = tempfile::tempdir().unwrap();
    // A 4×2 lat-long map: the top row (the +y hemisphere) is 2, the bottom row 0.5.
    let img = RgbImage::from_fn(4, 2, |_, y| if y == 0 { [2.0; 3] } else { [0.5; 3] }).unwrap();
    write_image(dir.path().join("env.exr"), &img, 0.0).unwrap();
    let xml = scene_xml(
        r#"<emitter type="point">
        <transform name="to_world"><translate x="1" y="2" z="3"/></transform>
        <rgb name="intensity" value="1, 2, 3"/>
    </emitter>
    <emitter type="spot">
        <transform name="to_world"><lookat origin="0, 4, 0" target="0, 0, 0" up="0, 0, 1"/></transform>
        <float name="intensity" value="7"/>
        <float name="cutoff_angle" value="30"/>
    </emitter>
    <emitter type="directional"><vector name="direction" x="0" y="-2" z="0"/><rgb name="irradiance" value="0.5"/></emitter>
    <emitter type="envmap">
        <string name="filename" value="env.exr"/>
        <float name="scale" value="3"/>
        <transform name="to_world"><rotate x="1" angle="180"/></transform>
    </emitter>
    <shape type="disk"><emitter type="area"><rgb name="radiance" value="4, 5, 6"/></emitter></shape>"#,
    );
    let s = load_in(dir.path(), &xml, &[]).unwrap();
    let spectrum = |r, g, b| Spectrum::rgb(r, g, b);
    let mut saw = 0;
    for l in &s.lights {
        match l {
            Light::Point {
                position,
                intensity,
            } => {
                assert!(close(*position, Vec3::new(1.0, 2.0, 3.0)));
                assert_eq!(*intensity, spectrum(1.0, 2.0, 3.0));
                saw |= 1;
            }
            Light::Spot {
                position,
                frame,
                intensity,
                cutoff,
                beam,
            } => {
                assert!(close(*position, Vec3::new(0.0, 4.0, 0.0)));
                assert!(close(frame.n, -Vec3::Y), "shines along to_world's +z");
                assert_eq!(*intensity, Spectrum::splat(7.0));
                assert!((cutoff.to_degrees() - 30.0).abs() < 1e-9);
                assert!(
                    (beam.to_degrees() - 22.5).abs() < 1e-9,
                    "beam_width defaults to ¾ cutoff"
                );
                saw |= 2;
            }
            Light::Directional {
                direction,
                irradiance,
            } => {
                assert!(close(*direction, -Vec3::Y));
                assert_eq!(*irradiance, Spectrum::splat(0.5));
                saw |= 4;
            }
            Light::Environment(Environment::Map(m)) => {
                // Rotated 180° about x, the map's bright top row lies below.
                assert!((m.eval(-Vec3::Y)[0] - 6.0).abs() < 1e-6);
                assert!((m.eval(Vec3::Y)[0] - 1.5).abs() < 1e-6);
                saw |= 8;
            }
            Light::Area {
                shape,
                radiance,
                two_sided,
            } => {
                assert_eq!(*shape, 0);
                assert_eq!(*radiance, spectrum(4.0, 5.0, 6.0));
                assert!(!two_sided, "Mitsuba's area lights emit from the front side");
                saw |= 16;
            }
            _ => panic!("unexpected light"),
        }
    }
    assert_eq!(saw, 31);
    assert_eq!(s.shape_light[0], Some(0));
    // An emitter without a BSDF is black, as in Mitsuba (other shapes get diffuse 0.5).
    assert_material(
        &s,
        s.shape_material[0] as usize,
        "type = \"lambert\"\nreflectance = 0",
        Vec2::ZERO,
    );
    let s = load(&scene_xml(
        r#"<emitter type="constant"><rgb name="radiance" value="0.25"/></emitter>"#,
    ));
    match &s.lights[0] {
        Light::Environment(env @ Environment::Constant(_)) => {
            assert_eq!(env.eval(Vec3::X), Spectrum::splat(0.25))
        }
        _ => panic!("constant environment expected"),
    }
}

#[test]
fn bsdfs_map_to_facette_materials() {
    let s = load(&scene_xml(
        r#"<bsdf type="diffuse" id="diffuse"><rgb name="reflectance" value="0.2, 0.4, 0.6"/></bsdf>
    <bsdf type="conductor" id="mirror"/>
    <bsdf type="conductor" id="cu"><string name="material" value="Cu"/><rgb name="specular_reflectance" value="0.9"/></bsdf>
    <bsdf type="roughconductor" id="aniso">
        <string name="distribution" value="ggx"/>
        <float name="alpha_u" value="0.1"/><float name="alpha_v" value="0.3"/>
        <rgb name="eta" value="0.2, 0.9, 1.1"/><rgb name="k" value="3.9, 2.4, 2.1"/>
        <boolean name="sample_visible" value="false"/>
    </bsdf>
    <bsdf type="dielectric" id="water"><string name="int_ior" value="water"/><string name="ext_ior" value="vacuum"/></bsdf>
    <bsdf type="roughdielectric" id="glass"><float name="alpha" value="0.2"/></bsdf>
    <bsdf type="plastic" id="plastic"><rgb name="diffuse_reflectance" value="0.5"/><float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/><boolean name="nonlinear" value="true"/></bsdf>
    <bsdf type="roughplastic" id="roughplastic"><rgb name="diffuse_reflectance" value="0.3"/><float name="alpha" value="0.3"/><string name="distribution" value="ggx"/><float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/><boolean name="nonlinear" value="true"/></bsdf>
    <bsdf type="twosided" id="twosided"><bsdf type="diffuse"/></bsdf>
    <bsdf type="il" id="il"><rgb name="kd" value="0.7, 0.3, 0.1"/><float name="ni" value="1.3"/><string name="distribution" value="gaussian"/><float name="sigma" value="0.3"/></bsdf>
    <bsdf type="facette-conductor" id="schlick"><string name="material" value="Cu"/><string name="fresnel" value="schlick"/><float name="alpha" value="0.2"/><string name="masking" value="smith-correlated"/></bsdf>"#,
    ));
    for (name, toml) in [
        ("diffuse", "type = \"lambert\"\nreflectance = [0.2, 0.4, 0.6]"),
        ("mirror", "type = \"conductor\"\nalpha = 0\nmaterial = \"none\""),
        ("cu", "type = \"conductor\"\nalpha = 0\nmaterial = \"Cu\"\nspecular_reflectance = 0.9"),
        ("aniso", "type = \"conductor\"\ndistribution = \"ggx\"\nalpha_u = 0.1\nalpha_v = 0.3\neta = [0.2, 0.9, 1.1]\nk = [3.9, 2.4, 2.1]\nsampling = \"distribution\""),
        ("water", "type = \"dielectric\"\nalpha = 0\nior = 1.333\next_ior = 1.0"),
        ("glass", "type = \"dielectric\"\ndistribution = \"beckmann\"\ng1 = \"rational\"\nalpha = 0.2\nior = 1.5046\next_ior = 1.000277"),
        ("plastic", "type = \"il\"\nkd = 0.5\nni = 1.5\nalpha = 0"),
        ("roughplastic", "type = \"il\"\nkd = 0.3\nni = 1.5\ndistribution = \"ggx\"\nalpha = 0.3"),
        ("twosided", "type = \"lambert\"\nreflectance = 0.5"),
        ("il", "type = \"il\"\nkd = [0.7, 0.3, 0.1]\nni = 1.3\ndistribution = \"gaussian\"\nsigma = 0.3"),
        ("schlick", "type = \"conductor\"\nmaterial = \"Cu\"\nfresnel = \"schlick\"\nalpha = 0.2\nmasking = \"smith-correlated\""),
    ] {
        assert_material(&s, material_index(&s, name), toml, Vec2::ZERO);
    }
    // Mitsuba's default (linear) plastic: substrate albedo K with K/(1 − K r_i) = 0.5/(1 − r_i).
    let s = load(&scene_xml(
        r#"<bsdf type="plastic" id="p"><float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/></bsdf>"#,
    ));
    let ri = facette_bsdf::fresnel::internal_diffuse_reflectance(1.5);
    let a = 0.5 / (1.0 - ri);
    let k = a / (1.0 + a * ri);
    assert_material(
        &s,
        material_index(&s, "p"),
        &format!("type = \"il\"\nkd = {k:?}\nni = 1.5\nalpha = 0"),
        Vec2::ZERO,
    );
}

#[test]
fn textures_map_to_facette_textures() {
    let dir = tempfile::tempdir().unwrap();
    // A 2×2 PNG: top-left red, top-right green, bottom-left blue, bottom-right white.
    let img = RgbImage::new(
        2,
        2,
        vec![
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
        ],
    )
    .unwrap();
    write_image(dir.path().join("tex.png"), &img, 0.0).unwrap();
    let xml = scene_xml(
        r#"<texture type="bitmap" id="tex"><string name="filename" value="tex.png"/><string name="wrap_mode" value="clamp"/></texture>
    <bsdf type="diffuse" id="bitmap"><ref name="reflectance" id="tex"/></bsdf>
    <bsdf type="diffuse" id="shifted">
        <texture type="bitmap" name="reflectance">
            <string name="filename" value="tex.png"/>
            <transform name="to_uv"><translate x="0.5"/></transform>
        </texture>
    </bsdf>
    <bsdf type="diffuse" id="checker">
        <texture type="checkerboard" name="reflectance">
            <rgb name="color0" value="0.1"/><rgb name="color1" value="0.9"/>
            <transform name="to_uv"><scale value="2"/></transform>
        </texture>
    </bsdf>"#,
    );
    let s = load_in(dir.path(), &xml, &[]).unwrap();
    let refl = |m: &str, u: f64, v: f64| {
        let b = s.materials[material_index(&s, m)]
            .bsdf(Vec2::new(u, v), [0.0; 4])
            .unwrap();
        let f = b.eval(
            Vec3::Z,
            Vec3::Z,
            &BsdfContext::RADIANCE,
            &mut Pcg32::new(1, 1),
        );
        [f[0] * PI, f[1] * PI, f[2] * PI]
    };
    let near = |a: [f64; 3], b: [f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-6);
    // uv (0, 0) is the image's top-left (Mitsuba's bitmap convention).
    assert!(near(refl("bitmap", 0.25, 0.25), [1.0, 0.0, 0.0]));
    assert!(near(refl("bitmap", 0.75, 0.25), [0.0, 1.0, 0.0]));
    assert!(near(refl("bitmap", 0.25, 0.75), [0.0, 0.0, 1.0]));
    assert!(
        near(refl("bitmap", 1.5, 0.75), [1.0, 1.0, 1.0]),
        "wrap_mode clamp"
    );
    assert!(
        near(refl("shifted", 0.25, 0.25), [0.0, 1.0, 0.0]),
        "to_uv translates"
    );
    // Mitsuba's checkerboard: color0 where the halves of u and v agree, to_uv scales.
    assert!(near(refl("checker", 0.1, 0.1), [0.1; 3]));
    assert!(near(refl("checker", 0.35, 0.1), [0.9; 3]));
    assert!(near(refl("checker", 0.35, 0.35), [0.1; 3]));
}

#[test]
fn old_files_are_upgraded_like_mitsuba_does() {
    let s = load(
        r#"<scene version="0.6.0">
    <integrator type="path"><integer name="maxDepth" value="3"/></integrator>
    <sensor type="perspective"><float name="fov" value="30"/><string name="fovAxis" value="y"/>
        <sampler type="independent"><integer name="sampleCount" value="9"/></sampler>
        <transform name="toWorld"><lookAt origin="0, 0, 1" target="0, 0, 0" up="0, 1, 0"/></transform>
    </sensor>
    <shape type="sphere"><bsdf type="diffuse"><rgb name="diffuseReflectance" value="0.3"/></bsdf></shape>
</scene>"#,
    );
    assert_eq!((s.integrator.max_depth, s.film.spp), (3, 9));
    let (r, _) = s.camera.generate_ray(384.0, 288.0, Vec2::ZERO);
    assert!(close(r.dir, -Vec3::Z));
    assert_material(&s, 0, "type = \"lambert\"\nreflectance = 0.3", Vec2::ZERO);
}
