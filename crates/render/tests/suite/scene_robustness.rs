//! Hostile and careless scene files (issue 17): each is an error naming the file, the line
//! where it applies and the culprit — never a stack overflow, an allocation abort, a run
//! that does not end, or a scene whose pixels overflow.

use facette_render::scene::load_scene;
use std::path::{Path, PathBuf};

const TOML_SCENE: &str = r#"
[camera]
position = [0, 0, 4]
target = [0, 0, 0]
fov = 40

[film]
width = 8
height = 6
spp = 2

[[objects]]
shape = "sphere"
radius = 1
material = { type = "lambert", reflectance = 0.5 }

[[lights]]
type = "constant"
radiance = 1.0
"#;

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The error of loading `path` (which must fail).
fn error(path: &Path) -> String {
    match load_scene(path) {
        Ok(_) => panic!("{} loaded", path.display()),
        Err(e) => e.to_string(),
    }
}

fn toml_error(text: &str) -> String {
    let d = tempfile::tempdir().unwrap();
    error(&write(d.path(), "s.toml", text))
}

#[test]
fn radiance_like_inputs_and_exposure_are_bounded_so_pixels_stay_finite() {
    let e = toml_error(&TOML_SCENE.replace("radiance = 1.0", "radiance = 1e308"));
    assert!(e.contains("s.toml:") && e.contains("`radiance`"), "{e}");
    let e = toml_error(&TOML_SCENE.replace(
        "[[lights]]",
        "[[lights]]\ntype = \"point\"\nposition = [0, 2, 2]\nintensity = 1e308\n\n[[lights]]",
    ));
    assert!(e.contains("`intensity`"), "{e}");
    let e = toml_error(&TOML_SCENE.replace("material = {", "emission = 1e308\nmaterial = {"));
    assert!(e.contains("`emission`"), "{e}");
    let e = toml_error(&TOML_SCENE.replace("spp = 2", "spp = 2\nexposure = 2000"));
    assert!(e.contains("`exposure`") && e.contains("64"), "{e}");
    let e = toml_error(
        &TOML_SCENE
            .replace("width = 8", "width = 65536")
            .replace("height = 6", "height = 65536"),
    );
    assert!(e.contains("film pixels") && e.contains("s.toml:"), "{e}");
}

#[test]
fn toml_type_errors_speak_the_scene_format_not_rust() {
    for (text, key, shape) in [
        (
            TOML_SCENE.replace("width = 8", "width = \"a\""),
            "`width`",
            "a whole number",
        ),
        (
            TOML_SCENE.replace("radiance = 1.0", "radiance = \"red\""),
            "`radiance`",
            "a colour",
        ),
        (
            format!(
                "film = 3\n{}",
                TOML_SCENE.replace("[film]\nwidth = 8\nheight = 6\nspp = 2\n", "")
            ),
            "`film`",
            "a table",
        ),
    ] {
        let e = toml_error(&text);
        assert!(e.contains(key) && e.contains(shape), "{e}");
        for internal in ["Desc", "untagged", "usize", "struct"] {
            assert!(!e.contains(internal), "`{internal}` in: {e}");
        }
    }
}

fn xml_error(files: &[(&str, &str)]) -> String {
    let d = tempfile::tempdir().unwrap();
    for (name, text) in files {
        write(d.path(), name, text);
    }
    error(&d.path().join(files[0].0))
}

#[test]
fn mitsuba_reference_cycles_and_deep_nesting_are_errors_not_stack_overflows() {
    let e = xml_error(&[(
        "scene.xml",
        "<scene version=\"3.0.0\">\n<bsdf type=\"twosided\" id=\"a\"><ref id=\"a\"/></bsdf>\n</scene>\n",
    )]);
    assert!(
        e.contains("scene.xml:2") && e.contains("cycle (a → a)"),
        "{e}"
    );
    // A longer cycle through two objects.
    let e = xml_error(&[(
        "scene.xml",
        "<scene version=\"3.0.0\">\n<texture type=\"bitmap\" id=\"t\"><ref id=\"b\"/></texture>\n<bsdf type=\"diffuse\" id=\"b\"><ref name=\"reflectance\" id=\"t\"/></bsdf>\n</scene>\n",
    )]);
    assert!(e.contains("cycle"), "{e}");
    let deep = format!(
        "<scene version=\"3.0.0\">{}{}</scene>",
        "<bsdf type=\"twosided\">".repeat(20_000),
        "</bsdf>".repeat(20_000)
    );
    let e = xml_error(&[("scene.xml", &deep)]);
    assert!(e.contains("nesting depth"), "{e}");
}

#[test]
fn mitsuba_parameter_bombs_and_include_fan_outs_stop_at_their_limits() {
    let mut bomb =
        String::from("<scene version=\"3.0.0\">\n<default name=\"p0\" value=\"xxxxxxxxxx\"/>\n");
    for i in 1..12 {
        bomb += &format!(
            "<default name=\"p{i}\" value=\"{}\"/>\n",
            format!("$p{}", i - 1).repeat(10)
        );
    }
    bomb += "<integer name=\"x\" value=\"$p11\"/>\n</scene>\n";
    let e = xml_error(&[("scene.xml", &bomb)]);
    assert!(e.contains("$parameter substitution"), "{e}");

    // 4 includes per file, 12 levels: 16 million files if nothing stopped it.
    let mut files: Vec<(String, String)> = Vec::new();
    for level in 0..12 {
        let body = if level < 11 {
            format!("<include filename=\"l{}.xml\"/>", level + 1).repeat(4)
        } else {
            "<bsdf type=\"diffuse\"/>".to_string()
        };
        files.push((
            format!("l{level}.xml"),
            format!("<scene version=\"3.0.0\">{body}</scene>"),
        ));
    }
    let refs: Vec<(&str, &str)> = files
        .iter()
        .map(|(a, b)| (a.as_str(), b.as_str()))
        .collect();
    let start = std::time::Instant::now();
    let e = xml_error(&refs);
    assert!(e.contains("<include>d files"), "{e}");
    assert!(start.elapsed().as_secs() < 20);
}

#[test]
fn mitsuba_files_newer_than_version_3_are_refused() {
    let e = xml_error(&[("scene.xml", "<scene version=\"99.0.0\">\n</scene>\n")]);
    assert!(e.contains("scene.xml:1") && e.contains("99.0.0"), "{e}");
}

fn mesh_error(name: &str, contents: &[u8]) -> String {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join(name), contents).unwrap();
    let shape = if name.ends_with(".ply") { "ply" } else { "obj" };
    let scene = TOML_SCENE.replace(
        "shape = \"sphere\"\nradius = 1",
        &format!("shape = \"{shape}\"\nfile = \"{name}\""),
    );
    error(&write(d.path(), "s.toml", &scene))
}

#[test]
fn ply_headers_are_validated_before_the_parser_allocates_or_panics() {
    let head = "ply\nformat ascii 1.0\n";
    let xyz = "property float x\nproperty float y\nproperty float z\n";
    // A count beyond u64 (ply-rs unwrapped it).
    let e = mesh_error(
        "m.ply",
        format!("{head}element vertex 100000000000000000000\n{xyz}end_header\n").as_bytes(),
    );
    assert!(
        e.contains("m.ply:3") && e.contains("100000000000000000000"),
        "{e}"
    );
    // An element without properties and a count of 10^12 (one record each, nothing read).
    let e = mesh_error(
        "m.ply",
        format!("{head}element vertex 3\n{xyz}element junk 1000000000000\nend_header\n").as_bytes(),
    );
    assert!(e.contains("m.ply:7") && e.contains("junk"), "{e}");
    let e = mesh_error(
        "m.ply",
        format!("{head}element vertex 3\n{xyz}element junk 100\nend_header\n0 0 0\n1 0 0\n0 1 0\n")
            .as_bytes(),
    );
    assert!(e.contains("no properties"), "{e}");
    // More elements than the file has bytes for.
    let e = mesh_error(
        "m.ply",
        format!(
            "ply\nformat binary_little_endian 1.0\nelement vertex 200000000\n{xyz}end_header\n"
        )
        .as_bytes(),
    );
    assert!(e.contains("more than the"), "{e}");
    // A version number that does not fit.
    let e = mesh_error(
        "m.ply",
        b"ply\nformat ascii 99999999999999999999.0\nend_header\n",
    );
    assert!(e.contains("m.ply:2"), "{e}");
    // A bad data line: the line, in plain words, without the parser's Debug dump.
    let e = mesh_error(
        "m.ply",
        format!("{head}element vertex 3\n{xyz}element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 x\n3 0 1 2\n").as_bytes(),
    );
    assert!(e.contains("m.ply:12"), "{e}");
    for dump in ["Couln't", "Error:", "String:", "ParseError"] {
        assert!(!e.contains(dump), "`{dump}` in: {e}");
    }
}

#[test]
fn obj_faces_with_texture_indices_but_no_texture_coordinates_are_refused() {
    let e = mesh_error("m.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/2 3/3\n");
    assert!(e.contains("m.obj:4") && e.contains("`vt`"), "{e}");
    let e = mesh_error("m.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n");
    assert!(e.contains("`vn`"), "{e}");
}

#[test]
fn objects_and_cameras_beyond_the_coordinate_limit_are_refused() {
    // A rectangle scaled by 1e300 has an infinite area: its emission rendered 0.007
    // instead of 1 before this limit.
    let e = toml_error(&TOML_SCENE.replace(
        "[[lights]]",
        "[[objects]]\nshape = \"rectangle\"\ntransform = [{scale = 1e300}]\nemission = 1\nmaterial = { type = \"lambert\" }\n\n[[lights]]",
    ));
    assert!(
        e.contains("s.toml:") && e.contains("coordinate limit 1e30"),
        "{e}"
    );
    let e = toml_error(&TOML_SCENE.replace("radius = 1", "radius = 1e308"));
    assert!(e.contains("`radius`") && e.contains("1e30"), "{e}");
    let e = toml_error(&TOML_SCENE.replace("position = [0, 0, 4]", "position = [0, 0, 1e200]"));
    assert!(e.contains("look_at origin") && e.contains("±1e30"), "{e}");
    // Within the limit, a huge emitter still renders its emission.
    let ok = toml_error_or_ok(&TOML_SCENE.replace(
        "[[lights]]",
        "[[objects]]\nshape = \"rectangle\"\ntransform = [{scale = 1e29}]\nemission = 1\nmaterial = { type = \"lambert\" }\n\n[[lights]]",
    ));
    assert!(ok.is_none(), "{ok:?}");
}

fn toml_error_or_ok(text: &str) -> Option<String> {
    let d = tempfile::tempdir().unwrap();
    let p = write(d.path(), "s.toml", text);
    load_scene(&p).err().map(|e| e.to_string())
}

#[test]
fn adaptive_quadrature_in_a_scene_is_warned_about() {
    let d = tempfile::tempdir().unwrap();
    let text = TOML_SCENE.replace(
        "material = { type = \"lambert\", reflectance = 0.5 }",
        "material = { type = \"il\", ni = 1.5, distribution = \"beckmann\", alpha = 0.3, evaluation = \"quadrature\" }",
    );
    let scene = load_scene(&write(d.path(), "s.toml", &text)).unwrap();
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    assert!(
        scene.warnings[0].contains("samples = N"),
        "{:?}",
        scene.warnings
    );
    // The fixed set and the stochastic estimate are what renders use: no warning.
    for ev in [
        "evaluation = \"quadrature\", samples = 64",
        "evaluation = \"stochastic\"",
    ] {
        let text = TOML_SCENE.replace(
            "material = { type = \"lambert\", reflectance = 0.5 }",
            &format!("material = {{ type = \"il\", ni = 1.5, distribution = \"beckmann\", alpha = 0.3, {ev} }}"),
        );
        let scene = load_scene(&write(d.path(), "s.toml", &text)).unwrap();
        assert!(scene.warnings.is_empty(), "{ev}: {:?}", scene.warnings);
    }
}
