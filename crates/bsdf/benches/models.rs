//! Kernel benchmarks of the BSDF models: ns per eval, sample and pdf (one thread), over
//! batches of 256 different inputs (criterion reports the time per element). Results are in
//! docs/performance.md.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::math::spherical_direction;
use facette_bsdf::spec::{build_material, parse_inline_table};
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
    (
        "kelemen-ward",
        r#"{type = "kelemen", alpha = 0.3, kd = 0.5}"#,
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
    for (name, toml) in MODELS {
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
    targets = models
}
criterion_main!(benches);
