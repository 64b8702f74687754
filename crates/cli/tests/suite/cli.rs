//! End-to-end tests of the `facette` command line for materials: `eval`, `albedo`,
//! `validate`, bad materials, and output into a closed pipe. Rendering is in
//! `cli_render.rs`, tables and normal maps in `cli_tables_and_maps.rs`.

use crate::common::*;
use std::io::Write;
use std::process::{Command, Stdio};

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
fn eval_with_error_prints_the_quadrature_error_or_the_standard_error() {
    // Beckmann α = 0.7, n_i = 1, at a grazing pair: the reference of IL18 eqs. 4 + 13 from
    // scripts/il_reference.py (crates/bsdf/tests/suite/il_quadrature_reference.rs).
    let reference = 0.021_810_921_655_075_52;
    let il = r#"{type = "il", kd = 0.8, ni = 1.0, distribution = "beckmann", alpha = 0.7, masking = "v-cavity", evaluation = "quadrature"}"#;
    let pair = "85,0,85,180\n";
    let o = facette(&["eval", "--material", il, "--with-error"], Some(pair));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).starts_with("theta_i,phi_i,theta_o,phi_o,r,g,b,err_r,err_g,err_b\n"));
    let r = rows(&o);
    assert_eq!(r[0].len(), 10);
    let (f, err) = (r[0][4], r[0][7]);
    assert!(err > 0.0 && err <= 1e-6 * f, "{f} ± {err}");
    assert!(
        (f - reference).abs() <= err.max(1e-9 * reference),
        "{f} ± {err} vs {reference}"
    );
    // Without the flag: the seven columns, the same value.
    let o = facette(&["eval", "--material", il], Some(pair));
    assert_eq!(
        stdout(&o).lines().next(),
        Some("theta_i,phi_i,theta_o,phi_o,r,g,b")
    );
    assert_eq!(rows(&o)[0], r[0][..7].to_vec());
    // Stochastic: the standard error of the mean of the estimates, consistent with the
    // reference.
    let stochastic = il.replace("\"quadrature\"", "\"stochastic\"");
    let o = facette(
        &[
            "eval",
            "--material",
            &stochastic,
            "--with-error",
            "--samples",
            "20000",
        ],
        Some(pair),
    );
    let r = rows(&o);
    let (f, se) = (r[0][4], r[0][7]);
    assert!(se > 0.0 && se < 0.05 * f, "{f} ± {se}");
    assert!(
        (f - reference).abs() < 5.0 * se,
        "{f} ± {se} vs {reference}"
    );
    // Closed forms: 0.
    let o = facette(
        &[
            "eval",
            "--material",
            r#"{type = "lambert"}"#,
            "--with-error",
        ],
        Some(pair),
    );
    assert_eq!(rows(&o)[0][7..], [0.0, 0.0, 0.0]);
}

#[test]
fn eval_notes_stochastic_values_only() {
    // IL with the body and the inter-reflections by quadrature evaluates deterministically
    // (only its sampling weights carry a walk): no note about averaged estimates, the same
    // value from two seeds; with the walk, the note.
    let base = r#"type = "il", kd = 0.8, ni = 1.5, distribution = "beckmann", alpha = 0.5, scattering = "multiple", evaluation = "quadrature", tolerance = 1e-3"#;
    let pair = Some("40,0,30,150\n");
    let exact = format!("{{{base}, multiple_evaluation = \"quadrature\"}}");
    let run = |m: &str, seed: &str| facette(&["eval", "--material", m, "--seed", seed], pair);
    let (a, b) = (run(&exact, "1"), run(&exact, "2"));
    assert!(a.status.success(), "{}", stderr(&a));
    assert!(!stderr(&a).contains("stochastically"), "{}", stderr(&a));
    assert_eq!(rows(&a), rows(&b));
    let walk = format!("{{{base}}}");
    let o = facette(&["eval", "--material", &walk, "--samples", "200"], pair);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("is evaluated stochastically; each value averages 200"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn quadrature_keys_are_checked_by_name() {
    let base = r#"type = "il", distribution = "beckmann", alpha = 0.3"#;
    for (extra, expect) in [
        (
            r#"evaluation = "quadrature", samples = 64, tolerance = 1e-4"#,
            "exclusive",
        ),
        (r#"evaluation = "quadrature", tolerance = 0.5"#, "tolerance"),
        (
            r#"evaluation = "stochastic", tolerance = 1e-4"#,
            "`tolerance` applies to",
        ),
        (
            r#"evaluation = "quadrature", tolerances = 1e-4"#,
            "tolerance",
        ),
    ] {
        let m = format!("{{{base}, {extra}}}");
        let o = facette(&["eval", "--material", &m], Some("30,0,30,180\n"));
        assert!(!o.status.success(), "{m}");
        assert!(stderr(&o).contains(expect), "{m}: {}", stderr(&o));
    }
    // Oren–Nayar: the same keys.
    let o = facette(
        &[
            "eval",
            "--material",
            r#"{type = "oren-nayar", sigma = 0.3, evaluation = "quadrature", tolerance = 1e-8}"#,
            "--with-error",
        ],
        Some("60,0,60,0\n"),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let r = rows(&o);
    assert!(r[0][7] > 0.0 && r[0][7] <= 1e-8 * r[0][4], "{:?}", r[0]);
}
