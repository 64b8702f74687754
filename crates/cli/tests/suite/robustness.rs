//! Hostile and careless command lines (issue 17): each example of the issue gives a clear
//! error naming the culprit and a non-zero exit — no panic, no allocation abort, no
//! infinite pixel, no clobbered output — or, for a valid extreme, a finite result.

use crate::common::*;
use facette_bsdf::storage::framed::Framed;
use std::path::Path;
use std::process::{Command, Output, Stdio};

const SCENE: &str = r#"
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

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A failure that is an error message, not a panic or a signal.
fn assert_clean_error(o: &Output, culprit: &str) {
    let err = stderr(o);
    assert!(
        matches!(o.status.code(), Some(1) | Some(2)),
        "exit {:?}: {err}",
        o.status
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains(culprit), "expected `{culprit}` in: {err}");
}

fn scene_file(dir: &Path, text: &str) -> std::path::PathBuf {
    let p = dir.join("scene.toml");
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn render_flags_beyond_their_limits_are_errors_and_write_nothing() {
    let d = tempfile::tempdir().unwrap();
    let scene = scene_file(d.path(), SCENE);
    let out = d.path().join("x.exr");
    for (flag, value, culprit) in [
        ("--spp", "18446744073709551615", "--spp"),
        ("--time-limit", "1e308", "--time-limit"),
        ("--exposure", "5000", "--exposure"),
        ("--threads", "100000000", "--threads"),
    ] {
        let o = facette(&["render", s(&scene), "-o", s(&out), flag, value], None);
        assert_clean_error(&o, culprit);
        assert!(!out.exists(), "{flag} {value}");
    }
    // A product that overflows: a valid film and spp whose product is out of bounds.
    let big = scene_file(
        d.path(),
        &SCENE
            .replace("width = 8", "width = 5000")
            .replace("height = 6", "height = 5000"),
    );
    let o = facette(
        &["render", s(&big), "-o", s(&out), "--spp", "16777216"],
        None,
    );
    assert_clean_error(&o, "camera samples");
}

#[test]
fn scene_exposure_and_film_size_the_docs_allowed_are_errors() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("x.exr");
    let exposure = scene_file(
        d.path(),
        &SCENE.replace("spp = 2", "spp = 2\nexposure = 2000"),
    );
    assert_clean_error(
        &facette(&["render", s(&exposure), "-o", s(&out)], None),
        "`exposure`",
    );
    let film = scene_file(
        d.path(),
        &SCENE
            .replace("width = 8", "width = 65536")
            .replace("height = 6", "height = 65536"),
    );
    assert_clean_error(
        &facette(&["render", s(&film), "-o", s(&out)], None),
        "film pixels",
    );
    assert!(!out.exists());
}

#[test]
fn a_second_interrupt_while_rendering_writes_nothing_and_leaves_no_temporary_file() {
    let d = tempfile::tempdir().unwrap();
    let scene = scene_file(
        d.path(),
        &SCENE
            .replace("width = 8", "width = 64")
            .replace("height = 6", "height = 64"),
    );
    let out = d.path().join("twice.exr");
    let child = Command::new(env!("CARGO_BIN_EXE_facette"))
        .args(["render", s(&scene), "-o", s(&out), "--spp", "1000000"])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1000));
    for _ in 0..2 {
        let killed = Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let o = child.wait_with_output().unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(130), "{err}");
    // Either the second signal came while rendering (nothing written) or during the write
    // (the write completes): never a message that contradicts the file.
    let entries: Vec<String> = std::fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        entries.iter().all(|n| !n.contains("tmp")),
        "temporary file left: {entries:?}"
    );
    if err.contains("exiting without writing") {
        assert!(!out.exists(), "{err}");
    } else {
        assert!(out.exists(), "{err}");
    }
}

#[test]
fn lab_counts_out_of_range_are_usage_errors() {
    let d = tempfile::tempdir().unwrap();
    let o = facette(&["il-approx", "accuracy", "--samples", "0"], None);
    assert_clean_error(&o, "--samples");
    let p = d.path().join("p.svg");
    let o = facette(
        &[
            "plot",
            "slice",
            "--material",
            "{type = \"lambert\"}",
            "--points",
            "1000000000",
            "-o",
            s(&p),
        ],
        None,
    );
    assert_clean_error(&o, "--points");
    let t = d.path().join("t.fctab");
    let o = facette(
        &[
            "tabulate",
            "--material",
            "{type = \"il\", ni = 1.2, distribution = \"gaussian\", sigma = 0.3}",
            "--step",
            "0.01",
            "-o",
            s(&t),
        ],
        None,
    );
    assert_clean_error(&o, "table entries");
    assert!(!p.exists() && !t.exists());
}

#[test]
fn plot_checks_every_output_before_writing_any() {
    let d = tempfile::tempdir().unwrap();
    let svg = d.path().join("p.svg");
    std::fs::write(&svg, "previous").unwrap();
    let csv = d.path().join("no/dir/p.csv");
    let o = facette(
        &[
            "plot",
            "slice",
            "--material",
            "{type = \"lambert\"}",
            "-o",
            s(&svg),
            "--csv",
            s(&csv),
        ],
        None,
    );
    assert_clean_error(&o, "--csv");
    assert_eq!(std::fs::read_to_string(&svg).unwrap(), "previous");
}

#[test]
fn a_random_file_given_as_merl_is_refused_before_its_dimensions_are_multiplied() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("random.binary");
    // Fixed pseudo-random bytes (an LCG), 35 MB as in the issue.
    let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
    let bytes: Vec<u8> = (0..35_000_000)
        .map(|_| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 56) as u8
        })
        .collect();
    std::fs::write(&f, &bytes).unwrap();
    assert_clean_error(&facette(&["fit", s(&f)], None), "random.binary");
    // The header alone, with dimensions whose product overflows.
    let mut header = Vec::new();
    for d in [i32::MAX, i32::MAX, 3] {
        header.extend_from_slice(&d.to_le_bytes());
    }
    std::fs::write(&f, &header).unwrap();
    assert_clean_error(&facette(&["fit", s(&f)], None), "dimensions");
}

#[test]
fn material_errors_name_the_key_the_user_wrote() {
    let eval = |m: &str| facette(&["eval", "--material", m], Some("10,0,20,0\n"));
    let o = eval("{type = \"conductor\", distribution = \"ggx\", alpha_u = 0, alpha_v = 0.1}");
    assert_clean_error(&o, "`alpha_u`");
    let o = eval("{type = \"conductor\", distribution = \"ggx\", alpha_u = 0.1, alpha_v = 20}");
    assert_clean_error(&o, "`alpha_v`");
    let o = eval("{type = \"dielectric\", alpha = 0.1, ior = 0.0001, ext_ior = 50}");
    assert_clean_error(&o, "ior / ext_ior");
    assert!(!stderr(&o).contains("`eta`"), "{}", stderr(&o));
    let o = eval("{type = \"kelemen\", distribution = \"x\", kd = 0.5}");
    assert_clean_error(&o, "unknown distribution `x`");
    // A valid extreme gives a finite result.
    let o = eval("{type = \"kelemen\", alpha = 1e-320}");
    assert!(o.status.success(), "{}", stderr(&o));
    let r = rows(&o);
    assert!(r[0][4..].iter().all(|v| v.is_finite()), "{:?}", r);
}

/// Renders the two parts of `SCENE` into `dir`; returns their paths.
fn two_parts(dir: &Path) -> Vec<std::path::PathBuf> {
    let scene = scene_file(dir, SCENE);
    (0..2)
        .map(|k| {
            let p = dir.join(format!("p{k}.fcpart"));
            let part = format!("{k}/2");
            let o = facette(&["render", s(&scene), "--part", &part, "-o", s(&p)], None);
            assert!(o.status.success(), "{}", stderr(&o));
            p
        })
        .collect()
}

/// A part file with `edit` applied to its payload and a valid checksum again: the
/// corruption a CRC cannot catch (a bug, or a hand-made file).
fn corrupt(path: &Path, edit: impl Fn(&mut Vec<u8>)) {
    const FRAME: Framed = Framed {
        magic: b"FCRPART1",
        version: 3,
        legacy_version: Some(2),
        what: "facette partial render",
    };
    let bytes = std::fs::read(path).unwrap();
    let mut payload = FRAME.unframe(&bytes).unwrap().payload.to_vec();
    edit(&mut payload);
    std::fs::write(path, FRAME.frame(&payload)).unwrap();
}

#[test]
fn merge_refuses_corrupt_part_headers_without_overflow_or_huge_allocations() {
    // Payload offsets: hash 0, seed 8, part 16, parts 20, spp 24, sampler 28, width 32,
    // height 36, exposure 40, discarded 48, pixels from 56 (sums, squares, count).
    let cases: [(&str, usize, Vec<u8>); 4] = [
        (
            "parts of a distributed job",
            20,
            4_000_000_000u32.to_le_bytes().to_vec(),
        ),
        ("exposure", 40, f64::NAN.to_le_bytes().to_vec()),
        (
            "more than the render's",
            56 + 48,
            u32::MAX.to_le_bytes().to_vec(),
        ),
        ("invalid image size", 32, 70_000u32.to_le_bytes().to_vec()),
    ];
    for (culprit, at, value) in cases {
        let d = tempfile::tempdir().unwrap();
        let parts = two_parts(d.path());
        corrupt(&parts[1], |p| {
            p[at..at + value.len()].copy_from_slice(&value)
        });
        let out = d.path().join("merged.exr");
        let o = facette(&["merge", s(&parts[0]), s(&parts[1]), "-o", s(&out)], None);
        assert_clean_error(&o, culprit);
        assert!(!out.exists());
    }
    // Sums that are finite in each part but overflow when added.
    let d = tempfile::tempdir().unwrap();
    let parts = two_parts(d.path());
    for p in &parts {
        corrupt(p, |b| b[56..64].copy_from_slice(&1.7e308f64.to_le_bytes()));
    }
    let out = d.path().join("merged.exr");
    let o = facette(&["merge", s(&parts[0]), s(&parts[1]), "-o", s(&out)], None);
    assert_clean_error(&o, "corrupt parts");
    assert!(!out.exists());
}

#[test]
fn every_command_checks_its_outputs_before_working() {
    let d = tempfile::tempdir().unwrap();
    let scene = scene_file(d.path(), SCENE);
    let missing = d.path().join("no/dir");
    let out = |name: &str| missing.join(name).to_str().unwrap().to_string();
    let a_file = d.path().join("a-file");
    std::fs::write(&a_file, "keep").unwrap();
    let il = "{type = \"il\", ni = 1.5, distribution = \"beckmann\", alpha = 0.3}";
    let cases: Vec<Vec<String>> = vec![
        vec!["render".into(), s(&scene).into(), "-o".into(), out("x.exr")],
        vec![
            "render".into(),
            s(&scene).into(),
            "--part".into(),
            "0/2".into(),
            "-o".into(),
            out("x.fcpart"),
        ],
        vec![
            "measure".into(),
            "--material".into(),
            "{type = \"lambert\"}".into(),
            "-o".into(),
            out("m.binary"),
        ],
        vec![
            "normalmap".into(),
            "generate".into(),
            "scratched".into(),
            "--resolution".into(),
            "64".into(),
            "-o".into(),
            out("n.exr"),
        ],
        vec![
            "tabulate".into(),
            "--material".into(),
            il.into(),
            "-o".into(),
            out("t.fctab"),
        ],
        vec!["il-approx".into(), "fit".into(), "-o".into(), out("c.rs")],
        vec![
            "fit".into(),
            s(&a_file).into(),
            "--model".into(),
            "plastic".into(),
            "-o".into(),
            out("f.svg"),
        ],
        vec!["merge".into(), s(&a_file).into(), "-o".into(), out("m.exr")],
        vec![
            "reproduce".into(),
            "il18-fig7".into(),
            "--quick".into(),
            "-o".into(),
            s(&a_file).into(),
        ],
    ];
    for args in cases {
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let start = std::time::Instant::now();
        let o = facette(&argv, None);
        let secs = start.elapsed().as_secs_f64();
        assert_clean_error(&o, "-o");
        // Refused before the work: well under the time any of these commands needs.
        assert!(secs < 5.0, "{argv:?} took {secs:.1} s before refusing");
    }
    assert!(!missing.exists());
    assert_eq!(std::fs::read_to_string(&a_file).unwrap(), "keep");
    assert_eq!(
        std::fs::read_dir(d.path()).unwrap().count(),
        2,
        "only the scene and a-file"
    );
}

#[test]
fn limits_are_raised_or_lowered_by_flag_and_variable() {
    let d = tempfile::tempdir().unwrap();
    let o = facette(&["--limit", "list"], None);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("mesh-elements,268435456,4294967295,"),
        "{}",
        stdout(&o)
    );

    // A mesh over a lowered element limit is refused at the line that crossed it.
    let obj = d.path().join("quad.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
    let scene = scene_file(
        d.path(),
        &SCENE.replace(
            "shape = \"sphere\"\nradius = 1",
            "shape = \"obj\"\nfile = \"quad.obj\"",
        ),
    );
    let out = d.path().join("x.exr");
    let o = facette(
        &[
            "render",
            s(&scene),
            "-o",
            s(&out),
            "--limit",
            "mesh-elements=3",
            "--quiet",
        ],
        None,
    );
    assert_clean_error(&o, "quad.obj:4");
    assert!(
        stderr(&o).contains("vertex positions (`v` lines) = 4 exceeds the limit of 3"),
        "{}",
        stderr(&o)
    );
    assert!(
        stderr(&o).contains("--limit mesh-elements=N"),
        "{}",
        stderr(&o)
    );
    let o = facette(&["render", s(&scene), "-o", s(&out), "--quiet"], None);
    assert!(o.status.success(), "{}", stderr(&o));

    // The 8×6 film is refused under a lowered pixel limit, and renders when the flag
    // raises it again.
    let big = scene_file(d.path(), SCENE);
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_facette"));
    cmd.args(["render", s(&big), "-o", s(&out), "--quiet"])
        .env("FACETTE_LIMITS", "film-pixels=40")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let o = cmd.output().unwrap();
    assert_clean_error(&o, "film pixels");
    assert!(
        stderr(&o).contains("--limit film-pixels=N"),
        "{}",
        stderr(&o)
    );
    let o = Command::new(env!("CARGO_BIN_EXE_facette"))
        .args([
            "render",
            s(&big),
            "-o",
            s(&out),
            "--quiet",
            "--limit",
            "film-pixels=48",
        ])
        .env("FACETTE_LIMITS", "film-pixels=40")
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "the flag wins over the variable: {}",
        stderr(&o)
    );

    // Fixed limits, unknown keys and bad values are usage errors naming the culprit.
    for (arg, culprit) in [
        ("xml-depth=1000", "is fixed at 64"),
        ("mesh-element=3", "unknown limit `mesh-element`"),
        ("film-pixels=0", "outside 1…"),
        ("film-pixels", "expected KEY=N"),
    ] {
        let o = facette(&["--limit", arg, "render", s(&scene)], None);
        assert_clean_error(&o, culprit);
    }
    let o = Command::new(env!("CARGO_BIN_EXE_facette"))
        .args(["render", s(&scene), "-o", s(&out)])
        .env("FACETTE_LIMITS", "bogus=1")
        .output()
        .unwrap();
    assert_clean_error(&o, "FACETTE_LIMITS: unknown limit `bogus`");
}

#[test]
fn sky_colours_and_environment_maps_are_held_to_the_radiance_bound() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("x.exr");
    let sky = SCENE.replace(
        "type = \"constant\"\nradiance = 1.0",
        "type = \"environment\"\nsky = { zenith = 1e20, width = 16, height = 8 }",
    );
    let o = facette(
        &["render", s(&scene_file(d.path(), &sky)), "-o", s(&out)],
        None,
    );
    assert_clean_error(&o, "zenith");
    assert!(stderr(&o).contains("1e15"), "{}", stderr(&o));

    let bright = SCENE.replace(
        "type = \"constant\"\nradiance = 1.0",
        "type = \"environment\"\nsky = { zenith = 1e10, width = 16, height = 8 }\nscale = 1e10",
    );
    let o = facette(
        &["render", s(&scene_file(d.path(), &bright)), "-o", s(&out)],
        None,
    );
    assert_clean_error(&o, "scale");
    assert!(!out.exists());
}

/// A 69-byte PNG whose header claims 100000 × 100000 pixels (valid CRCs).
const HUGE_PNG: [u8; 69] = [
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52,
    0x00, 0x01, 0x86, 0xa0, 0x00, 0x01, 0x86, 0xa0, 0x08, 0x02, 0x00, 0x00, 0x00, 0x27, 0x30, 0x9c,
    0x9f, 0x00, 0x00, 0x00, 0x0c, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0x60, 0xa0, 0x3d, 0x00,
    0x00, 0x00, 0x64, 0x00, 0x01, 0x86, 0x64, 0x3c, 0x35, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e,
    0x44, 0xae, 0x42, 0x60, 0x82,
];

#[test]
fn png_headers_are_held_to_the_image_limit_before_decoding() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("huge.png"), HUGE_PNG).unwrap();
    let scene = scene_file(
        d.path(),
        &SCENE.replace(
            "type = \"constant\"\nradiance = 1.0",
            "type = \"environment\"\nfile = \"huge.png\"",
        ),
    );
    let out = d.path().join("x.exr");
    let o = facette(&["render", s(&scene), "-o", s(&out)], None);
    assert_clean_error(&o, "huge.png");
    let e = stderr(&o);
    assert!(
        e.contains("100000 × 100000 = 10000000000 exceeds the limit of 268435456"),
        "{e}"
    );
    assert!(e.contains("--limit image-pixels=N"), "{e}");
    assert!(!out.exists());
}
