//! End-to-end tests of `facette render` and `facette merge`: images and summaries, errors
//! that leave outputs untouched, time limits and interrupts, parts merged exactly, and
//! the sampler flag.

use crate::common::*;
use std::process::{Command, Stdio};

const TINY_SCENE: &str = r#"
[camera]
position = [0, 0, 4]
target = [0, 0, 0]
fov = 40

[film]
width = 24
height = 16
spp = 8

[[objects]]
shape = "sphere"
radius = 1
material = { type = "il", kd = [0.8, 0.4, 0.2], ni = 1.5, alpha = 0.3 }

[[lights]]
type = "point"
position = [2, 2, 3]
intensity = 10

[[lights]]
type = "constant"
radiance = 0.5
"#;

#[test]
fn render_writes_exr_and_png_and_prints_a_summary() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("tiny.toml");
    std::fs::write(&scene, TINY_SCENE).unwrap();
    let exr = dir.path().join("out.exr");
    let o = facette(
        &[
            "render",
            scene.to_str().unwrap(),
            "-o",
            exr.to_str().unwrap(),
            "--seed",
            "3",
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = stderr(&o);
    assert!(
        summary.contains("24×16, 8 spp")
            && summary.contains("Msamples/s")
            && summary.contains("0 discarded"),
        "{summary}"
    );
    let img = facette_render::image::read_image(&exr, facette_render::image::ColorEncoding::Linear)
        .unwrap();
    assert_eq!((img.width(), img.height()), (24, 16));
    assert!(img
        .data()
        .iter()
        .flatten()
        .all(|v| v.is_finite() && *v >= 0.0));
    // Centre pixel: the lit sphere; corner: the 0.5 background.
    assert!(img.get(12, 8)[0] > img.get(12, 8)[2]);
    assert!((img.get(0, 0)[1] - 0.5).abs() < 1e-6);
    // Same seed, same image; PNG by extension; --spp overrides the scene.
    let png = dir.path().join("out.png");
    let o = facette(
        &[
            "render",
            scene.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
            "--spp",
            "2",
            "--threads",
            "1",
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("2 spp"));
    let p = facette_render::image::read_image(&png, facette_render::image::ColorEncoding::Srgb)
        .unwrap();
    assert_eq!((p.width(), p.height()), (24, 16));
    let again = dir.path().join("again.exr");
    let o = facette(
        &[
            "render",
            scene.to_str().unwrap(),
            "-o",
            again.to_str().unwrap(),
            "--seed",
            "3",
            "--threads",
            "1",
        ],
        None,
    );
    assert!(o.status.success());
    let img2 =
        facette_render::image::read_image(&again, facette_render::image::ColorEncoding::Linear)
            .unwrap();
    assert_eq!(
        img.data(),
        img2.data(),
        "same seed, different thread count: different image"
    );
}

#[test]
fn render_errors_leave_existing_outputs_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("keep.png");
    std::fs::write(&out, b"previous render").unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, TINY_SCENE.replace("alpha = 0.3", "alpha = -0.3")).unwrap();
    let o = facette(
        &["render", bad.to_str().unwrap(), "-o", out.to_str().unwrap()],
        None,
    );
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(e.contains("bad.toml:15:") && e.contains("alpha"), "{e}");
    assert!(!e.contains("panicked"), "{e}");
    assert_eq!(std::fs::read(&out).unwrap(), b"previous render");
    // Unsupported output extension, missing directory, missing scene: errors before rendering.
    let good = dir.path().join("good.toml");
    std::fs::write(&good, TINY_SCENE).unwrap();
    let o = facette(&["render", good.to_str().unwrap(), "-o", "x.jpg"], None);
    assert!(
        stderr(&o).contains("unsupported image extension `.jpg`; valid: .exr, .png"),
        "{}",
        stderr(&o)
    );
    let o = facette(
        &[
            "render",
            good.to_str().unwrap(),
            "-o",
            dir.path().join("no/such/dir.exr").to_str().unwrap(),
        ],
        None,
    );
    assert!(stderr(&o).contains("does not exist"), "{}", stderr(&o));
    let o = facette(
        &[
            "render",
            dir.path().join("none.toml").to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        None,
    );
    assert!(
        stderr(&o).contains("cannot read the scene file"),
        "{}",
        stderr(&o)
    );
    assert_eq!(std::fs::read(&out).unwrap(), b"previous render");
}

#[test]
fn render_time_limit_and_interrupt_write_the_image_so_far() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("slow.toml");
    std::fs::write(
        &scene,
        TINY_SCENE
            .replace("width = 24", "width = 96")
            .replace("height = 16", "height = 64"),
    )
    .unwrap();
    let out = dir.path().join("limited.exr");
    let start = std::time::Instant::now();
    let o = facette(
        &[
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--spp",
            "1000000",
            "--time-limit",
            "1",
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(start.elapsed().as_secs_f64() < 30.0);
    assert!(stderr(&o).contains("interrupted"), "{}", stderr(&o));
    let img = facette_render::image::read_image(&out, facette_render::image::ColorEncoding::Linear)
        .unwrap();
    assert!(img.data().iter().flatten().all(|v| v.is_finite()));
    assert!(
        img.data().iter().all(|p| p[1] > 0.0),
        "every pixel has samples"
    );

    // SIGINT: the render stops, writes what it has and exits with 130.
    let out = dir.path().join("interrupted.exr");
    let child = Command::new(env!("CARGO_BIN_EXE_facette"))
        .args([
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--spp",
            "1000000",
        ])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    assert!(stderr(&o).contains("interrupted"), "{}", stderr(&o));
    let img = facette_render::image::read_image(&out, facette_render::image::ColorEncoding::Linear)
        .unwrap();
    assert_eq!((img.width(), img.height()), (96, 64));
    assert!(img.data().iter().flatten().all(|v| v.is_finite()));
}

#[test]
fn render_parts_merge_exactly_and_bad_sets_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("tiny.toml");
    std::fs::write(&scene, TINY_SCENE).unwrap();
    let s = scene.to_str().unwrap();
    let part = |k: u32, n: u32, seed: &str| {
        let out = dir.path().join(format!("p{k}of{n}s{seed}.fcpart"));
        let o = facette(
            &[
                "render",
                s,
                "--part",
                &format!("{k}/{n}"),
                "--seed",
                seed,
                "-o",
                out.to_str().unwrap(),
            ],
            None,
        );
        assert!(o.status.success(), "{}", stderr(&o));
        out.to_str().unwrap().to_string()
    };
    let parts: Vec<String> = (0..3).rev().map(|k| part(k, 3, "9")).collect();
    let merged = dir.path().join("merged.exr");
    let mut args = vec!["merge"];
    args.extend(parts.iter().map(|p| p.as_str()));
    args.extend(["-o", merged.to_str().unwrap()]);
    let o = facette(&args, None);
    assert!(o.status.success(), "{}", stderr(&o));
    // The same three parts rendered in one process.
    let sc = facette_render::scene::load_scene(&scene).unwrap();
    let opts = facette_render::render::RenderOptions {
        seed: 9,
        ..Default::default()
    };
    let film = facette_render::partial_film::render_in_parts(&sc, &opts, 3).unwrap();
    let got =
        facette_render::image::read_image(&merged, facette_render::image::ColorEncoding::Linear)
            .unwrap();
    assert_eq!(
        got.data(),
        film.image().data(),
        "merged parts differ from the in-process render"
    );
    // Statistically the same as a plain render with many more samples.
    let plain = facette_render::render::render(
        &sc,
        &facette_render::render::RenderOptions {
            spp: Some(96),
            seed: 1,
            ..Default::default()
        },
        &std::sync::atomic::AtomicBool::new(false),
        &|_, _| {},
    )
    .unwrap()
    .0;
    let (a, ea) = film.block_mean(0, 0, 24, 16);
    let (b, eb) = plain.block_mean(0, 0, 24, 16);
    for c in 0..3 {
        assert!(
            (a[c] - b[c]).abs() < 4.0 * (ea[c].hypot(eb[c])) + 1e-9,
            "{a:?} ± {ea:?} vs {b:?} ± {eb:?}"
        );
    }
    // Refused: a missing part, a duplicate, another seed, another scene, another N.
    let bad = |list: Vec<String>, what: &str| {
        let mut args = vec!["merge".to_string()];
        args.extend(list);
        args.extend([
            "-o".into(),
            dir.path().join("bad.exr").to_str().unwrap().into(),
        ]);
        let args: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
        let o = facette(&args, None);
        assert_eq!(o.status.code(), Some(1));
        assert!(
            stderr(&o).contains(what),
            "expected `{what}` in: {}",
            stderr(&o)
        );
    };
    bad(parts[..2].to_vec(), "missing part(s)");
    bad(
        vec![parts[0].clone(), parts[0].clone(), parts[1].clone()],
        "given twice",
    );
    bad(
        vec![parts[0].clone(), parts[1].clone(), part(0, 3, "10")],
        "the seed",
    );
    bad(vec![parts[0].clone(), part(1, 4, "9")], "the part count");
    let other_sampler = dir.path().join("p0of3independent.fcpart");
    let o = facette(
        &[
            "render",
            s,
            "--part",
            "0/3",
            "--seed",
            "9",
            "--sampler",
            "independent",
            "-o",
            other_sampler.to_str().unwrap(),
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    bad(
        vec![
            parts[0].clone(),
            parts[1].clone(),
            other_sampler.to_str().unwrap().into(),
        ],
        "the sampler is sobol in the first part and independent",
    );
    std::fs::write(
        &scene,
        TINY_SCENE.replace("intensity = 10", "intensity = 11"),
    )
    .unwrap();
    let other = part(0, 3, "9");
    bad(vec![parts[0].clone(), parts[1].clone(), other], "the scene");
    std::fs::write(dir.path().join("junk.fcpart"), b"FCRPART1 and garbage").unwrap();
    bad(
        vec![dir.path().join("junk.fcpart").to_str().unwrap().into()],
        "junk.fcpart",
    );
    assert!(!dir.path().join("bad.exr").exists());
}

#[test]
fn render_sampler_flag_overrides_the_scene_and_lists_the_valid_names() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("tiny.toml");
    std::fs::write(&scene, TINY_SCENE).unwrap();
    let s = scene.to_str().unwrap();
    let render = |sampler: &str| {
        let out = dir.path().join(format!("{sampler}.exr"));
        let o = facette(
            &[
                "render",
                s,
                "--sampler",
                sampler,
                "-q",
                "-o",
                out.to_str().unwrap(),
            ],
            None,
        );
        (o, out)
    };
    let mut images = Vec::new();
    for name in ["sobol", "independent", "stratified"] {
        let (o, out) = render(name);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let img =
            facette_render::image::read_image(&out, facette_render::image::ColorEncoding::Linear)
                .unwrap();
        assert!(img
            .data()
            .iter()
            .flatten()
            .all(|v| v.is_finite() && *v >= 0.0));
        images.push(img);
    }
    assert_ne!(images[0].data(), images[1].data(), "sobol = independent");
    assert_ne!(
        images[1].data(),
        images[2].data(),
        "independent = stratified"
    );
    let (o, out) = render("halton");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("unknown sampler `halton`; valid: sobol, independent, stratified"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
}
