//! End-to-end tests of the lab commands: `plot`, `fit` and `reproduce`. Each checks the
//! numbers a command prints or writes, not only that a file appeared.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn facette(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_facette"))
        .args(args)
        .output()
        .expect("facette runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn ok(o: &Output) {
    assert!(
        o.status.success(),
        "stdout:\n{}\nstderr:\n{}",
        stdout(o),
        stderr(o)
    );
}

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The (series, x, y) rows of a `--csv` file.
fn csv_rows(p: &Path) -> Vec<(String, f64, f64)> {
    std::fs::read_to_string(p)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let (name, rest) = l.rsplit_once(',').unwrap();
            let (name, x) = name.rsplit_once(',').unwrap();
            (
                name.trim_matches('"').to_string(),
                x.parse().unwrap(),
                rest.parse().unwrap(),
            )
        })
        .collect()
}

fn is_png(p: &Path) -> bool {
    std::fs::read(p)
        .map(|b| b.len() > 1000 && &b[1..4] == b"PNG")
        .unwrap_or(false)
}

const LAMBERT: &str = r#"{type = "lambert", reflectance = 0.5}"#;
const CONDUCTOR: &str = r#"{type = "conductor", distribution = "ggx", alpha = 0.05}"#;

#[test]
fn plot_slice_of_two_materials_has_the_expected_shapes() {
    let d = tmp();
    let (svg, csv) = (d.path().join("s.svg"), d.path().join("s.csv"));
    let o = facette(&[
        "plot",
        "slice",
        "--material",
        LAMBERT,
        "--material",
        CONDUCTOR,
        "--label",
        "matte",
        "--label",
        "metal",
        "--theta-i",
        "40",
        "--log",
        "--points",
        "181",
        "-o",
        s(&svg),
        "--csv",
        s(&csv),
    ]);
    ok(&o);
    let out = stdout(&o);
    assert!(out.contains("matte: max 1.591549e-1"), "{out}");
    let text = std::fs::read_to_string(&svg).unwrap();
    for label in [
        "matte",
        "metal",
        "f (1/sr)",
        "θ_o (degrees",
        "mirror direction",
    ] {
        assert!(text.contains(label), "the SVG lacks {label}");
    }
    let rows = csv_rows(&csv);
    for (_, _, y) in rows.iter().filter(|r| r.0 == "matte") {
        assert!((y - 0.5 / std::f64::consts::PI).abs() < 1e-8);
    }
    // The narrow GGX lobe peaks at the mirror direction θ_o = +θ_i (1° grid).
    let peak = rows
        .iter()
        .filter(|r| r.0 == "metal")
        .max_by(|a, b| a.2.total_cmp(&b.2))
        .unwrap();
    assert!((peak.1 - 40.0).abs() <= 1.0, "{peak:?}");
}

#[test]
fn plot_polar_hemisphere_and_albedo() {
    let d = tmp();
    // Polar lobe of f·|cos θ_o| of a Lambertian surface: a circle of diameter ρ/π.
    let (png, csv) = (d.path().join("p.png"), d.path().join("p.csv"));
    let o = facette(&[
        "plot",
        "polar",
        "--material",
        LAMBERT,
        "--quantity",
        "fcos",
        "--theta-i",
        "30",
        "-o",
        s(&png),
        "--csv",
        s(&csv),
    ]);
    ok(&o);
    assert!(is_png(&png));
    let r = 0.5 / std::f64::consts::PI / 2.0;
    let lobe: Vec<_> = csv_rows(&csv)
        .into_iter()
        .filter(|x| x.0 == "θ_i = 30°")
        .collect();
    assert_eq!(lobe.len(), 181);
    for (_, x, z) in lobe {
        assert!(((x * x + (z - r) * (z - r)).sqrt() - r).abs() < 1e-8);
    }
    // Hemisphere map of a Lambertian surface: one value everywhere.
    let png = d.path().join("h.png");
    let o = facette(&[
        "plot",
        "hemisphere",
        "--material",
        LAMBERT,
        "--theta-i",
        "45",
        "--resolution",
        "32",
        "-o",
        s(&png),
    ]);
    ok(&o);
    assert!(
        stdout(&o).contains("min 1.591549e-1, max 1.591549e-1"),
        "{}",
        stdout(&o)
    );
    assert!(is_png(&png));
    // Albedo: a smooth dielectric reflects Fresnel and transmits the rest.
    let (svg, csv) = (d.path().join("a.svg"), d.path().join("a.csv"));
    let o = facette(&[
        "plot",
        "albedo",
        "--material",
        r#"{type = "dielectric", alpha = 0, ior = 1.5}"#,
        "--step",
        "30",
        "--samples",
        "20000",
        "-o",
        s(&svg),
        "--csv",
        s(&csv),
    ]);
    ok(&o);
    let rows = csv_rows(&csv);
    let at = |name: &str, x: f64| rows.iter().find(|r| r.0 == name && r.1 == x).unwrap().2;
    assert!((at("reflectance R", 0.0) - 0.04).abs() < 0.005, "{rows:?}");
    assert!((at("R + T", 60.0) - 1.0).abs() < 1e-9);
}

#[test]
fn plot_table_against_quadrature() {
    let d = tmp();
    let table = d.path().join("t.fctab");
    let mat = r#"{type = "il", kd = 0.9, ni = 1.2, distribution = "gaussian", sigma = 0.3}"#;
    let o = facette(&[
        "tabulate",
        "--material",
        mat,
        "--step",
        "10",
        "--samples",
        "512",
        "-o",
        s(&table),
    ]);
    ok(&o);
    let png = d.path().join("t.png");
    let o = facette(&[
        "plot",
        "table",
        "--material",
        mat,
        "--table",
        s(&table),
        "--theta-i",
        "60",
        "--samples",
        "4096",
        "--points",
        "91",
        "-o",
        s(&png),
    ]);
    ok(&o);
    let out = stdout(&o);
    let num = |key: &str| -> f64 {
        let i = out.find(key).unwrap_or_else(|| panic!("{key} in {out}")) + key.len();
        out[i..]
            .split(|c: char| c == ',' || c == ';' || c.is_whitespace())
            .find(|t| !t.is_empty())
            .unwrap()
            .parse()
            .unwrap()
    };
    let (interp, nearest) = (
        num("interpolated mean relative error "),
        num("nearest entry mean "),
    );
    // A 10° grid with interpolation is within a few per cent (TSBRM §4.3); the nearest entry
    // is clearly worse.
    assert!(interp < 0.05 && nearest > interp, "{out}");
    assert!(is_png(&png));
    // A table built for another material is refused.
    let o = facette(&[
        "plot",
        "table",
        "--material",
        r#"{type = "il", ni = 1.5, distribution = "gaussian", sigma = 0.3}"#,
        "--table",
        s(&table),
        "-o",
        s(&png),
    ]);
    assert!(
        !o.status.success() && stderr(&o).contains("the table was built for ni = 1.2"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn plot_errors_are_clear_and_write_nothing() {
    let d = tmp();
    let bad: PathBuf = d.path().join("x.jpg");
    let o = facette(&["plot", "slice", "--material", LAMBERT, "-o", s(&bad)]);
    assert!(!o.status.success() && stderr(&o).contains("use a .svg or .png extension"));
    let out = d.path().join("x.svg");
    let o = facette(&[
        "plot",
        "slice",
        "--material",
        LAMBERT,
        "--quantity",
        "g",
        "-o",
        s(&out),
    ]);
    assert!(
        stderr(&o).contains("valid values: f, fcos, fcos-i"),
        "{}",
        stderr(&o)
    );
    let o = facette(&[
        "plot",
        "slice",
        "--material",
        LAMBERT,
        "--theta-i",
        "95",
        "-o",
        s(&out),
    ]);
    assert!(stderr(&o).contains("[0, 90)"), "{}", stderr(&o));
    let o = facette(&[
        "plot",
        "slice",
        "--material",
        "{type = \"lambret\"}",
        "-o",
        s(&out),
    ]);
    assert!(stderr(&o).contains("lambert, oren-nayar"), "{}", stderr(&o));
    assert!(!out.exists() && !bad.exists());
}

mod fit {
    use super::*;
    use facette_bsdf::math::rng::{mix_seed, Pcg32};
    use facette_bsdf::recipe::{build_material, parse_inline_table};
    use facette_bsdf::BsdfContext;
    use facette_lab::merl::MerlBrdf;

    /// Writes a synthetic MERL file of `material` (3 % of the bins when `sparse`).
    fn synthetic(material: &str, sparse: bool, noise: f64, path: &Path) {
        let b = build_material(&parse_inline_table(material).unwrap()).unwrap();
        let mut m = MerlBrdf::from_fn(|k, i, o| {
            (!sparse || mix_seed(3, k as u64) % 100 < 3)
                .then(|| b.eval(o, i, &BsdfContext::RADIANCE, &mut Pcg32::new(1, 1)))
        });
        if noise > 0.0 {
            m = m.with_multiplicative_noise(noise, 4);
        }
        m.save(path).unwrap();
    }

    fn value(out: &str, name: &str) -> f64 {
        let line = out
            .lines()
            .find(|l| l.starts_with(&format!("{name} = ")))
            .unwrap_or_else(|| panic!("no {name} in {out}"));
        line[name.len() + 3..]
            .split_whitespace()
            .next()
            .unwrap()
            .parse()
            .unwrap()
    }

    #[test]
    fn fit_kelemen_from_the_cli_recovers_its_parameters() {
        let d = tmp();
        let file = d.path().join("k.binary");
        synthetic(
            r#"{type = "kelemen", alpha = 0.2, ior = 1.5, kd = [0.5, 0.3, 0.2]}"#,
            false,
            0.05,
            &file,
        );
        let png = d.path().join("k.png");
        let o = facette(&[
            "fit",
            s(&file),
            "--model",
            "kelemen",
            "--samples",
            "2000",
            "-o",
            s(&png),
        ]);
        ok(&o);
        let out = stdout(&o);
        for (name, expected) in [("kd_r", 0.5), ("kd_g", 0.3), ("alpha", 0.2), ("ior", 1.5)] {
            let v = value(&out, name);
            assert!((v / expected - 1.0).abs() < 0.03, "{name} = {v}\n{out}");
        }
        assert!(out.contains("material: {type = \"kelemen\""), "{out}");
        assert!(is_png(&png));
    }

    #[test]
    fn fit_il_with_the_approximate_body_and_plastic() {
        let d = tmp();
        let file = d.path().join("il.binary");
        synthetic(
            r#"{type = "il", kd = [0.34, 0.34, 0.34], ni = 1.12, alpha = 0.092, evaluation = "quadrature", samples = 512}"#,
            true,
            0.0,
            &file,
        );
        let o = facette(&[
            "fit",
            s(&file),
            "--il-evaluation",
            "approx",
            "--samples",
            "3000",
        ]);
        ok(&o);
        let out = stdout(&o);
        // IL18 Fig. 19's MERL1 (specular white phenolic): K_d = 0.34, n_i = 1.12, σ = 0.065.
        for (name, expected, tol) in [
            ("kd_g", 0.34, 0.03),
            ("ni", 1.12, 0.01),
            ("sigma", 0.092 / std::f64::consts::SQRT_2, 0.05),
        ] {
            let v = value(&out, name);
            assert!((v / expected - 1.0).abs() < tol, "{name} = {v}\n{out}");
        }
        // The Lambert + Cook–Torrance model cannot follow IL's body term: a larger residual.
        let o2 = facette(&["fit", s(&file), "--model", "plastic", "--samples", "3000"]);
        ok(&o2);
        let (r_il, r_plastic) = (
            value(&out, "rms residual"),
            value(&stdout(&o2), "rms residual"),
        );
        assert!(r_plastic > 2.0 * r_il, "{r_il} {r_plastic}");
    }

    /// `facette measure` writes the file the library's virtual measurement makes, noise
    /// included, and refuses a bad noise level without writing anything.
    #[test]
    fn measure_writes_the_material_as_a_merl_file() {
        let d = tmp();
        let (cli, lib) = (d.path().join("cli.binary"), d.path().join("lib.binary"));
        let material =
            r#"{type = "conductor", material = "Au", distribution = "ggx", alpha = 0.3}"#;
        let o = facette(&[
            "measure",
            "--material",
            material,
            "--noise",
            "0.02",
            "--seed",
            "5",
            "-o",
            s(&cli),
        ]);
        ok(&o);
        let b = build_material(&parse_inline_table(material).unwrap()).unwrap();
        facette_lab::measure::measure_material(b.as_ref(), 0.02, 5)
            .save(&lib)
            .unwrap();
        assert_eq!(std::fs::read(&cli).unwrap(), std::fs::read(&lib).unwrap());
        let m = MerlBrdf::load(&cli).unwrap();
        assert!(stdout(&o).contains(&format!("{} valid bins", m.valid_bins())));
        let bad = d.path().join("bad.binary");
        let o = facette(&[
            "measure",
            "--material",
            material,
            "--noise",
            "2",
            "-o",
            s(&bad),
        ]);
        assert!(!o.status.success() && stderr(&o).contains("--noise"));
        assert!(!bad.exists());
    }

    #[test]
    fn malformed_merl_files_are_clear_errors() {
        let d = tmp();
        let file = d.path().join("bad.binary");
        std::fs::write(&file, [90u8, 0, 0, 0, 90, 0, 0, 0, 180, 0, 0, 0, 1, 2, 3]).unwrap();
        let o = facette(&["fit", s(&file)]);
        assert!(!o.status.success());
        assert!(stderr(&o).contains("truncated"), "{}", stderr(&o));
        let o = facette(&["fit", s(&d.path().join("missing.binary"))]);
        assert!(
            !o.status.success() && stderr(&o).contains("missing.binary"),
            "{}",
            stderr(&o)
        );
        let o = facette(&["fit", s(&file), "--model", "phong"]);
        assert!(
            stderr(&o).contains("valid values: il, plastic, kelemen"),
            "{}",
            stderr(&o)
        );
    }
}

mod reproduce {
    use super::*;

    /// The number after `key` on the line that starts with `prefix`.
    fn number_after(out: &str, prefix: &str, key: &str) -> f64 {
        let line = out
            .lines()
            .find(|l| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("no line {prefix} in {out}"));
        let i = line
            .find(key)
            .unwrap_or_else(|| panic!("no {key} in {line}"))
            + key.len();
        let t: String = line[i..]
            .chars()
            .take_while(|c| c.is_ascii_digit() || "-+.e".contains(*c))
            .collect();
        t.parse()
            .unwrap_or_else(|_| panic!("no number after {key} in {line}"))
    }

    #[test]
    fn il18_fig7_and_ksk01_fig5_numbers() {
        let d = tmp();
        let o = facette(&["reproduce", "il18-fig7", "--quick", "-o", s(d.path())]);
        ok(&o);
        let out = stdout(&o);
        // IL18 §3.3: without inter-reflections the rough surface loses more than 20 % at σ = 1;
        // the flat surface (σ = 0) conserves energy; the V-cavity walk restores most of it.
        let single = number_after(&out, "σ = 1:", "single scattering ");
        let multiple = number_after(&out, "σ = 1:", "with inter-reflections ");
        assert!(single < 0.8, "{out}");
        assert!(multiple > 0.95 && multiple < 1.01, "{out}");
        assert!(
            (number_after(&out, "σ = 0:", "single scattering ") - 1.0).abs() < 0.01,
            "{out}"
        );
        assert!(is_png(&d.path().join("il18-fig7.png")));
        let svg = std::fs::read_to_string(d.path().join("il18-fig7.svg")).unwrap();
        assert!(svg.contains("total reflectance") && svg.contains("with inter-reflections (IL_∞)"));

        let o = facette(&["reproduce", "ksk01-fig5", "--quick", "-o", s(d.path())]);
        ok(&o);
        let out = stdout(&o);
        let worst = number_after(&out, "largest |specular + matte − 1|", "89°]: ");
        assert!(worst < 0.01, "{out}");
    }

    #[test]
    fn cheap_figures_print_their_key_numbers() {
        let d = tmp();
        let o = facette(&["reproduce", "wmlt07-fig8", "-o", s(d.path())]);
        ok(&o);
        // D(0) = 1/(π α²) for all three distributions at matched widths (WMLT07 §5.2).
        assert!(
            stdout(&o).contains("Beckmann 7.9577, Phong 7.9577, GGX 7.9577"),
            "{}",
            stdout(&o)
        );
        let o = facette(&["reproduce", "ksk01-fig2", "--quick", "-o", s(d.path())]);
        ok(&o);
        // The off-specular peak lies beyond the mirror direction and moves with θ'.
        let out = stdout(&o);
        let shift = |p: &str| number_after(&out, p, "off-specular by ");
        assert!(
            shift("θ' = 67.5°") > shift("θ' = 22.5°") && shift("θ' = 22.5°") >= 0.0,
            "{out}"
        );
        let o = facette(&["reproduce", "wmlt07-fig2", "--quick", "-o", s(d.path())]);
        ok(&o);
        // Rough transmission peaks beyond the Snell direction, more so at grazing incidence.
        let out = stdout(&o);
        let shift = |p: &str| number_after(&out, p, "shift ");
        assert!(
            shift("θ_i = 80°") > 5.0 && shift("θ_i = 0°").abs() < 1.0,
            "{out}"
        );
        let o = facette(&["reproduce", "fig99", "-o", s(d.path())]);
        assert!(
            !o.status.success() && stderr(&o).contains("il18-fig7"),
            "{}",
            stderr(&o)
        );
    }
}

#[test]
fn plot_ndf_of_a_glint_footprint() {
    let d = tmp();
    // A small bumpy map with a wide roughness floor: 8 × 8 points per cell resolve every
    // lobe, so the cell averages integrate to ∫ D_P cos θ_h dω_h = 1.
    let mat = r#"{type = "glint", generate = "bumpy", resolution = 64, seed = 2, roughness_floor = 0.05}"#;
    let (png, csv) = (d.path().join("ndf.png"), d.path().join("ndf.csv"));
    let o = facette(&[
        "plot",
        "ndf",
        "--material",
        mat,
        "--footprint",
        "0.3,0.6,4,2,0.2",
        "--resolution",
        "64",
        "--supersample",
        "8",
        "-o",
        s(&png),
        "--csv",
        s(&csv),
    ]);
    ok(&o);
    assert!(is_png(&png));
    let out = stdout(&o);
    let integral: f64 = out
        .split("dω_h ≈ ")
        .nth(1)
        .and_then(|t| t.split_whitespace().next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("{out}"));
    assert!((integral - 1.0).abs() < 0.02, "{out}");
    // The CSV has the cells inside the disk, all finite and non-negative, some positive.
    let text = std::fs::read_to_string(&csv).unwrap();
    let vals: Vec<f64> = text
        .lines()
        .skip(1)
        .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
        .collect();
    assert!(vals.len() > 3000 && vals.len() < 64 * 64, "{}", vals.len());
    assert!(vals.iter().all(|v| v.is_finite() && *v >= 0.0));
    assert!(vals.iter().any(|v| *v > 1.0));
    // SVG output, the material's own footprint.
    let svg = d.path().join("ndf.svg");
    let o = facette(&[
        "plot",
        "ndf",
        "--material",
        mat,
        "--resolution",
        "16",
        "--log",
        "-o",
        s(&svg),
    ]);
    ok(&o);
    assert!(std::fs::read_to_string(&svg).unwrap().contains("sin θ_h"));
    // Clear errors: a material without a patch NDF, a malformed footprint.
    for (args, msg) in [
        (
            vec!["--material", CONDUCTOR],
            "needs a `type = \"glint\"` material, got `type = \"conductor\"`",
        ),
        (
            vec!["--material", mat, "--footprint", "0.5,0.5"],
            "expected U,V,SIGMA[,SIGMA_V[,RHO]]",
        ),
        (
            vec!["--material", mat, "--footprint", "0.5,0.5,2,2,1.5"],
            "ρ",
        ),
    ] {
        let bad = d.path().join("bad.png");
        let mut a = vec!["plot", "ndf", "-o", s(&bad)];
        a.extend(args);
        let o = facette(&a);
        assert!(!o.status.success());
        assert!(stderr(&o).contains(msg), "{msg}: {}", stderr(&o));
        assert!(!bad.exists());
    }
}
