//! Benchmarks of the glint model [CCM19] on generated maps (2048² unless told): the cost of one P-NDF
//! query against the footprint size, the build of the lobe mixture (lobes, slope hierarchy
//! and moment pyramid), and eval/sample of the P-BRDF with exact and approximate masking.
//! Also prints the memory per texel of each part and the mip level each masking mode
//! chooses per footprint size. Results are in docs/performance.md.
//!
//!   cargo bench -p facette-bsdf --bench glints -- --warm-up-time 1 --measurement-time 3
//!
//! `FACETTE_GLINT_BENCH_SIZE=4096` runs it on 4096² maps instead (issue 20: mip levels and
//! cache behaviour at that size; about 1.4 GB for the two surfaces).

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use facette_bsdf::fresnel::Fresnel;
use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::math::spectrum::Spectrum;
use facette_bsdf::math::spherical_direction;
use facette_bsdf::models::glint::footprint::FootprintQuery;
use facette_bsdf::models::glint::hierarchy::SlopeHierarchy;
use facette_bsdf::models::glint::microsurface::{build_lobes, DEFAULT_ROUGHNESS_FLOOR};
use facette_bsdf::models::glint::patch_masking::{
    choose_level, APPROX_BLOCKS, DEFAULT_MASKING_LOBES,
};
use facette_bsdf::models::glint::patch_ndf::PatchNdf;
use facette_bsdf::models::glint::{
    generate, Footprint, GlintBsdf, GlintParams, GlintSurface, MaskingMode, MisPdf, NormalMapKind,
};
use facette_bsdf::two_sided::TwoSided;
use facette_bsdf::{Bsdf, BsdfContext, Vec2, Vec3};
use std::sync::{Arc, OnceLock};

/// The maps' side in texels: 2048, or `FACETTE_GLINT_BENCH_SIZE`.
fn size() -> usize {
    static S: OnceLock<usize> = OnceLock::new();
    *S.get_or_init(|| {
        std::env::var("FACETTE_GLINT_BENCH_SIZE")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(2048)
    })
}
const SIGMAS: [f64; 4] = [1.0, 4.0, 16.0, 64.0];
const KINDS: [(&str, NormalMapKind); 2] = [
    ("scratched", NormalMapKind::Scratched),
    ("bumpy", NormalMapKind::Bumpy),
];

/// The surfaces, built once for every benchmark.
fn surface(kind: usize) -> Arc<GlintSurface> {
    static S: OnceLock<Vec<Arc<GlintSurface>>> = OnceLock::new();
    S.get_or_init(|| {
        KINDS
            .iter()
            .map(|(name, k)| {
                let size = size();
                let map = generate(*k, size, 3).unwrap();
                let s =
                    GlintSurface::build(map, DEFAULT_ROUGHNESS_FLOOR, format!("{name} {size}²"))
                        .unwrap();
                println!(
                    "{name} {size}²: built in {:.2} s (lobes + hierarchy + mip levels)",
                    s.build_seconds()
                );
                for l in s.memory().lines() {
                    println!("  {l}");
                }
                println!(
                    "  one lobe: {} bytes (std::mem::size_of of a 16-lobe block / 16)",
                    std::mem::size_of::<facette_bsdf::models::glint::lobe_blocks::LobeBlock>() / 16
                );
                Arc::new(s)
            })
            .collect()
    })[kind]
        .clone()
}

/// 64 footprint centres spread over the map (texels): each query reads memory the one
/// before did not.
fn centres() -> Vec<Vec2> {
    let size = size() as f64;
    (0..64)
        .map(|k| {
            let k = k as f64;
            Vec2::new(
                (k * 0.618_034).fract() * size,
                (k * 0.754_877).fract() * size,
            )
        })
        .collect()
}

/// 64 centres on an 8 × 8 grid `step` texels apart at the map's centre: neighbouring pixels'
/// footprints, as a renderer's tile queries them (they share the lobes they read).
fn clustered_centres(step: f64) -> Vec<Vec2> {
    let mid = 0.5 * size() as f64;
    (0..64)
        .map(|k| Vec2::new(mid + step * (k % 8) as f64, mid + step * (k / 8) as f64))
        .collect()
}

/// P-NDF queries: per footprint size, 256 slopes per batch, either half vectors drawn from
/// the footprint's own P-NDF (a glint is found: the case that matters for shading) or
/// uniform over θ_h < 40° (mostly empty space); footprints spread over the map, or (drawn
/// half vectors) clustered as neighbouring pixels' (cache behaviour).
fn pndf_query(c: &mut Criterion) {
    for (kind, (name, _)) in KINDS.iter().enumerate() {
        let surf = surface(kind);
        let size = size();
        let mut g = c.benchmark_group(format!("pndf-query-{name}-{size}"));
        g.throughput(Throughput::Elements(256));
        // σ = 64 visits ~10⁵ lobes per query: 10 samples keep the run to seconds.
        g.sample_size(10);
        for sigma in SIGMAS {
            let query_at = |c| FootprintQuery::new(Footprint::isotropic(c, sigma), size, size);
            let queries: Vec<FootprintQuery> = centres().into_iter().map(query_at).collect();
            let clustered: Vec<FootprintQuery> =
                clustered_centres(sigma).into_iter().map(query_at).collect();
            let q0 = &queries[0];
            println!(
                "{name} {size}², σ = {sigma} texels: mip level of the approximate masking {}, of the exact masking's sum {}",
                choose_level(&surf, q0, APPROX_BLOCKS),
                choose_level(&surf, q0, DEFAULT_MASKING_LOBES as f64)
            );
            let mut rng = Pcg32::new(7, 1);
            // (query index, slope) pairs.
            let mut sample_slopes = |queries: &[FootprintQuery]| -> Vec<(usize, [f64; 2])> {
                (0..256)
                    .map(|k| {
                        let q = k % queries.len();
                        let m = PatchNdf::new(&surf, &queries[q])
                            .sample_normal(&mut rng)
                            .unwrap_or(Vec3::Z);
                        (q, [-m.x / m.z, -m.y / m.z])
                    })
                    .collect()
            };
            let sampled = sample_slopes(&queries);
            let sampled_clustered = sample_slopes(&clustered);
            let uniform: Vec<(usize, [f64; 2])> = (0..256)
                .map(|k| {
                    let h = spherical_direction(
                        (k as f64 * 0.618_034).fract() * 40f64.to_radians(),
                        (k as f64 * 0.754_877).fract() * std::f64::consts::TAU,
                    );
                    (k % queries.len(), [-h.x / h.z, -h.y / h.z])
                })
                .collect();
            let runs = [
                ("sampled-h", &sampled, &queries),
                ("uniform-h", &uniform, &queries),
                ("sampled-h-clustered", &sampled_clustered, &clustered),
            ];
            for (what, set, queries) in runs {
                let (mut lobes, mut nonzero) = (0usize, 0usize);
                for (q, s) in set.iter() {
                    let (v, n) = PatchNdf::new(&surf, &queries[*q]).p22_counting(*s);
                    lobes += n;
                    nonzero += (v > 0.0) as usize;
                }
                println!(
                    "{name} σ = {sigma} texels, {what}: {:.1} lobes visited per query, {nonzero}/256 queries non-zero",
                    lobes as f64 / 256.0
                );
                g.bench_function(format!("sigma-{sigma}-{what}"), |b| {
                    b.iter(|| {
                        let mut acc = 0.0;
                        for (q, s) in black_box(set).iter() {
                            acc += PatchNdf::new(&surf, &queries[*q]).p22(*s);
                        }
                        black_box(acc)
                    })
                });
            }
        }
        g.finish();
    }
}

/// Building the mixture of a scratched map: lobes, then lobes + slope hierarchy, then
/// the whole surface (with the moment pyramid of the approximate masking).
fn mixture_build(c: &mut Criterion) {
    let size = size();
    let map = generate(NormalMapKind::Scratched, size, 3).unwrap();
    let mut g = c.benchmark_group(format!("mixture-build-scratched-{size}"));
    g.sample_size(10);
    g.bench_function("lobes", |b| {
        b.iter(|| black_box(build_lobes(&map, DEFAULT_ROUGHNESS_FLOOR)))
    });
    g.bench_function("lobes+hierarchy", |b| {
        b.iter(|| {
            let lobes = build_lobes(&map, DEFAULT_ROUGHNESS_FLOOR);
            black_box(SlopeHierarchy::build(&lobes, size, size))
        })
    });
    g.bench_function("surface", |b| {
        b.iter(|| {
            black_box(GlintSurface::build(map.clone(), DEFAULT_ROUGHNESS_FLOOR, "bench").unwrap())
        })
    });
    g.finish();
}

/// eval and sample of the P-BRDF (Al Fresnel) at σ = 4 texels, exact vs approximate masking,
/// over 256 direction pairs and 16 footprint centres (a new BSDF per footprint, as a
/// renderer builds one per shading point: its construction is timed separately).
fn glint_bsdf(c: &mut Criterion) {
    let dirs: Vec<Vec3> = (0..256)
        .map(|k| {
            spherical_direction(
                (k as f64 * 0.618_034).fract() * 1.3,
                (k as f64 * 0.754_877).fract() * std::f64::consts::TAU,
            )
        })
        .collect();
    let al = Fresnel::Conductor {
        eta: Spectrum::rgb(1.657, 0.880, 0.521),
        k: Spectrum::rgb(9.224, 6.270, 4.837),
    };
    let surf = surface(0);
    for (mode_name, mode) in [
        ("exact", MaskingMode::Exact),
        ("approx", MaskingMode::Approx),
    ] {
        let params = GlintParams {
            fresnel: al,
            tint: Spectrum::splat(1.0),
            masking: mode,
            masking_lobes: DEFAULT_MASKING_LOBES,
            mis_pdf: MisPdf::Exact,
        };
        let bsdfs: Vec<TwoSided<GlintBsdf>> = centres()
            .into_iter()
            .take(16)
            .map(|c| {
                TwoSided::new(GlintBsdf::new(
                    surf.clone(),
                    Footprint::isotropic(c, 4.0),
                    &params,
                ))
            })
            .collect();
        let mut g = c.benchmark_group(format!("glint-scratched-{}-sigma-4-{mode_name}", size()));
        g.throughput(Throughput::Elements(256));
        let ctx = BsdfContext::RADIANCE;
        g.bench_function("eval", |b| {
            let mut rng = Pcg32::new(1, 1);
            b.iter(|| {
                let d = black_box(&dirs);
                let mut acc = 0.0;
                for k in 0..256 {
                    acc += bsdfs[k % 16].eval(d[k], d[255 - k], &ctx, &mut rng)[0];
                }
                black_box(acc)
            })
        });
        g.bench_function("sample", |b| {
            let mut rng = Pcg32::new(1, 1);
            b.iter(|| {
                let d = black_box(&dirs);
                let mut acc = 0.0;
                for (k, w) in d.iter().enumerate() {
                    if let Some(s) = bsdfs[k % 16].sample(*w, &ctx, &mut rng) {
                        acc += s.weight[0];
                    }
                }
                black_box(acc)
            })
        });
        g.throughput(Throughput::Elements(1));
        g.bench_function("new-per-shading-point", |b| {
            let mut k = 0usize;
            let cs = centres();
            b.iter(|| {
                k = (k + 1) % cs.len();
                black_box(GlintBsdf::new(
                    surf.clone(),
                    Footprint::isotropic(cs[k], 4.0),
                    &params,
                ))
            })
        });
        g.finish();
    }
}

criterion_group!(benches, pndf_query, mixture_build, glint_bsdf);
criterion_main!(benches);
