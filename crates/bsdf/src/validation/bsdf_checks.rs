//! Checks of one BSDF: chi-square of `sample` against `pdf` (globally and zoomed on each
//! lobe), ∫ pdf ≤ 1, `pdf` equal to the density `sample` reports, `sample`'s weight equal to
//! eval·|cos|/pdf, reciprocity (the generalized form f_t(i,o)/η_o² = f_t(o,i)/η_i² across a
//! refractive interface, ERRATA 11), directional albedo ≤ 1 within Monte Carlo error, and a
//! NaN/Inf sweep over random and degenerate directions.
//!
//! Models that sample by a physical random walk (`pdf_is_exact()` false: their `pdf` is a
//! proxy for MIS and no density of the walk exists) replace the chi-square against `pdf` by
//! the chi-square of the weighted sample histogram against the integral of `eval` over each
//! cell ([`estimator_chi2`](super::estimator_chi2)) — which tests both the sampler and the
//! stochastic `eval`, and compares the albedo each of them gives; the proxy must still
//! integrate to at most one and be what `sample` reports.

use super::chi2::{chi2_test_region, expected_probabilities, Chi2Config};
use super::estimator_chi2::{estimator_chi2_test, EstimatorChi2Config};
use super::{rel_err, Check, SphereMap, Verdict};
use crate::bsdf::{Bsdf, BsdfContext, LobeFlags, TransportMode};
use crate::math::rng::{mix_seed, Pcg32, RandomSource};
use crate::math::spectrum::Spectrum;
use crate::math::warp::square_to_uniform_sphere;
use crate::math::{refract, spherical_direction, Vec3};
use rayon::prelude::*;

/// Options for [`check_bsdf`].
#[derive(Clone, Debug)]
pub struct BsdfCheckOptions {
    pub chi2: Chi2Config,
    /// Incidence angles (degrees) of `wo`.
    pub incidences_deg: Vec<f64>,
    /// Azimuth of `wo` (radians), away from the axes so anisotropy shows.
    pub azimuth: f64,
    /// Random direction pairs of the NaN/Inf sweep.
    pub sweep: usize,
    /// Samples per directional albedo.
    pub albedo_samples: usize,
    /// Samples per sample/pdf/eval consistency check.
    pub consistency_samples: usize,
    /// Random pairs of the reciprocity check and its relative tolerance.
    pub reciprocity_pairs: usize,
    pub reciprocity_tol: f64,
    /// Integrand estimates per cell and dimension of the random-walk samplers' chi-square.
    pub estimator_strata: usize,
}

impl Default for BsdfCheckOptions {
    fn default() -> Self {
        BsdfCheckOptions {
            chi2: Chi2Config {
                samples: 400_000,
                ..Chi2Config::default()
            },
            incidences_deg: vec![0.0, 30.0, 60.0, 85.0],
            azimuth: 0.4,
            sweep: 1_000_000,
            albedo_samples: 200_000,
            consistency_samples: 20_000,
            reciprocity_pairs: 4000,
            reciprocity_tol: 1e-4,
            estimator_strata: 32,
        }
    }
}

/// Index of refraction of the side of `w` relative to the outside.
fn side_index(bsdf: &dyn Bsdf, w: Vec3) -> f64 {
    match bsdf.relative_ior() {
        Some(eta) if w.z < 0.0 => eta,
        _ => 1.0,
    }
}

/// The directions `wo` the checks use: the incidences on the front side, and for
/// transmissive models the same on the back side.
fn incident_directions(bsdf: &dyn Bsdf, opts: &BsdfCheckOptions) -> Vec<(String, Vec3)> {
    let mut v = Vec::new();
    for &t in &opts.incidences_deg {
        let w = spherical_direction(t.to_radians(), opts.azimuth);
        v.push((format!("θ_o = {t}°"), w));
    }
    if bsdf.flags().intersects(LobeFlags::TRANSMISSION) {
        for &t in &opts.incidences_deg {
            let w = spherical_direction(t.to_radians(), opts.azimuth);
            v.push((format!("θ_o = {t}° from inside"), Vec3::new(w.x, w.y, -w.z)));
        }
    } else {
        // Opaque models are two-sided: one check from below.
        let w = spherical_direction(30f64.to_radians(), opts.azimuth);
        v.push(("θ_o = 30° from below".into(), Vec3::new(w.x, w.y, -w.z)));
    }
    v
}

/// Every check for one BSDF.
pub fn check_bsdf(bsdf: &dyn Bsdf, opts: &BsdfCheckOptions) -> Vec<Check> {
    check_bsdf_watched(bsdf, opts, &|_, _| true)
}

/// [`check_bsdf`], calling `watch(steps done, steps)` before each step (an incidence, then
/// the reciprocity and NaN/Inf sweeps) and stopping — with the checks done so far — when
/// it returns false: the hook through which the Python package reports progress and
/// stops on Ctrl-C.
pub fn check_bsdf_watched(
    bsdf: &dyn Bsdf,
    opts: &BsdfCheckOptions,
    watch: &dyn Fn(usize, usize) -> bool,
) -> Vec<Check> {
    let subject = bsdf.describe();
    let mut out = Vec::new();
    let dirs = incident_directions(bsdf, opts);
    let ctx = BsdfContext::RADIANCE;
    let width = bsdf.lobe_width();
    let steps = dirs.len() + 2;
    for (k, (label, wo)) in dirs.iter().enumerate() {
        if !watch(k, steps) {
            return out;
        }
        let wo = *wo;
        if bsdf.flags().has_smooth_part() {
            // Broad lobes: one test over the whole sphere. Narrow lobes: one test per side,
            // zoomed on the lobe of that side (reflection about the mirror direction,
            // transmission about the smooth refraction direction).
            let side = wo.z.signum();
            let mut tests: Vec<(String, SphereMap, f64)> = Vec::new();
            if width > 0.0 && width < 0.14 {
                if bsdf.flags().intersects(LobeFlags::REFLECTION) {
                    tests.push((
                        " (reflection side, zoomed on the mirror direction)".into(),
                        SphereMap::new(Vec3::new(-wo.x, -wo.y, wo.z), width),
                        side,
                    ));
                }
                if bsdf.flags().intersects(LobeFlags::TRANSMISSION) {
                    let eta = bsdf.relative_ior().unwrap_or(1.0);
                    let (n, rel) = if wo.z > 0.0 {
                        (Vec3::Z, 1.0 / eta)
                    } else {
                        (-Vec3::Z, eta)
                    };
                    let axis =
                        refract(wo, n, rel).unwrap_or(Vec3::new(wo.x, wo.y, -wo.z).normalize());
                    tests.push((
                        " (transmission side, zoomed on the refraction direction)".into(),
                        SphereMap::new(axis, width),
                        -side,
                    ));
                }
            } else {
                tests.push((String::new(), SphereMap::standard(), 0.0));
            }
            let mut integral = 0.0;
            for (j, (tag, map, region_side)) in tests.iter().enumerate() {
                let cfg = Chi2Config {
                    seed: mix_seed(opts.chi2.seed, (k * 8 + j) as u64),
                    ..opts.chi2
                };
                let rs = *region_side;
                if !bsdf.pdf_is_exact() {
                    let region = |wi: Vec3| rs == 0.0 || wi.z * rs > 0.0;
                    let o = estimator_chi2_test(
                        map,
                        &EstimatorChi2Config {
                            // Coarser cells than the pdf test: each cell's integral is itself
                            // a Monte Carlo estimate, of a heavy-tailed estimator whose variance
                            // 64 points per cell underestimate (measured: the test then fails
                            // consistent models); 32 × 32 points per cell estimate it well.
                            bins: (cfg.bins.0 / 2, cfg.bins.1 / 2),
                            samples: cfg.samples,
                            strata: opts.estimator_strata,
                            seed: cfg.seed,
                        },
                        region,
                        |r| match bsdf.sample(wo, &ctx, r) {
                            Some(s) if !s.lobe.is_delta() => Some((s.wi, s.weight.average())),
                            _ => None,
                        },
                        |wi, r| bsdf.eval(wo, wi, &ctx, r).average() * wi.z.abs(),
                    );
                    integral += expected_probabilities(map, &cfg, &|wi| {
                        if region(wi) {
                            bsdf.pdf(wo, wi, &ctx)
                        } else {
                            0.0
                        }
                    })
                    .iter()
                    .sum::<f64>();
                    out.push(Check::new(
                        &subject,
                        format!("weighted sample histogram vs ∫ eval chi-square at {label}{tag} (random-walk sampler)"),
                        o.summary(),
                        Verdict::Chi2 {
                            p_value: o.p_value,
                            structural_ok: o.invalid == 0,
                        },
                    ));
                    continue;
                }
                let o = chi2_test_region(
                    map,
                    &cfg,
                    |wi| rs == 0.0 || wi.z * rs > 0.0,
                    |r| match bsdf.sample(wo, &ctx, r) {
                        Some(s) if !s.lobe.is_delta() => Some(s.wi),
                        _ => None,
                    },
                    |wi| bsdf.pdf(wo, wi, &ctx),
                );
                integral += o.pdf_integral;
                out.push(Check::chi2(
                    &subject,
                    format!("chi-square at {label}{tag}"),
                    &o,
                ));
            }
            out.push(Check::new(
                &subject,
                if bsdf.pdf_is_exact() {
                    format!("∫ pdf dω ≤ 1 at {label}")
                } else {
                    format!("∫ pdf dω ≤ 1 at {label} (the MIS proxy)")
                },
                format!("{integral:.5}"),
                Verdict::from_bool(integral <= 1.0 + 2e-3),
            ));
            out.push(consistency_check(bsdf, wo, label, opts));
        }
        out.push(albedo_check(bsdf, wo, label, opts));
    }
    if !watch(dirs.len(), steps) {
        return out;
    }
    if bsdf.flags().has_smooth_part() {
        out.push(reciprocity_check(bsdf, opts));
    }
    if !watch(dirs.len() + 1, steps) {
        return out;
    }
    out.push(sweep_check(bsdf, opts));
    watch(steps, steps);
    out
}

/// `pdf(wo, wi)` equals the density `sample` reports, and the weight equals
/// eval·|cos|/pdf, in both transport modes.
fn consistency_check(bsdf: &dyn Bsdf, wo: Vec3, label: &str, opts: &BsdfCheckOptions) -> Check {
    let mut worst_pdf: f64 = 0.0;
    let mut worst_weight: f64 = 0.0;
    let mut n = 0usize;
    for (m, mode) in [TransportMode::Radiance, TransportMode::Importance]
        .iter()
        .enumerate()
    {
        let ctx = BsdfContext {
            mode: *mode,
            ..Default::default()
        };
        let mut rng = Pcg32::new(mix_seed(opts.chi2.seed, 77 + m as u64), 3);
        for _ in 0..opts.consistency_samples {
            let Some(s) = bsdf.sample(wo, &ctx, &mut rng) else {
                continue;
            };
            if s.lobe.is_delta() {
                continue;
            }
            n += 1;
            worst_pdf = worst_pdf.max(rel_err(bsdf.pdf(wo, s.wi, &ctx), s.pdf));
            // A proxy pdf is not the weight's denominator: such weights are tested against
            // ∫ eval by the weighted sample histogram instead.
            if !bsdf.is_stochastic() && bsdf.pdf_is_exact() {
                let f = bsdf.eval(wo, s.wi, &ctx, &mut rng);
                let expect = f * (s.wi.z.abs() / s.pdf);
                for c in 0..3 {
                    let e = if expect[c].abs() < 1e-12 {
                        (s.weight[c] - expect[c]).abs()
                    } else {
                        rel_err(s.weight[c], expect[c])
                    };
                    worst_weight = worst_weight.max(e);
                }
            }
        }
    }
    let ok = worst_pdf <= 1e-6 && worst_weight <= 1e-6;
    let w = if bsdf.is_stochastic() {
        "weight is a stochastic estimate (checked through the albedo)".to_string()
    } else if !bsdf.pdf_is_exact() {
        "weight against ∫ eval by the weighted sample histogram (the pdf is a MIS proxy)"
            .to_string()
    } else {
        format!("weight vs eval·|cos|/pdf max relative error {worst_weight:.1e}")
    };
    Check::new(
        bsdf.describe(),
        format!("sample/pdf/eval consistency at {label}"),
        format!("{n} samples: pdf vs sample's pdf max relative error {worst_pdf:.1e}; {w} (tolerance 1e-6)"),
        Verdict::from_bool(ok),
    )
}

/// Directional albedo (reflectance + transmittance) by the mean sample weight.
pub fn directional_albedo(
    bsdf: &dyn Bsdf,
    wo: Vec3,
    ctx: &BsdfContext,
    samples: usize,
    seed: u64,
) -> (Spectrum, Spectrum, Spectrum, Spectrum) {
    const CHUNKS: usize = 32;
    let per = samples.div_ceil(CHUNKS);
    let parts: Vec<[Spectrum; 4]> = (0..CHUNKS)
        .into_par_iter()
        .map(|c| {
            let mut rng = Pcg32::new(mix_seed(seed, c as u64), 5);
            let mut acc = [Spectrum::ZERO; 4];
            for _ in 0..per {
                if let Some(s) = bsdf.sample(wo, ctx, &mut rng) {
                    let w = s.weight;
                    if s.wi.z * wo.z > 0.0 {
                        acc[0] += w;
                        acc[1] += w * w;
                    } else {
                        acc[2] += w;
                        acc[3] += w * w;
                    }
                }
            }
            acc
        })
        .collect();
    let n = (per * CHUNKS) as f64;
    let mut sum = [Spectrum::ZERO; 4];
    for p in parts {
        for k in 0..4 {
            sum[k] += p[k];
        }
    }
    let stats = |s: Spectrum, s2: Spectrum| {
        let mean = s / n;
        let var = (s2 / n - mean * mean).map(|v| v.max(0.0));
        (mean, (var / n).map(f64::sqrt))
    };
    let (r, rse) = stats(sum[0], sum[1]);
    let (t, tse) = stats(sum[2], sum[3]);
    (r, rse, t, tse)
}

fn albedo_check(bsdf: &dyn Bsdf, wo: Vec3, label: &str, opts: &BsdfCheckOptions) -> Check {
    let (r, rse, t, tse) = directional_albedo(
        bsdf,
        wo,
        &BsdfContext::IMPORTANCE,
        opts.albedo_samples,
        mix_seed(opts.chi2.seed, 991),
    );
    let total = r + t;
    let se = (rse * rse + tse * tse).map(f64::sqrt);
    let mut ok = total.is_finite();
    for c in 0..3 {
        ok &= total[c] <= 1.0 + 3.0 * se[c] + 1e-9 + bsdf.albedo_excess();
    }
    let fig = if bsdf.flags().intersects(LobeFlags::TRANSMISSION) {
        format!(
            "R = {:.4} ± {:.1e}, T = {:.4} ± {:.1e}, R + T = {:.4} (green channel)",
            r[1], rse[1], t[1], tse[1], total[1]
        )
    } else {
        format!(
            "R = {:.4} ± {:.1e} (green channel; max over channels {:.4})",
            r[1],
            rse[1],
            total.max_component()
        )
    };
    let fig = match bsdf.albedo_excess() {
        x if x > 0.0 => format!("{fig}; allowed excess {x:.1e} (tabulated compensation)"),
        _ => fig,
    };
    Check::new(
        bsdf.describe(),
        format!("directional albedo ≤ 1 within 3 standard errors at {label}"),
        fig,
        Verdict::from_bool(ok),
    )
}

fn reciprocity_check(bsdf: &dyn Bsdf, opts: &BsdfCheckOptions) -> Check {
    if bsdf.is_stochastic() {
        return statistical_reciprocity_check(bsdf, opts);
    }
    let mut rng = Pcg32::new(mix_seed(opts.chi2.seed, 4242), 8);
    let transmissive = bsdf.flags().intersects(LobeFlags::TRANSMISSION);
    let mut worst_r: f64 = 0.0;
    let mut worst_t: f64 = 0.0;
    let mut worst_mode: f64 = 0.0;
    let seed = mix_seed(opts.chi2.seed, 17);
    let eval = |a: Vec3, b: Vec3, mode: TransportMode| {
        let mut r = Pcg32::new(seed, 1);
        bsdf.eval(
            a,
            b,
            &BsdfContext {
                mode,
                ..Default::default()
            },
            &mut r,
        )
    };
    let tol = opts.reciprocity_tol;
    for _ in 0..opts.reciprocity_pairs {
        let a = square_to_uniform_sphere(rng.next_2d());
        let mut b = square_to_uniform_sphere(rng.next_2d());
        if !transmissive && a.z * b.z < 0.0 {
            b.z = -b.z;
        }
        let fab = eval(a, b, TransportMode::Radiance);
        let fba = eval(b, a, TransportMode::Radiance);
        if a.z * b.z > 0.0 {
            worst_r = worst_r.max(spectrum_rel_err(fab, fba));
        } else {
            // eval_rad(a, b) = f(i=b, o=a): f(i,o)/η_o² = f(o,i)/η_i².
            let (na, nb) = (side_index(bsdf, a), side_index(bsdf, b));
            worst_t = worst_t.max(spectrum_rel_err(fab / (na * na), fba / (nb * nb)));
            // Importance mode is the adjoint: eval_imp(b, a) = eval_rad(a, b).
            worst_mode =
                worst_mode.max(spectrum_rel_err(fab, eval(b, a, TransportMode::Importance)));
        }
    }
    let ok = worst_r <= tol && worst_t <= tol && worst_mode <= 1e-12;
    let fig = if transmissive {
        format!(
            "{} pairs: BRDF max relative error {worst_r:.1e}; BTDF f_t(i,o)/η_o² vs f_t(o,i)/η_i² {worst_t:.1e}; radiance vs importance adjoint {worst_mode:.1e} (tolerance {tol:.0e})",
            opts.reciprocity_pairs
        )
    } else {
        format!(
            "{} pairs: max relative error {worst_r:.1e} (tolerance {tol:.0e})",
            opts.reciprocity_pairs
        )
    };
    Check::new(bsdf.describe(), "reciprocity", fig, Verdict::from_bool(ok))
}

/// Largest relative difference between two spectra over the channels (0 where both vanish).
fn spectrum_rel_err(x: Spectrum, y: Spectrum) -> f64 {
    (0..3)
        .map(|c| {
            let scale = x[c].abs().max(y[c].abs());
            if scale < 1e-10 {
                0.0
            } else {
                (x[c] - y[c]).abs() / scale
            }
        })
        .fold(0.0, f64::max)
}

/// Reciprocity of a stochastic model within Monte Carlo error: converged estimates of
/// f(a, b) and f(b, a) must agree within 4 combined standard errors. Some estimators have
/// heavy tails (the random walk's next-event estimate, docs/materials.md): rare large values
/// make the sample mean and its standard error both too small for a while. A pair beyond 4
/// standard errors is therefore re-estimated with 8× and then 64× more estimates, and judged
/// on the last: a real violation keeps its distance while its error shrinks.
fn statistical_reciprocity_check(bsdf: &dyn Bsdf, opts: &BsdfCheckOptions) -> Check {
    let pairs = 40usize;
    let samples = 20_000usize;
    let seed = mix_seed(opts.chi2.seed, 4343);
    // (max z over channels, max relative difference) for a pair at n estimates each way.
    let compare = |a: Vec3, b: Vec3, n: usize, rng: &mut Pcg32| -> (f64, f64) {
        let ctx = BsdfContext::RADIANCE;
        let (fab, sab) = bsdf.eval_estimate(a, b, &ctx, n, rng);
        let (fba, sba) = bsdf.eval_estimate(b, a, &ctx, n, rng);
        let mut z: f64 = 0.0;
        let mut rel: f64 = 0.0;
        for c in 0..3 {
            let se = (sab[c] * sab[c] + sba[c] * sba[c]).sqrt();
            let d = (fab[c] - fba[c]).abs();
            if se > 0.0 {
                z = z.max(d / se);
            } else if d > 1e-12 {
                z = f64::INFINITY;
            }
            let scale = fab[c].abs().max(fba[c].abs());
            if scale > 1e-10 {
                rel = rel.max(d / scale);
            }
        }
        (z, rel)
    };
    let results: Vec<(f64, f64, usize)> = (0..pairs)
        .into_par_iter()
        .map(|k| {
            let mut rng = Pcg32::new(mix_seed(seed, k as u64), 8);
            let a = square_to_uniform_sphere(rng.next_2d());
            let mut b = square_to_uniform_sphere(rng.next_2d());
            if a.z * b.z < 0.0 {
                b.z = -b.z;
            }
            let mut n = samples;
            let (mut z, mut rel) = compare(a, b, n, &mut rng);
            while z > 4.0 && n < 64 * samples {
                n *= 8;
                (z, rel) = compare(a, b, n, &mut rng);
            }
            (z, rel, n)
        })
        .collect();
    let worst_z = results.iter().map(|r| r.0).fold(0.0, f64::max);
    let worst_rel = results.iter().map(|r| r.1).fold(0.0, f64::max);
    let escalated = results.iter().filter(|r| r.2 > samples).count();
    // 40 pairs × 3 channels: 4 standard errors keeps the family-wise false alarm below 1 %.
    Check::new(
        bsdf.describe(),
        "reciprocity within Monte Carlo error (stochastic model)",
        format!(
            "{pairs} pairs × {samples} estimates ({escalated} re-estimated with up to 64× more): max |f(a,b) − f(b,a)| = {worst_z:.2} standard errors (tolerance 4), max relative difference {worst_rel:.1e}"
        ),
        Verdict::from_bool(worst_z <= 4.0),
    )
}

/// Directions that stress the code paths: poles, the tangent plane, just above and below it.
pub fn degenerate_directions() -> Vec<Vec3> {
    let mut v = vec![
        Vec3::Z,
        -Vec3::Z,
        Vec3::X,
        Vec3::Y,
        Vec3::new(0.6, 0.8, 0.0),
        Vec3::new(1.0, 0.0, 1e-12).normalize(),
        Vec3::new(1.0, 0.0, -1e-12).normalize(),
        Vec3::new(0.0, 1.0, 1e-300).normalize(),
        Vec3::new(1e-9, 0.0, 1.0).normalize(),
        Vec3::new(-1e-9, 1e-9, -1.0).normalize(),
        spherical_direction(89.999f64.to_radians(), 0.3),
        spherical_direction(45f64.to_radians(), 0.0),
    ];
    let more: Vec<Vec3> = v.iter().map(|d| Vec3::new(-d.x, -d.y, d.z)).collect();
    v.extend(more);
    v
}

fn sweep_check(bsdf: &dyn Bsdf, opts: &BsdfCheckOptions) -> Check {
    let degenerate = degenerate_directions();
    const CHUNKS: usize = 64;
    let per = opts.sweep.div_ceil(CHUNKS);
    let problems: Vec<String> = (0..CHUNKS)
        .into_par_iter()
        .flat_map_iter(|c| {
            let mut rng = Pcg32::new(mix_seed(opts.chi2.seed, 5000 + c as u64), 2);
            let mut probs = Vec::new();
            let mut pairs: Vec<(Vec3, Vec3)> = Vec::new();
            if c == 0 {
                for &a in &degenerate {
                    for &b in &degenerate {
                        pairs.push((a, b));
                    }
                }
            }
            for _ in 0..per {
                pairs.push((
                    square_to_uniform_sphere(rng.next_2d()),
                    square_to_uniform_sphere(rng.next_2d()),
                ));
            }
            for (k, (a, b)) in pairs.into_iter().enumerate() {
                let mode = if k % 2 == 0 {
                    TransportMode::Radiance
                } else {
                    TransportMode::Importance
                };
                let ctx = BsdfContext {
                    mode,
                    ..Default::default()
                };
                let f = bsdf.eval(a, b, &ctx, &mut rng);
                if !f.is_finite() || f.has_negative() {
                    probs.push(format!("eval({a:?}, {b:?}) = {:?}", f.0));
                }
                let p = bsdf.pdf(a, b, &ctx);
                if !(p.is_finite() && p >= 0.0) {
                    probs.push(format!("pdf({a:?}, {b:?}) = {p}"));
                }
                if let Some(s) = bsdf.sample(a, &ctx, &mut rng) {
                    let unit = (s.wi.length() - 1.0).abs() < 1e-9;
                    if !(s.wi.is_finite()
                        && unit
                        && s.weight.is_finite()
                        && !s.weight.has_negative()
                        && s.pdf > 0.0
                        && s.pdf.is_finite())
                    {
                        probs.push(format!("sample({a:?}) = {s:?}"));
                    }
                }
                if probs.len() > 3 {
                    break;
                }
            }
            probs
        })
        .collect();
    let total = opts.sweep + degenerate.len() * degenerate.len();
    let ok = problems.is_empty();
    Check::new(
        bsdf.describe(),
        "NaN/Inf sweep of eval, pdf and sample over random and degenerate directions",
        if ok {
            format!("{total} direction pairs, all finite and non-negative")
        } else {
            problems.into_iter().take(4).collect::<Vec<_>>().join("; ")
        },
        Verdict::from_bool(ok),
    )
}
