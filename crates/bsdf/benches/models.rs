//! Kernel benchmarks of the BSDF models: ns per eval, sample and pdf (one thread), over
//! batches of 256 different inputs (criterion reports the time per element). Results are in
//! docs/performance.md.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::math::spherical_direction;
use facette_bsdf::recipe::{build_material, parse_inline_table};
use facette_bsdf::{BsdfContext, Vec3};

const MODELS: &[(&str, &str)] = &[
    ("lambert", r#"{type = "lambert"}"#),
    (
        "oren-nayar-qualitative",
        r#"{type = "oren-nayar", sigma = 0.3, model = "qualitative"}"#,
    ),
    (
        "oren-nayar-exact-stochastic",
        r#"{type = "oren-nayar", sigma = 0.3, evaluation = "stochastic"}"#,
    ),
    (
        "oren-nayar-exact-quadrature-256",
        r#"{type = "oren-nayar", sigma = 0.3, samples = 256}"#,
    ),
    (
        "conductor-ggx",
        r#"{type = "conductor", distribution = "ggx", alpha = 0.3, material = "Au"}"#,
    ),
    (
        "conductor-beckmann",
        r#"{type = "conductor", distribution = "beckmann", alpha = 0.3, material = "Au"}"#,
    ),
    (
        "dielectric-ggx",
        r#"{type = "dielectric", distribution = "ggx", alpha = 0.3, ior = 1.5}"#,
    ),
    (
        "dielectric-beckmann",
        r#"{type = "dielectric", distribution = "beckmann", alpha = 0.3, ior = 1.5}"#,
    ),
    // The energy options against their single-scattering base (height-correlated masking).
    (
        "conductor-ggx-correlated",
        r#"{type = "conductor", distribution = "ggx", alpha = 0.3, material = "Au", masking = "smith-correlated"}"#,
    ),
    (
        "conductor-ggx-multiple",
        r#"{type = "conductor", distribution = "ggx", alpha = 0.3, material = "Au", scattering = "multiple"}"#,
    ),
    (
        "conductor-ggx-compensated",
        r#"{type = "conductor", distribution = "ggx", alpha = 0.3, material = "Au", masking = "smith-correlated", energy = "compensated"}"#,
    ),
    (
        "dielectric-ggx-correlated",
        r#"{type = "dielectric", distribution = "ggx", alpha = 0.3, ior = 1.5, masking = "smith-correlated"}"#,
    ),
    (
        "dielectric-ggx-multiple",
        r#"{type = "dielectric", distribution = "ggx", alpha = 0.3, ior = 1.5, scattering = "multiple"}"#,
    ),
    (
        "dielectric-ggx-compensated",
        r#"{type = "dielectric", distribution = "ggx", alpha = 0.3, ior = 1.5, masking = "smith-correlated", energy = "compensated"}"#,
    ),
    (
        "kelemen-ward",
        r#"{type = "kelemen", alpha = 0.3, kd = 0.5}"#,
    ),
    ("il-flat", r#"{type = "il", kd = 0.6, ni = 1.5, alpha = 0}"#),
    (
        "il-stochastic",
        r#"{type = "il", kd = 0.6, ni = 1.5, distribution = "beckmann", alpha = 0.3}"#,
    ),
    (
        "il-quadrature-256",
        r#"{type = "il", kd = 0.6, ni = 1.5, distribution = "beckmann", alpha = 0.3, evaluation = "quadrature", samples = 256}"#,
    ),
    (
        "il-quadrature-adaptive",
        r#"{type = "il", kd = 0.6, ni = 1.5, distribution = "beckmann", alpha = 0.3, evaluation = "quadrature"}"#,
    ),
    (
        "il-approx",
        r#"{type = "il", kd = 0.6, ni = 1.5, distribution = "beckmann", alpha = 0.3, masking = "v-cavity", evaluation = "approx"}"#,
    ),
    (
        "il-multiple",
        r#"{type = "il", kd = 0.6, ni = 1.5, distribution = "beckmann", alpha = 0.3, masking = "v-cavity", scattering = "multiple"}"#,
    ),
];

fn models(c: &mut Criterion) {
    let dirs: Vec<Vec3> = (0..256)
        .map(|k| {
            spherical_direction(
                (k as f64 * 0.618_034).fract() * 1.5,
                (k as f64 * 0.754_877).fract() * std::f64::consts::TAU,
            )
        })
        .collect();
    // The tabulated IL body term (5° grid, 10 000 microfacets per entry), saved to a
    // temporary file and loaded through the material syntax.
    let table_path = std::env::temp_dir().join("facette-bench-il-5deg.fctab");
    {
        use facette_bsdf::microfacet::specular_lobe::{NormalSampling, SpecularLobe};
        use facette_bsdf::microfacet::{Beckmann, Masking, Ndf};
        let lobe = SpecularLobe::new(
            Ndf::Beckmann(Beckmann::isotropic(0.3).unwrap()),
            Masking::SmithSeparable,
            NormalSampling::Visible,
        )
        .unwrap();
        facette_bsdf::models::il::il_table::BodyTable::build(&lobe, 1.5, 5.0, 10_000, &|_, _| {})
            .unwrap()
            .save(&table_path)
            .unwrap();
    }
    let table_toml = format!(
        r#"{{type = "il", kd = 0.6, ni = 1.5, distribution = "beckmann", alpha = 0.3, table = "{}"}}"#,
        table_path.display()
    );
    let mut all: Vec<(&str, String)> = MODELS.iter().map(|(n, t)| (*n, t.to_string())).collect();
    all.push(("il-table-5deg", table_toml));
    for (name, toml) in &all {
        let bsdf = build_material(&parse_inline_table(toml).unwrap()).unwrap();
        let mut g = c.benchmark_group(*name);
        g.throughput(Throughput::Elements(256));
        let ctx = BsdfContext::RADIANCE;
        g.bench_function("eval", |b| {
            let mut rng = Pcg32::new(1, 1);
            b.iter(|| {
                let d = black_box(&dirs);
                let mut acc = 0.0;
                for k in 0..256 {
                    acc += bsdf.eval(d[k], d[255 - k], &ctx, &mut rng)[0];
                }
                black_box(acc)
            })
        });
        g.bench_function("sample", |b| {
            let mut rng = Pcg32::new(1, 1);
            b.iter(|| {
                let d = black_box(&dirs);
                let mut acc = 0.0;
                for w in d.iter() {
                    if let Some(s) = bsdf.sample(*w, &ctx, &mut rng) {
                        acc += s.weight[0];
                    }
                }
                black_box(acc)
            })
        });
        g.bench_function("pdf", |b| {
            b.iter(|| {
                let d = black_box(&dirs);
                let mut acc = 0.0;
                for k in 0..256 {
                    acc += bsdf.pdf(d[k], d[255 - k], &ctx);
                }
                black_box(acc)
            })
        });
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(std::time::Duration::from_millis(300)).measurement_time(std::time::Duration::from_secs(1));
    targets = models, il_tables, albedo_tables, il_multiple
}
criterion_main!(benches);

/// Building a 5° and a 10° IL body table with 10 000 microfacets per entry (TSBRM §4.3
/// reports 1 min 43 s and 13 s).
fn il_tables(c: &mut Criterion) {
    use facette_bsdf::microfacet::specular_lobe::{NormalSampling, SpecularLobe};
    use facette_bsdf::microfacet::{Gaussian, Masking, Ndf};
    let lobe = SpecularLobe::new(
        Ndf::Gaussian(Gaussian::new(0.3).unwrap()),
        Masking::VCavity,
        NormalSampling::Distribution,
    )
    .unwrap();
    let mut g = c.benchmark_group("il-table-build");
    g.sample_size(10);
    for step in [10.0, 5.0] {
        g.bench_function(format!("step-{step}deg-10000-samples"), |b| {
            b.iter(|| {
                black_box(
                    facette_bsdf::models::il::il_table::BodyTable::build(
                        &lobe,
                        1.2,
                        step,
                        10_000,
                        &|_, _| {},
                    )
                    .unwrap(),
                )
            })
        });
    }
    g.finish();
}

/// Building the albedo tables of the energy compensation (GGX, height-correlated masking):
/// the conductor's (F = 1) and the dielectric's (η = 1.5 and 1/1.5, both sides).
fn albedo_tables(c: &mut Criterion) {
    use facette_bsdf::microfacet::{Ggx, Masking, Ndf};
    use facette_bsdf::models::multiple_scattering::albedo_tables::{
        AlbedoTable, EntryQuadrature, TableFresnel,
    };
    let ndf = Ndf::Ggx(Ggx::isotropic(0.3).unwrap());
    let mut g = c.benchmark_group("albedo-table-build");
    g.sample_size(10);
    for (name, fresnel) in [
        ("conductor", TableFresnel::One),
        ("dielectric-1.5", TableFresnel::Dielectric(1.5)),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| black_box(AlbedoTable::build(&ndf, Masking::SmithCorrelated, fresnel)))
        });
        // The fixed 16-point entries (the default before issue 18), for comparison.
        g.bench_function(format!("{name}-fixed16"), |b| {
            b.iter(|| {
                black_box(AlbedoTable::build_with(
                    &ndf,
                    Masking::SmithCorrelated,
                    fresnel,
                    EntryQuadrature::Fixed { points: 16 },
                ))
            })
        });
    }
    g.finish();
}

/// IL_∞ eval, deterministic throughout (the body by adaptive quadrature, the V-cavity
/// multiple scattering by its quadrature; issue 18: the target is 200 direction pairs per
/// second at tolerance 1e-4, the tolerance relative to the value eval returns), per
/// direction pair, with the groove operators of the quadrature nodes already cached (the
/// steady state of a sweep: the θ_m nodes come from one dyadic tree, so a sweep's pairs
/// share them); the walk at 100,000 estimates per pair is the alternative (about 0.26 s a
/// pair). Beckmann α = 1.2 (deep grooves, long chains) is the slow end of the range.
/// Measured figures: docs/performance.md.
fn il_multiple(c: &mut Criterion) {
    let mut g = c.benchmark_group("il-multiple-quadrature");
    g.sample_size(10);
    let pairs: Vec<(Vec3, Vec3)> = [
        (0.3, 0.5, 2.0),
        (1.1, 0.7, 3.0),
        (0.9, 1.2, 0.5),
        (0.2, 1.0, 1.0),
    ]
    .iter()
    .map(|&(to, ti, pi)| (spherical_direction(to, 0.0), spherical_direction(ti, pi)))
    .collect();
    for (alpha, tol) in [("0.5", "1e-4"), ("0.5", "1e-3"), ("1.2", "1e-4")] {
        let m = build_material(
            &parse_inline_table(&format!(
                "{{type = \"il\", kd = 0.8, ni = 1.5, distribution = \"beckmann\", alpha = {alpha}, scattering = \"multiple\", evaluation = \"quadrature\", multiple_evaluation = \"quadrature\", tolerance = {tol}}}"
            ))
            .unwrap(),
        )
        .unwrap();
        g.throughput(Throughput::Elements(pairs.len() as u64));
        g.bench_function(format!("beckmann-{alpha}-tolerance-{tol}"), |b| {
            let mut rng = Pcg32::new(1, 1);
            b.iter(|| {
                for (wo, wi) in &pairs {
                    black_box(m.eval(*wo, *wi, &BsdfContext::RADIANCE, &mut rng));
                }
            })
        });
    }
    g.finish();
}
