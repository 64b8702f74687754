//! Property tests of the material parameters (issue 17): any table of a model's keys with
//! any values — inside, at and far outside the documented ranges, NaN, subnormal, huge —
//! either builds a material whose `eval`, `pdf` and `sample` are finite for every pair of
//! directions tried, or is refused with an error naming a key; it never panics. The test
//! builds run the strict finite guard (`strict-finite`), so a NaN inside a model fails
//! here. Fixed seed: a failure replays.

use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::recipe::{build_material, parse_inline_table};
use facette_bsdf::{BsdfContext, Vec3};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// Values that probe ranges: documented ends, just outside, extremes and non-finite.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        3 => (1e-4f64..10.0).prop_map(|v| format!("{v:e}")),
        1 => (0.0f64..1.0).prop_map(|v| format!("{v:e}")),
        2 => prop::sample::select(vec![
            "0", "-0.0", "1e-320", "1e-4", "1", "1.0000001", "10", "10.5", "100", "1e308",
            "-1", "nan", "inf", "-inf", "0.9999999", "1e-12",
        ])
        .prop_map(str::to_string),
    ]
}

/// Each model with the keys a table may give it (a subset is drawn).
const MODELS: &[(&str, &[&str])] = &[
    ("lambert", &["reflectance"]),
    ("oren-nayar", &["reflectance", "sigma"]),
    ("conductor", &["alpha", "alpha_u", "alpha_v"]),
    ("dielectric", &["alpha", "ior", "ext_ior"]),
    ("kelemen", &["alpha", "ior", "kd"]),
    ("il", &["kd", "ni", "alpha", "sigma"]),
];

fn table() -> impl Strategy<Value = String> {
    (0..MODELS.len())
        .prop_flat_map(|m| {
            let keys = MODELS[m].1;
            (
                Just(m),
                prop::collection::vec((0..keys.len(), value()), 0..4),
                prop::sample::select(vec!["beckmann", "ggx", "x"]),
            )
        })
        .prop_map(|(m, pairs, dist)| {
            let (ty, keys) = MODELS[m];
            let mut t = format!("{{type = \"{ty}\"");
            let mut used = Vec::new();
            for (k, v) in pairs {
                if !used.contains(&k) {
                    used.push(k);
                    t += &format!(", {} = {v}", keys[k]);
                }
            }
            if matches!(ty, "conductor" | "dielectric") {
                t += &format!(", distribution = \"{dist}\"");
            }
            if ty == "kelemen" {
                // A small albedo table: the build is what is tested, not its accuracy.
                t += ", table_samples = 64";
            }
            t + "}"
        })
}

#[test]
fn any_parameter_table_builds_a_finite_material_or_names_its_error() {
    let config = Config {
        cases: 160,
        failure_persistence: None,
        ..Config::default()
    };
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[17; 32]);
    let mut runner = TestRunner::new_with_rng(config, rng);
    let dirs = [
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.6, 0.0, 0.8),
        Vec3::new(-0.3, 0.5, 0.81240384),
        Vec3::new(0.99, 0.0, 0.14106736),
        Vec3::new(0.2, -0.1, -0.97467943),
    ];
    runner
        .run(&table(), |text| {
            let built = parse_inline_table(&text).and_then(|t| build_material(&t));
            match built {
                Err(e) => {
                    let m = e.to_string();
                    prop_assert!(!m.is_empty() && !m.contains("panicked"), "{text}: {m}");
                }
                Ok(b) => {
                    let mut rng = Pcg32::new(7, 0);
                    let ctx = &BsdfContext::RADIANCE;
                    for &wo in &dirs {
                        for &wi in &dirs {
                            let f = b.eval(wo, wi, ctx, &mut rng);
                            prop_assert!(f.is_finite(), "{text}: eval {wo} {wi} = {f:?}");
                            let p = b.pdf(wo, wi, ctx);
                            prop_assert!(p.is_finite(), "{text}: pdf {wo} {wi} = {p}");
                        }
                        if let Some(s) = b.sample(wo, ctx, &mut rng) {
                            prop_assert!(s.weight.is_finite(), "{text}: sample weight");
                        }
                    }
                }
            }
            Ok(())
        })
        .unwrap();
}
