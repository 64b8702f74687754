//! Kernel benchmarks of the microfacet core: ns per D, G1, D + G1, sample and pdf for each
//! distribution (one thread). Results are recorded in docs/performance.md.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use facette_bsdf::math::spherical_direction;
use facette_bsdf::microfacet::{Beckmann, Distribution, Gaussian, Ggx, Ndf, Phong};
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

fn bench_distribution(c: &mut Criterion, name: &str, d: Ndf) {
    let (dirs, us) = inputs();
    let mut g = c.benchmark_group(name);
    g.bench_function("D", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) & 255;
            black_box(d.d(black_box(dirs[k])))
        })
    });
    g.bench_function("G1", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) & 255;
            black_box(d.g1(black_box(dirs[k]), Vec3::Z))
        })
    });
    g.bench_function("D+G1", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) & 255;
            let v = black_box(dirs[k]);
            black_box(d.d(v) + d.g1(v, Vec3::Z))
        })
    });
    g.bench_function("sample_normal", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) & 255;
            black_box(d.sample_normal(black_box(us[k])))
        })
    });
    g.bench_function("pdf_normal", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) & 255;
            black_box(d.pdf_normal(black_box(dirs[k])))
        })
    });
    if d.has_visible_sampling() {
        g.bench_function("sample_visible", |b| {
            let mut k = 0;
            b.iter(|| {
                k = (k + 1) & 255;
                black_box(d.sample_visible(black_box(dirs[k]), black_box(us[k])))
            })
        });
        g.bench_function("pdf_visible", |b| {
            let mut k = 0;
            b.iter(|| {
                k = (k + 1) & 255;
                black_box(d.pdf_visible(black_box(dirs[k]), black_box(dirs[255 - k])))
            })
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
                .with_g1(facette_bsdf::microfacet::BeckmannG1::Rational),
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
