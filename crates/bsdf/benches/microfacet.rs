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
        // The map the fixed-rule albedo quadrature uses (GGX: Heitz's disk beside the caps).
        batch(&mut g, "sample_visible_smooth", &dirs, &us, |v, _, u| {
            d.sample_visible_smooth(v, u).z
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

/// The renderer's f32 lanes: 32 packets of 8 visible-normal samples per iteration, in a
/// function compiled for AVX2 + FMA as the render kernel is (the baseline build where the
/// CPU lacks them); criterion reports ns per sample.
mod lanes {
    use facette_bsdf::lanes::{F32x8, LVec3, Real};
    use facette_bsdf::microfacet::{Beckmann, Ggx};
    use facette_bsdf::{Vec2, Vec3};

    pub struct Packets {
        pub dirs: Vec<LVec3<F32x8>>,
        pub us: Vec<(F32x8, F32x8)>,
    }

    pub fn packets(dirs: &[Vec3], us: &[Vec2]) -> Packets {
        Packets {
            dirs: dirs.chunks(8).map(|c| LVec3::from_fn(|i| c[i])).collect(),
            us: us
                .chunks(8)
                .map(|c| (F32x8::from_fn(|i| c[i].x), F32x8::from_fn(|i| c[i].y)))
                .collect(),
        }
    }

    macro_rules! visible_sampler {
        ($name:ident, $avx2:ident, $ndf:ty) => {
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2,fma")]
            unsafe fn $avx2(d: &$ndf, p: &Packets) -> f64 {
                let mut acc = F32x8::zero();
                for (v, &(u0, u1)) in p.dirs.iter().zip(&p.us) {
                    acc = acc + d.sample_visible_lanes(*v, u0, u1).z;
                }
                acc.lane(0)
            }

            pub fn $name(d: &$ndf, p: &Packets) -> f64 {
                #[cfg(target_arch = "x86_64")]
                if std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
                {
                    // SAFETY: the CPU has the features the function is compiled for.
                    return unsafe { $avx2(d, p) };
                }
                let mut acc = F32x8::zero();
                for (v, &(u0, u1)) in p.dirs.iter().zip(&p.us) {
                    acc = acc + d.sample_visible_lanes(*v, u0, u1).z;
                }
                acc.lane(0)
            }
        };
    }
    visible_sampler!(beckmann_visible, beckmann_visible_avx2, Beckmann);
    visible_sampler!(ggx_visible, ggx_visible_avx2, Ggx);
}

fn lane_kernels(c: &mut Criterion) {
    let (dirs, us) = inputs();
    let p = lanes::packets(&dirs, &us);
    let mut g = c.benchmark_group("f32x8");
    g.throughput(Throughput::Elements(256));
    let b = Beckmann::new(0.3, 0.5).unwrap();
    g.bench_function("beckmann sample_visible", |bench| {
        bench.iter(|| lanes::beckmann_visible(black_box(&b), black_box(&p)))
    });
    let gx = Ggx::new(0.3, 0.5).unwrap();
    g.bench_function("ggx sample_visible", |bench| {
        bench.iter(|| lanes::ggx_visible(black_box(&gx), black_box(&p)))
    });
    g.finish();
}

/// sin and cos of the samplers' angles 2πu: the C library's `sincos` against the one the
/// lane code's f64 instantiation uses (`math::sin_cos`), in the same run.
fn sin_cos(c: &mut Criterion) {
    let (_, us) = inputs();
    let angles: Vec<f64> = us.iter().map(|u| std::f64::consts::TAU * u.x).collect();
    let mut g = c.benchmark_group("sin_cos");
    g.throughput(Throughput::Elements(256));
    g.bench_function("libm", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &x in black_box(&angles).iter() {
                let (s, c) = x.sin_cos();
                acc += s + c;
            }
            black_box(acc)
        })
    });
    g.bench_function("facette", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &x in black_box(&angles).iter() {
                let (s, c) = facette_bsdf::math::sin_cos::sin_cos(x);
                acc += s + c;
            }
            black_box(acc)
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(std::time::Duration::from_millis(300)).measurement_time(std::time::Duration::from_secs(1));
    targets = distributions, lane_kernels, sin_cos
}
criterion_main!(benches);
