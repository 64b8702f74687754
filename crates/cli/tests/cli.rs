//! End-to-end tests of the `facette` command line.

use std::io::Write;
use std::process::{Command, Output, Stdio};

fn facette(args: &[&str], stdin: Option<&str>) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_facette"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("facette runs");
    if let Some(s) = stdin {
        // The process may exit before reading (on a bad argument): ignore a broken pipe.
        let _ = child.stdin.take().unwrap().write_all(s.as_bytes());
    } else {
        drop(child.stdin.take());
    }
    child.wait_with_output().unwrap()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The numeric columns of the data rows of a CSV output.
fn rows(o: &Output) -> Vec<Vec<f64>> {
    stdout(o)
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect()
}

#[test]
fn eval_lambert_is_kd_over_pi() {
    let o = facette(
        &[
            "eval",
            "--material",
            r#"{type = "lambert", reflectance = [0.2, 0.4, 0.6]}"#,
        ],
        Some("theta_i,phi_i,theta_o,phi_o\n30,0,60,120\n0,0,89,0\n"),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let r = rows(&o);
    assert_eq!(r.len(), 2);
    for row in &r {
        for (c, kd) in [0.2, 0.4, 0.6].iter().enumerate() {
            assert!(
                (row[4 + c] - kd / std::f64::consts::PI).abs() < 1e-9,
                "{row:?}"
            );
        }
    }
    // Directions on opposite sides: zero for a BRDF.
    let o = facette(
        &["eval", "--material", r#"{type = "lambert"}"#],
        Some("30,0,120,0\n"),
    );
    assert_eq!(rows(&o)[0][4], 0.0);
}

#[test]
fn eval_reads_a_file_and_reports_bad_rows_with_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("dirs.csv");
    std::fs::write(&p, "# comment\n30,0,30,180\n10,0,abc,0\n").unwrap();
    let o = facette(
        &[
            "eval",
            "--material",
            r#"{type = "conductor", alpha = 0.2}"#,
            "--input",
            p.to_str().unwrap(),
        ],
        None,
    );
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("dirs.csv:3") && e.contains("not a finite number"),
        "{e}"
    );
    let o = facette(
        &[
            "eval",
            "--material",
            r#"{type = "lambert"}"#,
            "--input",
            "/nonexistent.csv",
        ],
        None,
    );
    assert!(!o.status.success() && stderr(&o).contains("cannot open"));
}

#[test]
fn eval_dielectric_matches_walter_and_is_reciprocal_in_the_generalized_sense() {
    let m = r#"{type = "dielectric", distribution = "ggx", alpha = 0.3, ior = 1.5}"#;
    // f_t(i,o)/η_o² = f_t(o,i)/η_i²: i outside (η = 1), o inside (η = 1.5).
    let o = facette(
        &["eval", "--material", m],
        Some("30,0,160,180\n160,180,30,0\n"),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let r = rows(&o);
    let (f_io, f_oi) = (r[0][4], r[1][4]);
    assert!(f_io > 0.0);
    assert!(
        (f_io / (1.5 * 1.5) - f_oi).abs() < 1e-9 * f_io,
        "{f_io} {f_oi}"
    );
}

#[test]
fn stochastic_models_print_a_converged_estimate_and_say_so() {
    let o = facette(
        &[
            "eval",
            "--material",
            r#"{type = "oren-nayar", sigma = 0.4, evaluation = "stochastic"}"#,
            "--samples",
            "200000",
        ],
        Some("30,0,40,90\n"),
    );
    assert!(o.status.success());
    assert!(stderr(&o).contains("averages 200000"));
    let v = rows(&o)[0][4];
    // The quadrature mode gives the same value.
    let q = facette(
        &[
            "eval",
            "--material",
            r#"{type = "oren-nayar", sigma = 0.4, samples = 65536}"#,
        ],
        Some("30,0,40,90\n"),
    );
    let w = rows(&q)[0][4];
    assert!((v - w).abs() < 0.01 * w, "{v} vs {w}");
}

#[test]
fn albedo_of_the_smooth_dielectric_is_fresnel() {
    let o = facette(
        &[
            "albedo",
            "--material",
            r#"{type = "dielectric", alpha = 0, ior = 1.5}"#,
            "--theta-i",
            "0",
            "60",
            "--samples",
            "400000",
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let r = rows(&o);
    for (row, deg) in r.iter().zip([0.0f64, 60.0]) {
        let f = facette_fresnel(deg.to_radians().cos(), 1.5);
        let (refl, se) = (row[1], row[4]);
        assert!(
            (refl - f).abs() < 4.0 * se + 1e-9,
            "{deg}: {refl} ± {se} vs {f}"
        );
        assert!(
            (row[1] + row[7] - 1.0).abs() < 1e-9,
            "R + T = 1 for a lossless interface"
        );
    }
}

/// Fresnel for the test's expected values (unpolarized, s/p amplitudes).
fn facette_fresnel(c: f64, eta: f64) -> f64 {
    let s2 = (1.0 - c * c) / (eta * eta);
    let ct = (1.0 - s2).sqrt();
    let rs = (c - eta * ct) / (c + eta * ct);
    let rp = (eta * c - ct) / (eta * c + ct);
    0.5 * (rs * rs + rp * rp)
}

#[test]
fn albedo_of_white_lambert_is_one() {
    let o = facette(
        &[
            "albedo",
            "--material",
            r#"{type = "lambert", reflectance = 1}"#,
            "--theta-i",
            "45",
        ],
        None,
    );
    let r = rows(&o);
    assert!((r[0][1] - 1.0).abs() < 1e-12 && r[0][7] == 0.0);
}

#[test]
fn validate_material_passes_and_prints_a_summary() {
    let o = facette(
        &[
            "validate",
            "--material",
            r#"{type = "conductor", distribution = "ggx", alpha_u = 0.1, alpha_v = 0.3}"#,
            "--samples",
            "100000",
        ],
        None,
    );
    let out = stdout(&o);
    assert!(o.status.success(), "{out}");
    let last = out.lines().last().unwrap();
    assert!(last.contains("passed, 0 failed"), "{last}");
    assert!(out.contains("[PASS]") && out.contains("chi-square") && out.contains("reciprocity"));
}

#[test]
fn multiple_scattering_and_compensation_restore_the_white_furnace() {
    // The same spec everywhere: albedo of a white rough conductor, single scattering vs the
    // random walk vs the compensation; eval of the walk is a stochastic estimate.
    let albedo = |m: &str| {
        let o = facette(
            &[
                "albedo",
                "--material",
                m,
                "--theta-i",
                "0",
                "70",
                "--samples",
                "40000",
            ],
            None,
        );
        assert!(o.status.success(), "{}", stderr(&o));
        rows(&o)
    };
    let single = albedo(
        r#"{type = "conductor", distribution = "ggx", alpha = 1, masking = "smith-correlated"}"#,
    );
    let multiple =
        albedo(r#"{type = "conductor", distribution = "ggx", alpha = 1, scattering = "multiple"}"#);
    let compensated = albedo(
        r#"{type = "conductor", distribution = "ggx", alpha = 1, masking = "smith-correlated", energy = "compensated"}"#,
    );
    for k in 0..2 {
        assert!(
            single[k][1] < 0.85,
            "single scattering loses energy: {:?}",
            single[k]
        );
        assert!((multiple[k][1] - 1.0).abs() < 1e-3, "{:?}", multiple[k]);
        assert!(
            (compensated[k][1] - 1.0).abs() < 4.0 * compensated[k][4] + 3e-3,
            "{:?}",
            compensated[k]
        );
    }
    let o = facette(
        &[
            "eval",
            "--material",
            r#"{type = "dielectric", distribution = "ggx", alpha = 0.7, scattering = "multiple"}"#,
            "--samples",
            "20000",
        ],
        Some("30,0,40,90\n30,0,150,180\n"),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("stochastically"), "{}", stderr(&o));
    let r = rows(&o);
    assert!(
        r.iter().all(|row| row[4] > 0.0 && row[4].is_finite()),
        "{r:?}"
    );
    // Bad values list the valid ones and exit non-zero.
    let o = facette(
        &[
            "eval",
            "--material",
            r#"{type = "conductor", alpha = 1, scattering = "many"}"#,
        ],
        Some("30,0,40,90\n"),
    );
    assert!(!o.status.success());
    assert!(stderr(&o).contains("single, multiple"), "{}", stderr(&o));
}

#[test]
fn validate_material_runs_the_random_walk_checks() {
    let o = facette(
        &[
            "validate",
            "--material",
            r#"{type = "conductor", distribution = "ggx", alpha = 0.8, scattering = "multiple"}"#,
            "--samples",
            "50000",
        ],
        None,
    );
    let out = stdout(&o);
    assert!(o.status.success(), "{out}");
    assert!(
        out.contains("random-walk sampler") && out.contains("stochastic model"),
        "{out}"
    );
    assert!(out.lines().last().unwrap().contains(" 0 failed"), "{out}");
}

#[test]
fn validate_distribution_and_family() {
    let o = facette(
        &[
            "validate",
            "--distribution",
            r#"{distribution = "beckmann", alpha = 0.2}"#,
            "--samples",
            "100000",
        ],
        None,
    );
    assert!(o.status.success(), "{}", stdout(&o));
    assert!(stdout(&o).contains("analytic Smith Λ vs numerical IL18 eq. 19"));
}

#[test]
fn bad_materials_are_clear_errors_with_nonzero_exit() {
    for (m, needle) in [
        (
            r#"{type = "glass"}"#,
            "lambert, oren-nayar, conductor, dielectric, kelemen",
        ),
        (
            r#"{type = "conductor", alpha = 0.2, roughness = 1}"#,
            "unknown key `roughness`",
        ),
        (
            r#"{type = "conductor", alpha = -1}"#,
            "`alpha` = -1 is out of range",
        ),
        (
            r#"{type = "dielectric", alpha = 0.1, ior = nan}"#,
            "must be a finite number",
        ),
        (
            r#"{type = "conductor", distribution = "gaussian", sigma = 0.2, masking = "smith"}"#,
            "diverges",
        ),
        (r#"{type = "lambert""#, "not a TOML inline table"),
    ] {
        let o = facette(&["eval", "--material", m], Some("0,0,0,0\n"));
        assert_eq!(o.status.code(), Some(1), "{m}");
        assert!(stderr(&o).contains(needle), "{m}: {}", stderr(&o));
    }
}

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

#[test]
fn table_parts_merge_into_the_same_table_file() {
    let dir = tempfile::tempdir().unwrap();
    let m = r#"{type = "il", ni = 1.4, distribution = "beckmann", alpha = 0.5}"#;
    let full = dir.path().join("full.fctab");
    let o = facette(
        &[
            "tabulate",
            "--material",
            m,
            "--step",
            "10",
            "--samples",
            "256",
            "-o",
            full.to_str().unwrap(),
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let mut parts = Vec::new();
    for k in 0..4 {
        let p = dir.path().join(format!("t{k}.fctpart"));
        let o = facette(
            &[
                "tabulate",
                "--material",
                m,
                "--step",
                "10",
                "--samples",
                "256",
                "--part",
                &format!("{k}/4"),
                "-o",
                p.to_str().unwrap(),
            ],
            None,
        );
        assert!(o.status.success(), "{}", stderr(&o));
        parts.push(p.to_str().unwrap().to_string());
    }
    let merged = dir.path().join("merged.fctab");
    let mut args = vec!["merge"];
    args.extend(parts.iter().map(|p| p.as_str()));
    args.extend(["-o", merged.to_str().unwrap()]);
    let o = facette(&args, None);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(&merged).unwrap(),
        std::fs::read(&full).unwrap()
    );
    let o = facette(
        &[
            "merge",
            &parts[0],
            &parts[1],
            "-o",
            merged.to_str().unwrap(),
        ],
        None,
    );
    assert!(
        stderr(&o).contains("missing part(s) 2, 3 of 4"),
        "{}",
        stderr(&o)
    );
}

/// `facette eval … | head -1`: the reader closes the pipe early; facette stops quietly with
/// the shell's SIGPIPE status (141) instead of printing an error or a panic.
#[test]
fn output_into_a_closed_pipe_exits_quietly() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_facette"))
        .args(["eval", "--material", "{type=\"lambert\"}"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Close our end of stdout before facette writes: every write then hits a broken pipe.
    drop(child.stdout.take());
    let mut stdin = child.stdin.take().unwrap();
    let line = "30,0,30,180\n".repeat(20_000);
    let _ = stdin.write_all(line.as_bytes());
    drop(stdin);
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(141), "{}", stderr(&o));
    assert!(stderr(&o).is_empty(), "{}", stderr(&o));
}

#[test]
fn normalmap_generate_writes_every_kind_and_eval_reads_them_with_a_footprint() {
    let dir = tempfile::tempdir().unwrap();
    for (kind, ext) in [
        ("scratched", "png"),
        ("brushed", "exr"),
        ("very-rough", "png"),
        ("metallic-paint", "exr"),
    ] {
        let f = dir.path().join(format!("{kind}.{ext}"));
        let o = facette(
            &[
                "normalmap",
                "generate",
                kind,
                "-o",
                f.to_str().unwrap(),
                "--resolution",
                "64",
                "--seed",
                "3",
            ],
            None,
        );
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(stdout(&o).contains("RMS slope"), "{}", stdout(&o));
        let mat = format!(
            r#"{{type = "glint", normal_map = "{}", material = "Al"}}"#,
            f.display()
        );
        let o = facette(
            &["eval", "--material", &mat, "--footprint", "0.3,0.6,4,2,0.2"],
            Some("20,0,20,180\n50,10,40,200\n"),
        );
        assert!(o.status.success(), "{kind}: {}", stderr(&o));
        let r = rows(&o);
        assert_eq!(r.len(), 2);
        assert!(r
            .iter()
            .all(|row| row[4..].iter().all(|v| v.is_finite() && *v >= 0.0)));
        assert!(r[0][4] > 0.0, "{kind}: {r:?}");
    }
    for (args, msg) in [
        (
            vec!["normalmap", "generate", "wood", "-o", "x.png"],
            "scratched, brushed, bumpy, flakes",
        ),
        (
            vec![
                "normalmap",
                "generate",
                "bumpy",
                "-o",
                "x.png",
                "--resolution",
                "5000",
            ],
            "4096",
        ),
        (
            vec![
                "normalmap",
                "generate",
                "bumpy",
                "-o",
                "x.jpg",
                "--resolution",
                "8",
            ],
            ".png or .exr",
        ),
    ] {
        let o = facette(&args, None);
        assert!(!o.status.success());
        assert!(stderr(&o).contains(msg), "{args:?}: {}", stderr(&o));
    }
}

#[test]
fn bad_normal_maps_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    // A grey PNG (a height map by mistake), a map whose normals are not unit (all zeros
    // decode: (255, 128, 255) is n ≈ (1, 0, 1), |n| = 1.41), an unreadable file and a missing one.
    let grey = dir.path().join("grey.png");
    image_png(&grey, &[[128, 128, 128]; 16]);
    let zeros = dir.path().join("zeros.png");
    image_png(&zeros, &[[255, 128, 255]; 16]);
    let junk = dir.path().join("junk.png");
    std::fs::write(&junk, b"definitely not a png").unwrap();
    for (file, msg) in [
        (grey.display().to_string(), "greyscale"),
        (
            zeros.display().to_string(),
            "do not decode to a unit normal",
        ),
        (junk.display().to_string(), "junk.png"),
        (
            dir.path().join("none.exr").display().to_string(),
            "none.exr",
        ),
    ] {
        let mat = format!(r#"{{type = "glint", normal_map = "{file}"}}"#);
        let o = facette(&["eval", "--material", &mat], Some("10,0,10,180\n"));
        assert!(!o.status.success(), "{file}");
        assert!(stderr(&o).contains(msg), "{file}: {}", stderr(&o));
    }
}

/// A 4×4 8-bit RGB PNG written by hand (stored, uncompressed deflate).
fn image_png(path: &std::path::Path, px: &[[u8; 3]; 16]) {
    fn crc(data: &[u8]) -> u32 {
        let mut c = 0xffff_ffffu32;
        for &b in data {
            c ^= b as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xedb8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    fn chunk(out: &mut Vec<u8>, ty: &[u8], data: &[u8]) {
        out.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let mut td = ty.to_vec();
        td.extend_from_slice(data);
        out.extend_from_slice(&td);
        out.extend_from_slice(&crc(&td).to_be_bytes());
    }
    let mut raw = Vec::new();
    for y in 0..4 {
        raw.push(0u8);
        for x in 0..4 {
            raw.extend_from_slice(&px[y * 4 + x]);
        }
    }
    let (mut a, mut b) = (1u32, 0u32);
    for &v in &raw {
        a = (a + v as u32) % 65521;
        b = (b + a) % 65521;
    }
    let mut z = vec![0x78, 0x01, 1];
    z.extend_from_slice(&(raw.len() as u16).to_le_bytes());
    z.extend_from_slice(&(!(raw.len() as u16)).to_le_bytes());
    z.extend_from_slice(&raw);
    z.extend_from_slice(&((b << 16) | a).to_be_bytes());
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&4u32.to_be_bytes());
    ihdr.extend_from_slice(&4u32.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    chunk(&mut out, b"IHDR", &ihdr);
    chunk(&mut out, b"IDAT", &z);
    chunk(&mut out, b"IEND", &[]);
    std::fs::write(path, out).unwrap();
}
