//! Kernel benchmarks of the microfacet core: ns per D, G1, D + G1, sample and pdf for each
//! distribution (one thread). Each iteration evaluates a batch of 256 different inputs whose
//! results are accumulated, and criterion reports the time per element — the throughput of
//! independent evaluations, as a renderer issues them. Results are in docs/performance.md.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use facette_bsdf::math::spherical_direction;
use facette_bsdf::microfacet::{Beckmann, BeckmannG1, Distribution, Gaussian, Ggx, Ndf, Phong};
use facette_bsdf::{Vec2, Vec3};

fn inputs() -> (Vec<Vec3>, Vec<Vec2>) {
    let mut dirs = Vec::new();
    let mut us = Vec::new();
    for k in 0..256 {
        let t = (k as f64 * 0.618_034).fract();
        let p = (k as f64 * 0.754_877).fract();
        dirs.push(spherical_direction(t * 1.5, p * std::f64::consts::TAU));
        us.push(Vec2::new(
            (k as f64 * 0.569_84).fract(),
            (k as f64 * 0.362_7).fract(),
        ));
    }
    (dirs, us)
}

/// Times `f` over the 256 inputs.
fn batch(
    g: &mut criterion::BenchmarkGroup<criterion::measurement::WallTime>,
    name: &str,
    dirs: &[Vec3],
    us: &[Vec2],
    f: impl Fn(Vec3, Vec3, Vec2) -> f64,
) {
    g.bench_function(name, |b| {
        b.iter(|| {
            let (dirs, us) = (black_box(dirs), black_box(us));
            let mut acc = 0.0;
            for k in 0..256 {
                acc += f(dirs[k], dirs[255 - k], us[k]);
            }
            black_box(acc)
        })
    });
}

fn bench_distribution(c: &mut Criterion, name: &str, d: Ndf) {
    let (dirs, us) = inputs();
    let mut g = c.benchmark_group(name);
    g.throughput(Throughput::Elements(256));
    batch(&mut g, "D", &dirs, &us, |v, _, _| d.d(v));
    batch(&mut g, "G1", &dirs, &us, |v, _, _| d.g1(v, Vec3::Z));
    batch(&mut g, "D+G1", &dirs, &us, |v, _, _| {
        d.d(v) + d.g1(v, Vec3::Z)
    });
    batch(&mut g, "sample_normal", &dirs, &us, |_, _, u| {
        d.sample_normal(u).z
    });
    batch(&mut g, "pdf_normal", &dirs, &us, |v, _, _| d.pdf_normal(v));
    if d.has_visible_sampling() {
        batch(&mut g, "sample_visible", &dirs, &us, |v, _, u| {
            d.sample_visible(v, u).z
        });
        batch(&mut g, "pdf_visible", &dirs, &us, |v, m, _| {
            d.pdf_visible(v, m)
        });
    }
    g.finish();
}

fn distributions(c: &mut Criterion) {
    bench_distribution(
        c,
        "beckmann",
        Ndf::Beckmann(Beckmann::new(0.3, 0.5).unwrap()),
    );
    bench_distribution(
        c,
        "beckmann-rational",
        Ndf::Beckmann(
            Beckmann::new(0.3, 0.5)
                .unwrap()
                .with_g1(BeckmannG1::Rational),
        ),
    );
    bench_distribution(c, "ggx", Ndf::Ggx(Ggx::new(0.3, 0.5).unwrap()));
    bench_distribution(c, "gaussian", Ndf::Gaussian(Gaussian::new(0.3).unwrap()));
    bench_distribution(c, "phong", Ndf::Phong(Phong::new(20.0).unwrap()));
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(std::time::Duration::from_millis(300)).measurement_time(std::time::Duration::from_secs(1));
    targets = distributions
}
criterion_main!(benches);
