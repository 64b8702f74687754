//! Checks of one microfacet distribution: normalization [WMLT07 eq. 4], the projected-area
//! identity [WMLT07 eq. 3], analytic Smith Λ against the numerical integral of IL18 eq. 19,
//! chi-square of every sampler against its pdf, the pdf integrating to one, and finite
//! results on degenerate directions.

use super::chi2::{chi2_test, Chi2Config};
use super::{rel_err, Check, SphereMap, Verdict};
use crate::math::rng::RandomSource;
use crate::math::{spherical_direction, Vec2, Vec3};
use crate::microfacet::beckmann::{g1_exact_of_a, BeckmannG1};
use crate::microfacet::smith_lambda::{
    lambda_isotropic, lambda_isotropic_cut, lambda_numeric, projected_area,
    projected_area_isotropic,
};
use crate::microfacet::{Beckmann, Distribution, Ndf, PhongG1};

/// Options for [`check_distribution`].
#[derive(Clone, Debug)]
pub struct DistributionCheckOptions {
    pub chi2: Chi2Config,
    /// Incidence angles (degrees) for projected area, Λ and visible-normal sampling.
    pub incidences_deg: Vec<f64>,
    /// Tolerance of normalization and projected area (absolute).
    pub area_tol: f64,
    /// Relative tolerance of Λ against its numerical integral.
    pub lambda_tol: f64,
}

impl Default for DistributionCheckOptions {
    fn default() -> Self {
        DistributionCheckOptions {
            chi2: Chi2Config::default(),
            incidences_deg: vec![0.0, 30.0, 60.0, 80.0, 89.0],
            area_tol: 1e-3,
            lambda_tol: 1e-3,
        }
    }
}

/// ∫ D(m) (v·m) dω by the fastest accurate route for this distribution.
fn projected_area_of(dist: &Ndf, v: Vec3) -> f64 {
    let theta_v = v.z.clamp(-1.0, 1.0).acos();
    match dist {
        Ndf::Gaussian(g) => {
            projected_area_isotropic(|t| g.d_theta(t), theta_v, dist.typical_width())
        }
        Ndf::Phong(p) => projected_area_isotropic(|t| p.d_theta(t), theta_v, dist.typical_width()),
        _ => projected_area(dist, v),
    }
}

/// All checks for one distribution.
pub fn check_distribution(dist: &Ndf, opts: &DistributionCheckOptions) -> Vec<Check> {
    let subject = dist.describe();
    let mut out = Vec::new();
    let width = dist.typical_width();
    let aniso = dist.is_anisotropic();
    let phis: &[f64] = if aniso {
        &[0.0, 0.7, std::f64::consts::FRAC_PI_2]
    } else {
        &[0.3]
    };

    // Normalization ∫ D (m·n) dω = 1  [WMLT07 eq. 4].
    let norm = projected_area_of(dist, Vec3::Z);
    out.push(Check::new(
        &subject,
        "normalization ∫D(m)(m·n)dω",
        format!(
            "{norm:.7} (error {:.1e}, tolerance {:.0e})",
            norm - 1.0,
            opts.area_tol
        ),
        Verdict::from_bool((norm - 1.0).abs() <= opts.area_tol),
    ));

    // Projected area ∫ D (v·m) dω = v·n  [WMLT07 eq. 3].
    let mut worst: (f64, f64, f64) = (0.0, 0.0, 0.0);
    for &t in &opts.incidences_deg {
        for &p in phis {
            let v = spherical_direction(t.to_radians(), p);
            let e = projected_area_of(dist, v) - v.z;
            if e.abs() >= worst.0.abs() {
                worst = (e, t, p);
            }
        }
    }
    out.push(Check::new(
        &subject,
        "projected area ∫D(m)(v·m)dω = v·n",
        format!(
            "max error {:.1e} at θ_v = {}° (tolerance {:.0e})",
            worst.0, worst.1, opts.area_tol
        ),
        Verdict::from_bool(worst.0.abs() <= opts.area_tol),
    ));

    out.extend(lambda_checks(dist, opts, phis));
    out.extend(sampler_checks(dist, opts, width, phis));
    out.push(degenerate_check(dist));
    out
}

/// Smith Λ against its numerical integral.
fn lambda_checks(dist: &Ndf, opts: &DistributionCheckOptions, phis: &[f64]) -> Vec<Check> {
    let subject = dist.describe();
    let mut out = Vec::new();
    let thetas: Vec<f64> = opts
        .incidences_deg
        .iter()
        .copied()
        .filter(|&t| t > 0.0)
        .collect();
    match dist {
        Ndf::Gaussian(g) => {
            // The Smith Λ of IL18 eq. 14 diverges: show it.
            let t = 60f64.to_radians();
            let vals: Vec<String> = [1e-2, 1e-4, 1e-6, 1e-8]
                .iter()
                .map(|&eps| format!("{:.4e}", lambda_isotropic_cut(|x| g.d_theta(x), t, eps)))
                .collect();
            out.push(Check::new(
                &subject,
                "Smith Λ(60°) with the θ_m integral cut ε = 1e-2, 1e-4, 1e-6, 1e-8 short of the horizon (diverges; Smith masking rejected)",
                vals.join(", "),
                Verdict::Info,
            ));
        }
        Ndf::Phong(p) => {
            // The tabulated exact Λ against direct integration, and WMLT07's recommended
            // rational G1 against the exact one.
            let numeric = p.clone().with_g1(PhongG1::Numeric);
            let mut worst_table: f64 = 0.0;
            let mut worst_rational: (f64, f64) = (0.0, 0.0);
            for &t in &thetas {
                let tr = t.to_radians();
                let exact = lambda_isotropic(|x| p.d_theta(x), tr);
                let v = spherical_direction(tr, 0.0);
                let tab = numeric.lambda(v);
                worst_table = worst_table.max(lambda_error(tab, exact));
                let g_exact = 1.0 / (1.0 + exact);
                let g_rat = 1.0 / (1.0 + p.lambda_rational(v));
                let e = rel_err(g_rat, g_exact);
                if e > worst_rational.0 {
                    worst_rational = (e, t);
                }
            }
            out.push(Check::new(
                &subject,
                "tabulated Smith Λ vs numerical IL18 eq. 19",
                format!(
                    "max relative error {worst_table:.2e} (tolerance {:.0e})",
                    opts.lambda_tol
                ),
                Verdict::from_bool(worst_table <= opts.lambda_tol),
            ));
            out.push(Check::new(
                &subject,
                "WMLT07's recommended rational G1 vs exact Smith G1 of Phong",
                format!(
                    "max relative error {:.2e} at θ = {}°",
                    worst_rational.0, worst_rational.1
                ),
                Verdict::Info,
            ));
        }
        Ndf::Beckmann(_) | Ndf::Ggx(_) => {
            let analytic = match dist {
                Ndf::Beckmann(b) => Ndf::Beckmann(b.with_g1(BeckmannG1::Exact)),
                other => other.clone(),
            };
            let mut worst: (f64, f64) = (0.0, 0.0);
            for &t in &thetas {
                for &p in phis {
                    let v = spherical_direction(t.to_radians(), p);
                    let e = lambda_error(analytic.lambda(v), lambda_numeric(&analytic, v));
                    if e >= worst.0 {
                        worst = (e, t);
                    }
                }
            }
            out.push(Check::new(
                &subject,
                "analytic Smith Λ vs numerical IL18 eq. 19",
                format!(
                    "max relative error {:.2e} at θ = {}° (tolerance {:.0e})",
                    worst.0, worst.1, opts.lambda_tol
                ),
                Verdict::from_bool(worst.0 <= opts.lambda_tol),
            ));
            if let Ndf::Beckmann(b) = dist {
                if b.g1_form() == BeckmannG1::Rational {
                    let (e, a) = rational_g1_max_error();
                    out.push(Check::new(
                        &subject,
                        "WMLT07 eq. 27 rational G1 vs exact (paper: < 0.35 %)",
                        format!("max relative error {:.3} % at a = {a:.4}", 100.0 * e),
                        Verdict::from_bool(e < 0.0035),
                    ));
                }
            }
        }
    }
    out
}

/// Relative error of Λ, absolute below 1e-9 where Λ is numerically zero.
fn lambda_error(a: f64, b: f64) -> f64 {
    if b.abs() < 1e-9 {
        (a - b).abs()
    } else {
        rel_err(a, b)
    }
}

/// Maximum relative error of WMLT07 eq. 27 over a ∈ (0, 10], on a grid of step 5e-5.
pub fn rational_g1_max_error() -> (f64, f64) {
    let mut worst = (0.0, 0.0);
    for k in 1..=200_000 {
        let a = k as f64 * 5e-5;
        let e = rel_err(Beckmann::g1_rational_of_a(a), g1_exact_of_a(a));
        if e > worst.0 {
            worst = (e, a);
        }
    }
    worst
}

/// Chi-square of the D(m)|m·n| sampler and of the visible-normal sampler.
fn sampler_checks(
    dist: &Ndf,
    opts: &DistributionCheckOptions,
    width: f64,
    phis: &[f64],
) -> Vec<Check> {
    let subject = dist.describe();
    let mut out = Vec::new();
    let map = SphereMap::new(Vec3::Z, (0.5 * width).min(1.0));
    let cfg = opts.chi2;
    let o = chi2_test(
        &map,
        &cfg,
        |r| Some(dist.sample_normal(r.next_2d())),
        |m| dist.pdf_normal(m),
    );
    let name = match dist {
        Ndf::Gaussian(_) => "chi-square: GGX proposal (σ̃ = √2σ) sampler vs pdf_normal",
        _ => "chi-square: D(m)|m·n| sampler vs pdf_normal",
    };
    out.push(Check::chi2(&subject, name, &o));
    out.push(Check::new(
        &subject,
        "∫ pdf_normal dω = 1",
        format!("{:.6}", o.pdf_integral),
        Verdict::from_bool((o.pdf_integral - 1.0).abs() <= 1e-3),
    ));
    if let Ndf::Gaussian(_) = dist {
        // E[D cos / pdf] = ∫ D cos dω = 1 under the proposal.
        let mut rng = crate::math::rng::Pcg32::new(cfg.seed, 99);
        let n = 200_000;
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let m = dist.sample_normal(rng.next_2d());
            let w = dist.d(m) * m.z / dist.pdf_normal(m);
            s += w;
            s2 += w * w;
        }
        let mean = s / n as f64;
        let se = ((s2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
        out.push(Check::new(
            &subject,
            "importance weight D(m)cosθ_m/pdf averages to 1",
            format!("{mean:.5} ± {se:.1e}"),
            Verdict::from_bool((mean - 1.0).abs() <= (4.0 * se).max(1e-3)),
        ));
    }
    if dist.has_visible_sampling() {
        for &t in &opts.incidences_deg {
            let v = spherical_direction(t.to_radians(), phis[phis.len() / 2]);
            let o = chi2_test(
                &map,
                &Chi2Config {
                    seed: cfg.seed ^ (t.to_bits()),
                    ..cfg
                },
                |r| Some(dist.sample_visible(v, r.next_2d())),
                |m| dist.pdf_visible(v, m),
            );
            out.push(Check::chi2(
                &subject,
                format!("chi-square: visible normals at θ_v = {t}° vs pdf_visible"),
                &o,
            ));
            if (o.pdf_integral - 1.0).abs() > 1e-3 {
                out.push(Check::new(
                    &subject,
                    format!("∫ pdf_visible dω = 1 at θ_v = {t}°"),
                    format!("{:.6}", o.pdf_integral),
                    Verdict::Fail,
                ));
            }
        }
    }
    out
}

/// Finite (or +∞ where defined so) results on degenerate inputs.
fn degenerate_check(dist: &Ndf) -> Check {
    let subject = dist.describe();
    let dirs = [
        Vec3::Z,
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 1e-12).normalize(),
        Vec3::new(0.6, 0.8, 0.0),
        Vec3::new(0.3, 0.4, -0.866).normalize(),
        -Vec3::Z,
        Vec3::new(1.0, 1e-300, 1e-300).normalize(),
    ];
    let us = [
        Vec2::new(0.0, 0.0),
        Vec2::new(0.999_999_999_999, 0.5),
        Vec2::new(1.0 - f64::EPSILON, 1.0 - f64::EPSILON),
        Vec2::new(0.5, 0.0),
    ];
    let mut problems = Vec::new();
    for &v in &dirs {
        let d = dist.d(v);
        let l = dist.lambda(v);
        let g = dist.g1(v, Vec3::Z);
        if !(d.is_finite() && d >= 0.0) {
            problems.push(format!("D({v:?}) = {d}"));
        }
        if l.is_nan() || l < 0.0 {
            problems.push(format!("Λ({v:?}) = {l}"));
        }
        if !(0.0..=1.0).contains(&g) {
            problems.push(format!("G1({v:?}) = {g}"));
        }
        for &u in &us {
            let m = dist.sample_normal(u);
            if !(m.is_finite() && m.z >= 0.0) {
                problems.push(format!("sample_normal({u:?}) = {m:?}"));
            }
            let p = dist.pdf_normal(m);
            if !(p.is_finite() && p >= 0.0) {
                problems.push(format!("pdf_normal = {p}"));
            }
            if v.z > 0.0 {
                let mv = dist.sample_visible(v, u);
                let pv = dist.pdf_visible(v, mv);
                if !(mv.is_finite() && mv.z >= 0.0 && pv.is_finite() && pv >= 0.0) {
                    problems.push(format!("sample_visible({v:?}, {u:?}) = {mv:?}, pdf {pv}"));
                }
            }
        }
    }
    Check::new(
        subject,
        "degenerate inputs (normal, grazing, back-facing directions; u at 0 and 1)",
        if problems.is_empty() {
            "all results finite".to_string()
        } else {
            problems.join("; ")
        },
        Verdict::from_bool(problems.is_empty()),
    )
}
