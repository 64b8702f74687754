//! Energy lost by single scattering, and restored (issue: multiple scattering): the white
//! furnace for the random walk on the Smith microsurface (HHdD16) and for the Kulla–Conty
//! compensation (KC17), from both sides of a dielectric; the walk's first order against
//! today's single-scattering lobe; height-distribution independence; reciprocity; the
//! validation suite on the new modes. Fixed seeds; every figure is printed.

use facette_bsdf::math::rng::{mix_seed, Pcg32};
use facette_bsdf::math::spherical_direction;
use facette_bsdf::microfacet::specular_lobe::{NormalSampling, SpecularLobe};
use facette_bsdf::microfacet::{Beckmann, Distribution, Ggx, Masking, Ndf};
use facette_bsdf::models::multiple_scattering::albedo_tables::{
    directional_albedo as table_albedo, TableFresnel,
};
use facette_bsdf::models::multiple_scattering::smith_microsurface::HeightDistribution;
use facette_bsdf::models::{
    MultipleScatteringConductor, MultipleScatteringDielectric, RoughConductor, RoughDielectric,
};
use facette_bsdf::recipe::{build_material, parse_inline_table};
use facette_bsdf::two_sided::OpaqueBsdf;
use facette_bsdf::validation::bsdf_checks::directional_albedo;
use facette_bsdf::validation::estimator_chi2::{estimator_chi2_test, EstimatorChi2Config};
use facette_bsdf::validation::suites::{material_suite_matching, SuiteOptions};
use facette_bsdf::validation::SphereMap;
use facette_bsdf::{Bsdf, BsdfContext, Spectrum, Vec3};
use rayon::prelude::*;
use std::sync::Arc;

fn material(s: &str) -> Arc<dyn Bsdf> {
    build_material(&parse_inline_table(s).unwrap()).unwrap_or_else(|e| panic!("{s}: {e}"))
}

fn material_err(s: &str) -> String {
    match build_material(&parse_inline_table(s).unwrap()) {
        Ok(b) => panic!("{s} built: {}", b.describe()),
        Err(e) => e.to_string(),
    }
}

fn lobe(ndf: Ndf) -> SpecularLobe {
    SpecularLobe::new(ndf, Masking::SmithCorrelated, NormalSampling::Visible).unwrap()
}

fn ndf(dist: &str, ax: f64, ay: f64) -> Ndf {
    match dist {
        "ggx" => Ndf::Ggx(Ggx::new(ax, ay).unwrap()),
        _ => Ndf::Beckmann(Beckmann::new(ax, ay).unwrap()),
    }
}

const ALPHAS: [f64; 4] = [0.1, 0.5, 1.0, 1.5];
const INCIDENCES: [f64; 4] = [0.0, 30.0, 60.0, 85.0];

/// Mean and standard error of the sampled weights' first channel, reflected and transmitted.
fn sampled(b: &dyn Bsdf, wo: Vec3, ctx: &BsdfContext, n: usize, seed: u64) -> [f64; 4] {
    let (r, rse, t, tse) = directional_albedo(b, wo, ctx, n, seed);
    [r[0], rse[0], t[0], tse[0]]
}

#[test]
fn white_conductor_furnace() {
    // F = 1: the walk's weights are exactly 1, so the albedo by sampling is 1 up to walks
    // abandoned past MAX_ORDER vertices or at degenerate configurations; the compensated
    // model reaches 1 within the table's interpolation error. The single-scattering loss,
    // from the table's own quadrature, is printed beside each case.
    let mut worst_walk: f64 = 0.0;
    let mut worst_comp: f64 = 0.0;
    for dist in ["beckmann", "ggx"] {
        for alpha in ALPHAS {
            let ms = material(&format!(
                r#"{{type = "conductor", distribution = "{dist}", alpha = {alpha}, scattering = "multiple"}}"#
            ));
            let comp = material(&format!(
                r#"{{type = "conductor", distribution = "{dist}", alpha = {alpha}, masking = "smith-correlated", energy = "compensated"}}"#
            ));
            let single = ndf(dist, alpha, alpha);
            for (k, deg) in INCIDENCES.iter().enumerate() {
                let wo = spherical_direction(deg.to_radians(), 0.4);
                let ctx = BsdfContext::RADIANCE;
                let seed = (alpha * 100.0) as u64 * 16 + k as u64;
                let e_ss = table_albedo(
                    &single,
                    Masking::SmithCorrelated,
                    TableFresnel::One,
                    wo.z,
                    48,
                );
                let walk = sampled(ms.as_ref(), wo, &ctx, 20_000, seed);
                let comp = sampled(comp.as_ref(), wo, &ctx, 40_000, seed);
                println!(
                    "{dist} α = {alpha} θ = {deg}°: single {e_ss:.4} (loses {:.2} %), random walk {:.6}, compensated {:.4} ± {:.1e}",
                    100.0 * (1.0 - e_ss),
                    walk[0],
                    comp[0],
                    comp[1]
                );
                worst_walk = worst_walk.max((1.0 - walk[0]).abs());
                worst_comp = worst_comp.max((comp[0] - 1.0).abs() - 3.0 * comp[1]);
                assert!((walk[0] - 1.0).abs() < 0.005);
            }
        }
    }
    println!(
        "max |1 − albedo|: random walk {worst_walk:.1e}; compensated, beyond 3 standard errors, {worst_comp:.1e}"
    );
    assert!(worst_walk < 1e-4, "{worst_walk}");
    // The documented error of the tables (docs/materials.md): 3e-3.
    assert!(worst_comp < 3e-3, "{worst_comp}");
}

#[test]
fn dielectric_reflectance_plus_transmittance_is_one_from_both_sides() {
    let mut worst_walk: f64 = 0.0;
    let mut worst_comp: f64 = 0.0;
    let mut worst_split: f64 = 0.0;
    for dist in ["beckmann", "ggx"] {
        for alpha in ALPHAS {
            let ms = material(&format!(
                r#"{{type = "dielectric", distribution = "{dist}", alpha = {alpha}, ior = 1.5, scattering = "multiple"}}"#
            ));
            let comp = material(&format!(
                r#"{{type = "dielectric", distribution = "{dist}", alpha = {alpha}, ior = 1.5, masking = "smith-correlated", energy = "compensated"}}"#
            ));
            let single = ndf(dist, alpha, alpha);
            for (k, deg) in INCIDENCES.iter().enumerate() {
                for side in [1.0, -1.0] {
                    let w = spherical_direction(deg.to_radians(), 0.4);
                    let wo = Vec3::new(w.x, w.y, side * w.z);
                    // Flux: importance mode, where reflectance + transmittance is the energy.
                    let ctx = BsdfContext::IMPORTANCE;
                    let seed = (alpha * 100.0) as u64 * 32 + 2 * k as u64 + (side < 0.0) as u64;
                    let eta = if side > 0.0 { 1.5 } else { 1.0 / 1.5 };
                    let e_ss = table_albedo(
                        &single,
                        Masking::SmithCorrelated,
                        TableFresnel::Dielectric(eta),
                        w.z,
                        48,
                    );
                    let walk = sampled(ms.as_ref(), wo, &ctx, 20_000, seed);
                    let c = sampled(comp.as_ref(), wo, &ctx, 40_000, seed);
                    let c_se = c[1].hypot(c[3]);
                    println!(
                        "{dist} α = {alpha} θ = {deg}° {}: single R + T {e_ss:.4} (loses {:.2} %); random walk R {:.4} T {:.4} (sum {:.6}); compensated R {:.4} T {:.4} (sum {:.4} ± {c_se:.1e})",
                        if side > 0.0 { "outside" } else { "inside " },
                        100.0 * (1.0 - e_ss),
                        walk[0],
                        walk[2],
                        walk[0] + walk[2],
                        c[0],
                        c[2],
                        c[0] + c[2]
                    );
                    assert!((walk[0] + walk[2] - 1.0).abs() < 0.005);
                    worst_walk = worst_walk.max((walk[0] + walk[2] - 1.0).abs());
                    worst_comp = worst_comp.max((c[0] + c[2] - 1.0).abs() - 3.0 * c_se);
                    worst_split = worst_split.max((c[0] - walk[0]).abs());
                }
            }
        }
    }
    println!(
        "max |1 − (R + T)|: random walk {worst_walk:.1e}; compensated, beyond 3 standard errors, {worst_comp:.1e}; compensated R vs walk R: max |ΔR| = {worst_split:.3}"
    );
    assert!(worst_walk < 1e-4, "{worst_walk}");
    assert!(worst_comp < 5e-3, "{worst_comp}");
    // The split is tabulated from the walk (docs/materials.md): R within 2 % of the walk's
    // here too (it was 0.13 at GGX α = 1.5 with the former Markov-chain split, 0.42 before).
    assert!(worst_split < 0.02, "{worst_split}");
}

#[test]
fn compensated_glass_splits_reflection_and_transmission_like_the_walk() {
    // R and T of `energy = "compensated"` each within 2 % (absolute) of the random walk's
    // (`scattering = "multiple"`), at 0, 45, 70 and 85° from both sides, η = 1.5, Beckmann
    // and GGX α from 0.1 to 1.5: flux (importance mode). Walk 40 000 samples, compensated
    // model 80 000 (standard error of a difference ≤ 3.5e-3). Measured figures (and α = 3,
    // 10) in docs/materials.md: largest 0.009 since the split is tabulated from the walk;
    // 0.131 (GGX α = 1.5) with the former Markov-chain split.
    let alphas = [0.1, 0.3, 0.5, 0.7, 1.0, 1.5];
    let cases: Vec<(&str, f64)> = ["beckmann", "ggx"]
        .iter()
        .flat_map(|&d| alphas.iter().map(move |&a| (d, a)))
        .collect();
    let rows: Vec<Vec<(f64, String)>> = cases
        .par_iter()
        .map(|&(dist, alpha)| {
            let ms = material(&format!(
                r#"{{type = "dielectric", distribution = "{dist}", alpha = {alpha}, ior = 1.5, scattering = "multiple"}}"#
            ));
            let comp = material(&format!(
                r#"{{type = "dielectric", distribution = "{dist}", alpha = {alpha}, ior = 1.5, masking = "smith-correlated", energy = "compensated"}}"#
            ));
            let mut out = Vec::new();
            for (k, deg) in [0.0f64, 45.0, 70.0, 85.0].iter().enumerate() {
                for side in [1.0, -1.0] {
                    let w = spherical_direction(deg.to_radians(), 0.4);
                    let wo = Vec3::new(w.x, w.y, side * w.z);
                    let ctx = BsdfContext::IMPORTANCE;
                    let seed = 4000 + 16 * k as u64 + (side < 0.0) as u64;
                    let walk = sampled(ms.as_ref(), wo, &ctx, 40_000, seed);
                    let c = sampled(comp.as_ref(), wo, &ctx, 80_000, seed + 8);
                    let (dr, dt) = (c[0] - walk[0], c[2] - walk[2]);
                    out.push((
                        dr.abs().max(dt.abs()),
                        format!(
                            "{dist} α = {alpha} θ = {deg}° {}: walk R {:.4} T {:.4}, compensated R {:.4} T {:.4} (ΔR {dr:+.4}, ΔT {dt:+.4})",
                            if side > 0.0 { "outside" } else { "inside " },
                            walk[0],
                            walk[2],
                            c[0],
                            c[2]
                        ),
                    ));
                }
            }
            out
        })
        .collect();
    let mut worst: (f64, String) = (0.0, String::new());
    for (d, label) in rows.into_iter().flatten() {
        println!("{label}");
        if d > worst.0 {
            worst = (d, label);
        }
    }
    println!("largest |ΔR| or |ΔT|: {:.4} ({})", worst.0, worst.1);
    assert!(worst.0 < 0.02, "{}", worst.1);
}

/// Eval against the histogram of `sample` for the random walk (32 × 32 estimates per cell:
/// the walk's estimator is heavy-tailed and fewer points underestimate its variance). The
/// totals are the albedo by the sampled weights and by integrating `eval`: they must agree.
fn eval_against_samples(toml: &str, wo: Vec3, ctx: BsdfContext, region: f64, seed: u64) {
    eval_against_samples_with(toml, wo, ctx, region, 100_000, seed);
}

/// [`eval_against_samples`] with `samples` draws; `region` 0 tests the whole sphere.
fn eval_against_samples_with(
    toml: &str,
    wo: Vec3,
    ctx: BsdfContext,
    region: f64,
    samples: usize,
    seed: u64,
) {
    let b = material(toml);
    let o = estimator_chi2_test(
        &SphereMap::standard(),
        &EstimatorChi2Config {
            bins: (16, 32),
            samples,
            strata: 32,
            seed,
        },
        |wi| region == 0.0 || wi.z * region > 0.0,
        |r| b.sample(wo, &ctx, r).map(|s| (s.wi, s.weight.average())),
        |wi, r| b.eval(wo, wi, &ctx, r).average() * wi.z.abs(),
    );
    println!(
        "{toml} θ_o = {:.0}°, {}: {}",
        wo.z.acos().to_degrees(),
        if region == 0.0 {
            "whole sphere"
        } else if region * wo.z > 0.0 {
            "reflection"
        } else {
            "transmission"
        },
        o.summary()
    );
    assert!(o.p_value > 1e-3 && o.invalid == 0, "{}", o.summary());
    assert!(o.total_z().abs() < 4.0, "{}", o.summary());
}

#[test]
fn the_walks_eval_agrees_with_its_samples() {
    let mut cases: Vec<(&str, Vec3, BsdfContext, f64)> = vec![
        (
            r#"{type = "conductor", distribution = "ggx", alpha = 1.0, scattering = "multiple"}"#,
            spherical_direction(0.5, 0.3),
            BsdfContext::RADIANCE,
            1.0,
        ),
        (
            r#"{type = "conductor", distribution = "beckmann", alpha_u = 0.9, alpha_v = 0.4, material = "Cu", scattering = "multiple"}"#,
            spherical_direction(1.2, 0.3),
            BsdfContext::RADIANCE,
            1.0,
        ),
        (
            r#"{type = "dielectric", distribution = "ggx", alpha = 0.7, scattering = "multiple"}"#,
            spherical_direction(0.6, 0.3),
            BsdfContext::RADIANCE,
            -1.0,
        ),
        (
            r#"{type = "dielectric", distribution = "beckmann", alpha = 1.0, scattering = "multiple"}"#,
            -spherical_direction(0.6, 0.3),
            BsdfContext::IMPORTANCE,
            -1.0,
        ),
        (
            r#"{type = "dielectric", distribution = "beckmann", alpha = 1.0, scattering = "multiple"}"#,
            -spherical_direction(0.6, 0.3),
            BsdfContext::IMPORTANCE,
            1.0,
        ),
    ];
    // Glass at grazing incidence (85°), from both sides: before the walk's remainder was
    // split where it leaves the side of `o` (`SPLIT_AT_CROSSING`), GGX α = 0.7 from inside
    // failed here (docs/materials.md, "GGX glass at grazing").
    let grazing = |side: f64| {
        let w = spherical_direction(85f64.to_radians(), 0.4);
        Vec3::new(w.x, w.y, side * w.z)
    };
    let glass =
        r#"{type = "dielectric", distribution = "ggx", alpha = 0.7, scattering = "multiple"}"#;
    let rough =
        r#"{type = "dielectric", distribution = "beckmann", alpha = 1.0, scattering = "multiple"}"#;
    cases.extend([
        (glass, grazing(-1.0), BsdfContext::RADIANCE, -1.0),
        (glass, grazing(-1.0), BsdfContext::RADIANCE, 1.0),
        (glass, grazing(1.0), BsdfContext::RADIANCE, 1.0),
        (glass, grazing(1.0), BsdfContext::RADIANCE, -1.0),
        (rough, grazing(-1.0), BsdfContext::IMPORTANCE, -1.0),
        (rough, grazing(-1.0), BsdfContext::IMPORTANCE, 1.0),
        (rough, grazing(1.0), BsdfContext::IMPORTANCE, 1.0),
        (rough, grazing(1.0), BsdfContext::IMPORTANCE, -1.0),
    ]);
    for (k, (toml, wo, ctx, region)) in cases.into_iter().enumerate() {
        eval_against_samples(toml, wo, ctx, region, 100 + k as u64);
    }
}

#[test]
fn glass_at_grazing_passes_validates_eval_against_samples() {
    // Exactly `facette validate`'s test of GGX glass α = 0.7 at 85° (1e6 draws, 16 × 32
    // cells of 32 × 32 eval estimates, its seeds: incidence k of 8, `mix_seed(7, 8k)`).
    // Measured p before the walk's remainder was split where it leaves the side of `o`:
    // 3.5e-5 from inside (k = 7), 2.0e-2 from outside (k = 3); after: 3.3e-2 and 0.15.
    let glass =
        r#"{type = "dielectric", distribution = "ggx", alpha = 0.7, scattering = "multiple"}"#;
    for (k, side) in [(7u64, -1.0), (3, 1.0)] {
        let w = spherical_direction(85f64.to_radians(), 0.4);
        let wo = Vec3::new(w.x, w.y, side * w.z);
        eval_against_samples_with(
            glass,
            wo,
            BsdfContext::RADIANCE,
            0.0,
            1_000_000,
            mix_seed(7, 8 * k),
        );
    }
}

#[test]
fn conductor_reciprocity_within_monte_carlo_error() {
    // f(a, b) = f(b, a): single scattering exactly, the walk's higher orders in expectation.
    // (1) The eval: its walk enters from the more masked direction of the unordered pair, so
    // f(a, b) and f(b, a) are one estimator — the same value for the same random numbers (to rounding).
    // (2) The walk itself, entered from either side (`estimate_orders`), at pairs where both
    // walks are well sampled: equal expectations, Beckmann included.
    let pairs = [
        (spherical_direction(0.3, 0.4), spherical_direction(1.1, 2.9)),
        (spherical_direction(1.3, 0.1), spherical_direction(0.5, 3.5)),
        (
            spherical_direction(0.9, 1.0),
            spherical_direction(1.45, 1.2),
        ),
        (
            spherical_direction(0.91, -0.66),
            spherical_direction(1.31, 1.97),
        ),
    ];
    for toml in [
        r#"{type = "conductor", distribution = "ggx", alpha = 1.0, scattering = "multiple"}"#,
        r#"{type = "conductor", distribution = "ggx", alpha_u = 0.7, alpha_v = 0.3, material = "Au", scattering = "multiple"}"#,
        r#"{type = "conductor", distribution = "beckmann", alpha = 0.5, scattering = "multiple"}"#,
        r#"{type = "conductor", distribution = "beckmann", alpha_u = 0.7, alpha_v = 0.3, material = "Cu", scattering = "multiple"}"#,
    ] {
        let b = material(toml);
        let ctx = BsdfContext::RADIANCE;
        for (k, (a, c)) in pairs.iter().enumerate() {
            for seed in 0..64 {
                let fab = b.eval(*a, *c, &ctx, &mut Pcg32::new(seed, k as u64));
                let fba = b.eval(*c, *a, &ctx, &mut Pcg32::new(seed, k as u64));
                // (The closed-form single scattering agrees to rounding.)
                for ch in 0..3 {
                    let tol = 1e-12 * fab[ch].abs().max(fba[ch].abs());
                    assert!(
                        (fab[ch] - fba[ch]).abs() <= tol,
                        "{toml} pair {k}: {fab:?} vs {fba:?}"
                    );
                }
            }
            let mut rng = Pcg32::new(31, k as u64);
            let (fab, sab) = b.eval_estimate(*a, *c, &ctx, 20_000, &mut rng);
            let (fba, sba) = b.eval_estimate(*c, *a, &ctx, 20_000, &mut rng);
            let z = (fab[1] - fba[1]).abs() / sab[1].hypot(sba[1]);
            println!(
                "{toml} pair {k}: eval f(a,b) {:.5} ± {:.1e}, f(b,a) {:.5} ± {:.1e} ({z:.2} σ)",
                fab[1], sab[1], fba[1], sba[1]
            );
            assert!(z < 4.0, "{toml} pair {k}");
        }
    }
    let n = 200_000;
    for dist in ["beckmann", "ggx"] {
        let conductor = MultipleScatteringConductor::new(
            RoughConductor::new(
                Some(lobe(ndf(dist, 0.5, 0.5))),
                facette_bsdf::fresnel::Fresnel::One,
                Spectrum::ONE,
            ),
            HeightDistribution::Uniform,
        )
        .unwrap();
        for (k, (a, c)) in pairs
            .iter()
            .enumerate()
            .take(2)
            .chain(pairs.iter().enumerate().skip(3))
        {
            let walk = |x: Vec3, y: Vec3, seed: u64| -> (f64, f64) {
                let v: Vec<f64> = (0..16u64)
                    .into_par_iter()
                    .flat_map_iter(|chunk| {
                        let mut rng = Pcg32::new(seed, chunk);
                        let conductor = &conductor;
                        (0..n / 16)
                            .map(move |_| conductor.estimate_orders(x, y, 2, &mut rng)[0])
                            .collect::<Vec<_>>()
                    })
                    .collect();
                let mean = v.iter().sum::<f64>() / n as f64;
                let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1) as f64;
                (mean, (var / n as f64).sqrt())
            };
            let (fab, sab) = walk(*a, *c, 7);
            let (fba, sba) = walk(*c, *a, 9);
            let z = (fab - fba).abs() / sab.hypot(sba);
            println!(
                "{dist} α = 0.5 pair {k}: orders ≥ 2 walking from a {fab:.5e} ± {sab:.1e}, from b {fba:.5e} ± {sba:.1e} ({z:.2} σ)"
            );
            assert!(z < 4.0, "{dist} pair {k}");
        }
    }
}

#[test]
fn the_eval_walks_from_the_more_masked_direction_with_less_variance() {
    // Beckmann α = 0.5, one grazing (84°) and one steep (56°) direction: orders ≥ 2 from the
    // walk entering at the grazing direction (what eval does) and at the steep one. Both are
    // unbiased, but next-event estimation toward a grazing direction depends on rare walks
    // that reach the top of the microsurface: that side's estimate is ruled by a few rare
    // large values (measured: relative standard error 0.035 from the grazing side, 0.97 from
    // the steep one, whose mean swings by factors of 2–15 between seeds).
    let conductor = MultipleScatteringConductor::new(
        RoughConductor::new(
            Some(lobe(ndf("beckmann", 0.5, 0.5))),
            facette_bsdf::fresnel::Fresnel::One,
            Spectrum::ONE,
        ),
        HeightDistribution::Uniform,
    )
    .unwrap();
    let grazing = Vec3::new(0.834, 0.544, 0.097).normalize();
    let steep = Vec3::new(-0.711, 0.424, 0.561).normalize();
    assert!(conductor.surface().walk_from_first(grazing, steep));
    let n = 100_000;
    let stats = |x: Vec3, y: Vec3| -> (f64, f64) {
        let mut rng = Pcg32::new(12, 0);
        let v: Vec<f64> = (0..n)
            .map(|_| conductor.estimate_orders(x, y, 2, &mut rng)[0])
            .collect();
        let mean = v.iter().sum::<f64>() / n as f64;
        let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1) as f64;
        (mean, (var / n as f64).sqrt() / mean)
    };
    let (from_grazing, rel_g) = stats(grazing, steep);
    let (from_steep, rel_s) = stats(steep, grazing);
    println!(
        "orders ≥ 2: walk from the grazing direction {from_grazing:.4e} (relative error {rel_g:.3}), from the steep one {from_steep:.4e} ({rel_s:.3})"
    );
    assert!(rel_g < 0.1 && rel_g < rel_s, "{rel_g} vs {rel_s}");
}

#[test]
fn coloured_conductors_compensation_against_the_walk() {
    // KC17's Fresnel factor F_ms approximates the walk's Fresnel products.
    let mut worst: f64 = 0.0;
    for (metal, alpha) in [("Au", 0.5), ("Cu", 1.0), ("Al", 1.5)] {
        let ms = material(&format!(
            r#"{{type = "conductor", distribution = "ggx", alpha = {alpha}, material = "{metal}", scattering = "multiple"}}"#
        ));
        let comp = material(&format!(
            r#"{{type = "conductor", distribution = "ggx", alpha = {alpha}, material = "{metal}", masking = "smith-correlated", energy = "compensated"}}"#
        ));
        let single = material(&format!(
            r#"{{type = "conductor", distribution = "ggx", alpha = {alpha}, material = "{metal}", masking = "smith-correlated"}}"#
        ));
        for deg in [0.0f64, 60.0] {
            let wo = spherical_direction(deg.to_radians(), 0.1);
            let ctx = BsdfContext::RADIANCE;
            let (w, wse, ..) = directional_albedo(ms.as_ref(), wo, &ctx, 100_000, 3);
            let (c, ..) = directional_albedo(comp.as_ref(), wo, &ctx, 100_000, 4);
            let (s, ..) = directional_albedo(single.as_ref(), wo, &ctx, 100_000, 5);
            println!(
                "{metal} GGX α = {alpha} θ = {deg}°: single {:.4?}, walk {:.4?} ± {:.0e}, compensated {:.4?}",
                s.0, w.0, wse[1], c.0
            );
            for ch in 0..3 {
                worst = worst.max((c[ch] - w[ch]).abs());
                assert!(c[ch] > s[ch], "compensation adds energy");
            }
        }
    }
    // KC17's Fresnel factor assumes the energy of every extra order is spread like the
    // compensation lobe's: measured 0.08 at α = 1.5 (documented in docs/materials.md).
    println!("max |compensated − walk| over RGB: {worst:.4}");
    assert!(worst < 0.1, "{worst}");
}

#[test]
fn the_walks_first_order_is_todays_single_scattering_lobe() {
    // The walk's next-event estimate of order 1 alone (the model evaluates it in closed
    // form) must reproduce the shared specular lobe with height-correlated Smith masking.
    let conductor = MultipleScatteringConductor::new(
        RoughConductor::new(
            Some(lobe(ndf("ggx", 0.4, 0.9))),
            facette_bsdf::fresnel::Fresnel::One,
            Spectrum::ONE,
        ),
        HeightDistribution::Uniform,
    )
    .unwrap();
    let dielectric = MultipleScatteringDielectric::new(
        RoughDielectric::new(
            1.5,
            Some(lobe(ndf("beckmann", 0.6, 0.3))),
            false,
            Spectrum::ONE,
            Spectrum::ONE,
        )
        .unwrap(),
        HeightDistribution::Uniform,
    )
    .unwrap();
    let pairs = [
        (spherical_direction(0.3, 0.4), spherical_direction(0.8, 2.9)),
        (spherical_direction(1.2, 0.1), spherical_direction(0.5, 3.5)),
        (
            spherical_direction(0.6, 1.0),
            -spherical_direction(0.4, 4.0),
        ),
        (
            -spherical_direction(0.2, 0.0),
            -spherical_direction(0.9, 2.5),
        ),
        (
            -spherical_direction(0.7, 0.3),
            spherical_direction(0.2, 3.0),
        ),
    ];
    let results: Vec<String> = pairs
        .par_iter()
        .enumerate()
        .map(|(k, &(i, o))| {
            let mut rng = Pcg32::new(17, k as u64);
            let n = 100_000;
            let radiance = BsdfContext::RADIANCE;
            let (exact, first) = if i.z * o.z > 0.0 && k < 2 {
                let f1 = conductor.single().eval(o, i, &radiance, &mut rng)[0];
                let est = facette_bsdf::bsdf::mean_and_stderr(n, || {
                    conductor.estimate_orders(i, o, 1, &mut rng)
                        - conductor.estimate_orders(i, o, 2, &mut rng)
                });
                (f1, est)
            } else {
                // f(i, o), i the light: radiance mode eval(wo = o, wi = i).
                let f1 = dielectric.single().eval(o, i, &radiance, &mut rng)[0];
                let est = facette_bsdf::bsdf::mean_and_stderr(n, || {
                    dielectric.estimate_orders(i, o, 1, &mut rng)
                        - dielectric.estimate_orders(i, o, 2, &mut rng)
                });
                (f1, est)
            };
            let (m, se) = (first.0[0], first.1[0]);
            assert!(
                (m - exact).abs() < 4.0 * se + 1e-9,
                "pair {k}: walk's order 1 {m} ± {se} vs lobe {exact}"
            );
            format!("pair {k}: lobe {exact:.5}, walk's first order {m:.5} ± {se:.1e}")
        })
        .collect();
    for r in results {
        println!("{r}");
    }
}

#[test]
fn the_bsdf_does_not_depend_on_the_height_distribution() {
    // HHdD16 §4: only C1(h) enters the walk.
    for (toml, pairs) in [
        (
            r#"type = "conductor", distribution = "ggx", alpha_u = 0.8, alpha_v = 0.4, material = "Cu", scattering = "multiple""#,
            vec![(spherical_direction(0.5, 0.2), spherical_direction(1.1, 2.0))],
        ),
        (
            r#"type = "dielectric", distribution = "beckmann", alpha = 0.9, scattering = "multiple""#,
            vec![
                (spherical_direction(0.5, 0.2), spherical_direction(0.7, 3.0)),
                (
                    spherical_direction(0.9, 0.2),
                    -spherical_direction(0.3, 3.0),
                ),
            ],
        ),
    ] {
        let u = material(&format!("{{{toml}, height_distribution = \"uniform\"}}"));
        let g = material(&format!("{{{toml}, height_distribution = \"gaussian\"}}"));
        for (wo, wi) in pairs {
            let ctx = BsdfContext::RADIANCE;
            let mut rng = Pcg32::new(2, 2);
            let (fu, su) = u.eval_estimate(wo, wi, &ctx, 60_000, &mut rng);
            let (fg, sg) = g.eval_estimate(wo, wi, &ctx, 60_000, &mut rng);
            let z = (fu[0] - fg[0]).abs() / su[0].hypot(sg[0]);
            println!(
                "{toml}: uniform {:.5} ± {:.1e}, gaussian {:.5} ± {:.1e} ({z:.2} σ)",
                fu[0], su[0], fg[0], sg[0]
            );
            assert!(z < 4.0);
            let (ru, _, tu, _) =
                directional_albedo(u.as_ref(), wo, &BsdfContext::IMPORTANCE, 60_000, 8);
            let (rg, rsg, tg, _) =
                directional_albedo(g.as_ref(), wo, &BsdfContext::IMPORTANCE, 60_000, 9);
            assert!(
                (ru[0] - rg[0]).abs() < 5.0 * rsg[0] * 2f64.sqrt() + 1e-9,
                "R {ru:?} vs {rg:?}"
            );
            println!(
                "  albedo uniform R {:.4} T {:.4}, gaussian R {:.4} T {:.4}",
                ru[0], tu[0], rg[0], tg[0]
            );
        }
    }
}

#[test]
fn transmission_obeys_the_generalized_reciprocity() {
    // f(i,o)/η_o² = f(o,i)/η_i² (ERRATA 11) for the walk's higher orders, within Monte Carlo
    // error; the first order is WMLT07's and exact.
    let b = MultipleScatteringDielectric::new(
        RoughDielectric::new(
            1.5,
            Some(lobe(ndf("ggx", 0.9, 0.9))),
            false,
            Spectrum::ONE,
            Spectrum::ONE,
        )
        .unwrap(),
        HeightDistribution::Uniform,
    )
    .unwrap();
    for (k, (a, c)) in [
        (
            spherical_direction(0.4, 0.1),
            -spherical_direction(0.6, 2.2),
        ),
        (
            spherical_direction(1.2, 0.1),
            -spherical_direction(0.2, 0.5),
        ),
        (spherical_direction(0.7, 0.4), spherical_direction(1.0, 3.5)),
    ]
    .into_iter()
    .enumerate()
    {
        let mut rng = Pcg32::new(23, k as u64);
        let n = 150_000;
        let (fac, sac) =
            facette_bsdf::bsdf::mean_and_stderr(n, || b.estimate_orders(a, c, 2, &mut rng));
        let (fca, sca) =
            facette_bsdf::bsdf::mean_and_stderr(n, || b.estimate_orders(c, a, 2, &mut rng));
        let eta = |w: Vec3| -> f64 {
            if w.z > 0.0 {
                1.0
            } else {
                1.5
            }
        };
        let (l, r) = (fac[0] / eta(c).powi(2), fca[0] / eta(a).powi(2));
        let se = (sac[0] / eta(c).powi(2)).hypot(sca[0] / eta(a).powi(2));
        println!("pair {k}: f(i,o)/η_o² = {l:.5}, f(o,i)/η_i² = {r:.5} ± {se:.1e}");
        assert!((l - r).abs() < 4.0 * se, "pair {k}");
    }
}

#[test]
fn bad_combinations_are_clear_errors() {
    let e = material_err(
        r#"{type = "conductor", distribution = "gaussian", sigma = 0.3, scattering = "multiple"}"#,
    );
    assert!(
        e.contains("smith-correlated") && e.contains("gaussian"),
        "{e}"
    );
    let e = material_err(
        r#"{type = "conductor", alpha = 0.3, scattering = "multiple", masking = "smith"}"#,
    );
    assert!(e.contains("smith-correlated"), "{e}");
    let e = material_err(
        r#"{type = "dielectric", alpha = 0.3, scattering = "multiple", energy = "compensated"}"#,
    );
    assert!(e.contains("choose one"), "{e}");
    let e = material_err(r#"{type = "conductor", alpha = 0.3, height_distribution = "gaussian"}"#);
    assert!(e.contains("applies to scattering"), "{e}");
    let e = material_err(r#"{type = "conductor", alpha = 0.3, scattering = "double"}"#);
    assert!(e.contains("single, multiple"), "{e}");
    let e = material_err(r#"{type = "dielectric", alpha = 0.3, energy = "yes"}"#);
    assert!(e.contains("uncompensated, compensated"), "{e}");
    let e = material_err(
        r#"{type = "conductor", alpha = 0.3, scattering = "multiple", height_distribution = "flat"}"#,
    );
    assert!(e.contains("uniform, gaussian"), "{e}");
    let e = material_err(
        r#"{type = "dielectric", alpha = 0.3, scattering = "multiple", sampling = "widened"}"#,
    );
    assert!(e.contains("`sampling` does not apply"), "{e}");
    let e = material_err(
        r#"{type = "conductor", distribution = "phong", exponent = 20, energy = "compensated"}"#,
    );
    assert!(e.contains("beckmann and ggx"), "{e}");
    let e = material_err(r#"{type = "conductor", alpha = 0.3, scatering = "multiple"}"#);
    assert!(e.contains("scattering, energy, height_distribution"), "{e}");
    // A smooth surface has nothing to add: the mirror.
    let b = material(r#"{type = "conductor", alpha = 0, scattering = "multiple"}"#);
    assert!(b.flags().is_delta());
    assert_eq!(
        Distribution::describe(&ndf("ggx", 0.3, 0.3)),
        "ggx(alpha=0.3)"
    );
}

#[test]
fn validation_suite_on_the_new_modes() {
    let r = material_suite_matching(
        &SuiteOptions {
            chi2_samples: 200_000,
            seed: 7,
        },
        // The compensated models: deterministic, checked like every model. The random walks
        // have their own tests above (the suite's statistical checks cost minutes there).
        |m| m.contains("energy = \"compensated\""),
        None,
    );
    for l in r.lines() {
        println!("{l}");
    }
    println!("{}", r.summary_line());
    assert!(r.all_passed(), "failures:\n{}", r.failures().join("\n"));
    assert!(r.passed() > 0);
}

#[test]
fn dielectric_eval_is_one_estimator_for_both_orders_of_a_pair() {
    // The dielectric's walk enters from the more masked direction too: f(a, b)/η_b² and
    // f(b, a)/η_a² (the generalized reciprocity, ERRATA 11) are the same estimate for the
    // same random numbers, to rounding — reflection and transmission, from both sides.
    let eta: f64 = 1.5;
    let b = material(
        r#"{type = "dielectric", distribution = "beckmann", alpha = 0.5, scattering = "multiple"}"#,
    );
    let ctx = BsdfContext::RADIANCE;
    let index = |w: Vec3| -> f64 {
        if w.z > 0.0 {
            1.0
        } else {
            eta
        }
    };
    let dirs = [
        spherical_direction(0.3, 0.4),
        spherical_direction(1.4, 2.0),
        spherical_direction(2.0, -1.0),
        spherical_direction(2.9, 0.7),
    ];
    for (k, x) in dirs.iter().enumerate() {
        for y in dirs.iter().skip(k + 1) {
            for seed in 0..32 {
                let fxy = b.eval(*y, *x, &ctx, &mut Pcg32::new(seed, 3));
                let fyx = b.eval(*x, *y, &ctx, &mut Pcg32::new(seed, 3));
                let (l, r) = (fxy[1] / index(*y).powi(2), fyx[1] / index(*x).powi(2));
                assert!(
                    (l - r).abs() <= 1e-9 * l.abs().max(r.abs()),
                    "{x:?} {y:?}: {l} vs {r}"
                );
            }
        }
    }
}
