//! Scene files: the example scenes load and render without a single NaN/Inf sample, and
//! every kind of bad input is a clear error naming the file and line.

use facette_render::render::{render, RenderOptions};
use facette_render::scene::{load_scene, load_scene_str};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// Copies an example scene into a temporary directory with a smaller film, so that its
/// generated assets land there and not in the source tree.
fn small_copy(name: &str, dir: &Path, width: i64, height: i64) -> PathBuf {
    let src = std::fs::read_to_string(scenes_dir().join(name)).unwrap();
    let mut table: toml::Table = toml::from_str(&src).unwrap();
    let film = table
        .entry("film")
        .or_insert(toml::Value::Table(toml::Table::new()))
        .as_table_mut()
        .unwrap();
    film.insert("width".into(), toml::Value::Integer(width));
    film.insert("height".into(), toml::Value::Integer(height));
    let path = dir.join(name);
    std::fs::write(&path, toml::to_string(&table).unwrap()).unwrap();
    path
}

#[test]
fn example_scenes_render_without_nan_or_inf() {
    let dir = tempfile::tempdir().unwrap();
    let mut names: Vec<String> = std::fs::read_dir(scenes_dir())
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".toml"))
        .collect();
    names.sort();
    for required in [
        "showcase.toml",
        "glass.toml",
        "comparison.toml",
        "mesh.toml",
        "bench-sphere.toml",
        "furnace-ms.toml",
    ] {
        assert!(
            names.iter().any(|n| n == required),
            "scenes/{required} is missing"
        );
    }
    for name in names {
        let path = small_copy(&name, dir.path(), 48, 32);
        let scene = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
        let opts = RenderOptions {
            spp: Some(8),
            seed: 3,
            ..Default::default()
        };
        let (film, stats) = render(&scene, &opts, &AtomicBool::new(false), &|_, _| {}).unwrap();
        let image = film.image();
        let bad = image
            .data()
            .iter()
            .flatten()
            .filter(|v| !v.is_finite() || **v < 0.0)
            .count();
        println!(
            "{name}: {} samples, {} discarded, mean {:.4}",
            stats.samples,
            stats.discarded,
            image.data().iter().map(|p| p[1] as f64).sum::<f64>() / image.data().len() as f64
        );
        assert_eq!(bad, 0, "{name}: {bad} non-finite or negative pixel values");
        assert_eq!(stats.discarded, 0, "{name}: NaN/Inf samples");
        assert!(
            image.data().iter().any(|p| p[1] > 0.0),
            "{name}: black image"
        );
    }
    // The sky of the showcase was generated once into the scene's assets folder.
    assert!(dir.path().join("assets/sky.exr").is_file());
}

fn error_of(src: &str) -> String {
    match load_scene_str(src, Path::new("scene.toml")) {
        Ok(_) => panic!("accepted:\n{src}"),
        Err(e) => e.to_string(),
    }
}

const CAMERA: &str = "[camera]\nposition = [0, 0, 4]\ntarget = [0, 0, 0]\n";

#[test]
fn syntax_errors_give_file_and_line() {
    let e = error_of(&format!(
        "{CAMERA}[film]\nwidth = 64\nheight = 6 4\nspp = 4\n"
    ));
    assert!(e.starts_with("scene.toml:6:"), "{e}");
    let e = error_of(&format!(
        "{CAMERA}[[objects]]\nshape = \"sphere\"\nradius = \"big\"\nmaterial = \"m\"\n"
    ));
    assert!(e.starts_with("scene.toml:6:"), "{e}");
}

#[test]
fn unknown_keys_list_the_valid_ones() {
    let e = error_of("[camera]\nposition = [0, 0, 4]\ntarget = [0, 0, 0]\nfovv = 40\n");
    assert!(
        e.starts_with("scene.toml:4:") && e.contains("`fovv`") && e.contains("`fov`"),
        "{e}"
    );
    let e = error_of(&format!(
        "{CAMERA}[materials]\nm = {{ type = \"conductor\", alpah = 0.3 }}\n"
    ));
    assert!(e.starts_with("scene.toml:5:"), "{e}");
    assert!(
        e.contains("unknown key `alpah`") && e.contains("valid keys:") && e.contains("alpha"),
        "{e}"
    );
    let e = error_of(&format!(
        "{CAMERA}[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = 1\nradiance = 2\n"
    ));
    assert!(
        e.starts_with("scene.toml:4:")
            && e.contains("`radiance` does not apply")
            && e.contains("intensity"),
        "{e}"
    );
}

#[test]
fn unknown_names_list_the_valid_ones() {
    let e = error_of(&format!(
        "{CAMERA}[materials]\nm = {{ type = \"lambrt\" }}\n"
    ));
    assert!(
        e.contains("unknown material type `lambrt`")
            && e.contains("lambert, oren-nayar, conductor, dielectric, kelemen, il"),
        "{e}"
    );
    let e = error_of(&format!(
        "{CAMERA}[materials]\nred = {{ type = \"lambert\" }}\nblue = {{ type = \"lambert\" }}\n[[objects]]\nshape = \"sphere\"\nmaterial = \"green\"\n"
    ));
    assert!(
        e.starts_with("scene.toml:9:")
            && e.contains("unknown material `green`; defined: blue, red"),
        "{e}"
    );
    let e = error_of(&format!(
        "{CAMERA}[[objects]]\nshape = \"teapot\"\nmaterial = {{ type = \"lambert\" }}\n"
    ));
    assert!(
        e.contains("unknown shape `teapot`")
            && e.contains("sphere, rectangle, disk, cube, obj, ply, torus-knot"),
        "{e}"
    );
    let e = error_of(&format!("{CAMERA}[[lights]]\ntype = \"sun\"\n"));
    assert!(
        e.contains("unknown light type `sun`")
            && e.contains("point, spot, directional, environment, constant"),
        "{e}"
    );
    let e = error_of(&format!("{CAMERA}[film]\nfilter = \"mitchell\"\n"));
    assert!(
        e.contains("unknown filter `mitchell`; valid: box, gaussian"),
        "{e}"
    );
    let e = error_of(&format!("{CAMERA}[film]\nsampler = \"halton\"\n"));
    assert!(
        e.starts_with("scene.toml:")
            && e.contains("unknown sampler `halton`; valid: sobol, independent, stratified"),
        "{e}"
    );
}

#[test]
fn out_of_range_and_non_finite_parameters_are_rejected() {
    let obj = |m: &str| format!("{CAMERA}[[objects]]\nshape = \"sphere\"\nmaterial = {m}\n");
    let e = error_of(&obj("{ type = \"conductor\", alpha = nan }"));
    assert!(
        e.starts_with("scene.toml:6:") && e.contains("`alpha` must be a finite number"),
        "{e}"
    );
    let e = error_of(&obj("{ type = \"lambert\", reflectance = 1.5 }"));
    assert!(e.contains("reflectance"), "{e}");
    let e = error_of(&obj("{ type = \"il\", ni = 0.5, alpha = 0.2 }"));
    assert!(e.contains("ni"), "{e}");
    let e = error_of(&format!("{CAMERA}[[objects]]\nshape = \"sphere\"\nradius = -1\nmaterial = {{ type = \"lambert\" }}\n"));
    assert!(
        e.starts_with("scene.toml:4:") && e.contains("radius"),
        "{e}"
    );
    let e = error_of("[camera]\nposition = [0, 0, 4]\ntarget = [0, 0, 4]\n[[objects]]\nshape = \"sphere\"\nmaterial = { type = \"lambert\" }\n");
    assert!(
        e.starts_with("scene.toml:1:") && e.contains("camera"),
        "{e}"
    );
    let e = error_of("[camera]\nposition = [0, 0, 4]\ntarget = [0, 0, 0]\nfov = 200\n");
    assert!(e.contains("fov") && e.contains("(0, 180)"), "{e}");
    let e = error_of(&format!("{CAMERA}[film]\nwidth = 0\n"));
    assert!(e.contains("film size"), "{e}");
    let e = error_of(&format!(
        "{CAMERA}[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = -1\n"
    ));
    assert!(
        e.contains("`intensity`") && e.contains("outside 0…1e15"),
        "{e}"
    );
    let e = error_of(&format!("{CAMERA}[[objects]]\nshape = \"sphere\"\nmaterial = {{ type = \"lambert\" }}\ntransform = [{{ scale = 0 }}]\n"));
    assert!(e.starts_with("scene.toml:4:"), "{e}");
    let e = error_of(&format!("{CAMERA}[[objects]]\nshape = \"sphere\"\nmaterial = {{ type = \"lambert\", reflectance = {{ texture = \"checker\", a = 2 }} }}\n"));
    assert!(
        e.contains("`reflectance`") && e.contains("out of range"),
        "{e}"
    );
}

#[test]
fn missing_or_corrupt_files_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let scene_path = dir.path().join("s.toml");
    let load = |src: &str| {
        std::fs::write(&scene_path, src).unwrap();
        load_scene(&scene_path)
            .err()
            .map(|e| e.to_string())
            .expect("must fail")
    };
    let e = load(&format!("{CAMERA}[[objects]]\nshape = \"obj\"\nfile = \"bunny.obj\"\nmaterial = {{ type = \"lambert\" }}\n"));
    assert!(
        e.contains("s.toml:4:") && e.contains("bunny.obj") && e.contains("No such file"),
        "{e}"
    );
    let e = load(&format!("{CAMERA}[[objects]]\nshape = \"sphere\"\nmaterial = {{ type = \"lambert\", reflectance = {{ image = \"wood.png\" }} }}\n"));
    assert!(e.contains("s.toml:6:") && e.contains("wood.png"), "{e}");
    let e = load(&format!(
        "{CAMERA}[[lights]]\ntype = \"environment\"\nfile = \"studio.exr\"\n"
    ));
    assert!(e.contains("s.toml:4:") && e.contains("studio.exr"), "{e}");
    // A corrupt texture and a malformed mesh.
    std::fs::write(dir.path().join("bad.png"), b"\x89PNG\r\n\x1a\nnot really").unwrap();
    let e = load(&format!("{CAMERA}[[objects]]\nshape = \"sphere\"\nmaterial = {{ type = \"lambert\", reflectance = {{ image = \"bad.png\" }} }}\n"));
    assert!(e.contains("bad.png"), "{e}");
    std::fs::write(dir.path().join("bad.obj"), "v 0 0 0\nv 1 0 0\nf 1 2 9\n").unwrap();
    let e = load(&format!("{CAMERA}[[objects]]\nshape = \"obj\"\nfile = \"bad.obj\"\nmaterial = {{ type = \"lambert\" }}\n"));
    assert!(e.contains("bad.obj:3"), "{e}");
    // A file in the sky's place that facette did not write is never replaced.
    std::fs::write(dir.path().join("mine.exr"), b"precious").unwrap();
    let e = load(&format!("{CAMERA}[[lights]]\ntype = \"environment\"\nfile = \"mine.exr\"\nsky = {{ width = 16, height = 8 }}\n"));
    assert!(e.contains("mine.exr"), "{e}");
    assert_eq!(
        std::fs::read(dir.path().join("mine.exr")).unwrap(),
        b"precious"
    );
}

/// Meshes from OBJ and PLY files, with a cube and a textured material, load and render.
#[test]
fn obj_and_ply_meshes_render() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("quad.obj"),
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("tri.ply"),
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n-1 -1 0.5\n1 -1 0.5\n0 1 0.5\n3 0 1 2\n",
    )
    .unwrap();
    let src = format!(
        "{CAMERA}[film]\nwidth = 16\nheight = 16\n\
         [[objects]]\nshape = \"obj\"\nfile = \"quad.obj\"\nmaterial = {{ type = \"lambert\", reflectance = {{ texture = \"checker\", a = 0.1, b = 0.9, scale = 2 }} }}\n\
         [[objects]]\nshape = \"ply\"\nfile = \"tri.ply\"\nmaterial = {{ type = \"conductor\", alpha = 0.2 }}\n\
         [[objects]]\nshape = \"cube\"\ntransform = [{{ scale = 0.2 }}, {{ translate = [0, 0, 1.5] }}]\nmaterial = {{ type = \"dielectric\", alpha = 0.1 }}\n\
         [[lights]]\ntype = \"constant\"\nradiance = 1\n"
    );
    let path = dir.path().join("m.toml");
    std::fs::write(&path, src).unwrap();
    let scene = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.geometry.primitive_count(), 2 + 1 + 12);
    let (film, stats) = render(
        &scene,
        &RenderOptions {
            spp: Some(4),
            ..Default::default()
        },
        &AtomicBool::new(false),
        &|_, _| {},
    )
    .unwrap();
    assert_eq!(stats.discarded, 0);
    assert!(film
        .image()
        .data()
        .iter()
        .all(|p| p.iter().all(|v| v.is_finite())));
}
