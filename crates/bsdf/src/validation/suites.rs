//! Ready-made check suites: the microfacet core (distributions, masking, Fresnel) run by
//! `facette validate` with no material and by the test suite.

use super::chi2::Chi2Config;
use super::distribution_checks::{check_distribution, DistributionCheckOptions};
use super::{rel_err, Check, Report, Verdict};
use crate::fresnel::conductor::{fresnel_conductor_scalar, METALS};
use crate::fresnel::diffuse_averages::{
    external_diffuse_reflectance, external_diffuse_reflectance_numeric,
    internal_diffuse_reflectance, internal_diffuse_reflectance_numeric,
};
use crate::fresnel::schlick::fresnel_schlick_dielectric;
use crate::fresnel::{fresnel_conductor, fresnel_dielectric};
use crate::math::rng::{Pcg32, RandomSource};
use crate::math::spherical_direction;
use crate::math::warp::square_to_uniform_sphere;
use crate::microfacet::{Beckmann, BeckmannG1, Gaussian, Ggx, Masking, Ndf, Phong, PhongG1};
use rayon::prelude::*;

/// Options shared by the suites.
#[derive(Clone, Copy, Debug)]
pub struct SuiteOptions {
    pub chi2_samples: usize,
    pub seed: u64,
}

impl Default for SuiteOptions {
    fn default() -> Self {
        SuiteOptions {
            chi2_samples: 1_000_000,
            seed: 7,
        }
    }
}

/// Distribution families of the core suite.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    Beckmann,
    Ggx,
    Gaussian,
    Phong,
}

/// The distributions the core suite checks: roughness from 0.01 to 1.5, anisotropic pairs.
pub fn distribution_grid(family: Family) -> Vec<Ndf> {
    let alphas = [0.01, 0.1, 0.5, 1.0, 1.5];
    let pairs = [(0.05, 0.5), (1.5, 0.2)];
    match family {
        Family::Beckmann => {
            let mut v: Vec<Ndf> = alphas
                .iter()
                .map(|&a| Ndf::Beckmann(Beckmann::isotropic(a).unwrap()))
                .collect();
            v.extend(
                pairs
                    .iter()
                    .map(|&(x, y)| Ndf::Beckmann(Beckmann::new(x, y).unwrap())),
            );
            v.push(Ndf::Beckmann(
                Beckmann::isotropic(0.3)
                    .unwrap()
                    .with_g1(BeckmannG1::Rational),
            ));
            v
        }
        Family::Ggx => {
            let mut v: Vec<Ndf> = alphas
                .iter()
                .map(|&a| Ndf::Ggx(Ggx::isotropic(a).unwrap()))
                .collect();
            v.extend(
                pairs
                    .iter()
                    .map(|&(x, y)| Ndf::Ggx(Ggx::new(x, y).unwrap())),
            );
            v
        }
        Family::Gaussian => alphas
            .iter()
            .map(|&s| Ndf::Gaussian(Gaussian::new(s).unwrap()))
            .collect(),
        Family::Phong => [0.01, 0.1, 0.5, 1.0]
            .iter()
            .map(|&a| Ndf::Phong(Phong::from_beckmann_alpha(a).unwrap()))
            .chain(std::iter::once(Ndf::Phong(
                Phong::new(20.0).unwrap().with_g1(PhongG1::Numeric),
            )))
            .collect(),
    }
}

/// Checks of every distribution of a family.
pub fn distribution_suite(family: Family, opts: &SuiteOptions) -> Report {
    let dopts = DistributionCheckOptions {
        chi2: Chi2Config {
            samples: opts.chi2_samples,
            seed: opts.seed,
            ..Chi2Config::default()
        },
        ..DistributionCheckOptions::default()
    };
    let mut r = Report::new();
    for d in distribution_grid(family) {
        r.extend(check_distribution(&d, &dopts));
    }
    r
}

/// Fresnel checks: r_e/r_i closed forms against quadrature, the dielectric against its
/// amplitude form and its limits, conductors, Schlick's error.
pub fn fresnel_checks() -> Vec<Check> {
    let mut out = Vec::new();
    let ns = [1.01, 1.2, 1.33, 1.5, 2.0, 3.0];
    let mut worst_e: (f64, f64) = (0.0, 0.0);
    let mut worst_i: (f64, f64) = (0.0, 0.0);
    let mut values = Vec::new();
    for &n in &ns {
        let e = (external_diffuse_reflectance(n) - external_diffuse_reflectance_numeric(n)).abs();
        let i = (internal_diffuse_reflectance(n) - internal_diffuse_reflectance_numeric(n)).abs();
        if e >= worst_e.0 {
            worst_e = (e, n);
        }
        if i >= worst_i.0 {
            worst_i = (i, n);
        }
        values.push(format!("r_e({n}) = {:.6}", external_diffuse_reflectance(n)));
    }
    out.push(Check::new(
        "fresnel",
        "r_e closed form [IL18 eq. 11] vs quadrature, n_i ∈ {1.01, 1.2, 1.33, 1.5, 2, 3}",
        format!(
            "max |error| {:.1e} at n_i = {} (tolerance 1e-5); {}",
            worst_e.0,
            worst_e.1,
            values.join(", ")
        ),
        Verdict::from_bool(worst_e.0 <= 1e-5),
    ));
    out.push(Check::new(
        "fresnel",
        "r_i from n_i²(1 − r_i) = 1 − r_e vs quadrature with total internal reflection",
        format!(
            "max |error| {:.1e} at n_i = {} (tolerance 1e-5)",
            worst_i.0, worst_i.1
        ),
        Verdict::from_bool(worst_i.0 <= 1e-5),
    ));

    // Dielectric: bounds, normal incidence, reciprocity of the two sides, TIR, η → 1.
    let mut problems = Vec::new();
    for &eta in &[1.0 + 1e-9f64, 1.01, 1.33, 1.5, 2.4] {
        let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
        if (fresnel_dielectric(1.0, eta) - f0).abs() > 1e-12 {
            problems.push(format!("F(0°, {eta}) ≠ F0"));
        }
        for k in 0..=90 {
            let ti = (k as f64).to_radians();
            let ci = ti.cos();
            let f = fresnel_dielectric(ci, eta);
            if !(0.0..=1.0).contains(&f) {
                problems.push(format!("F({k}°, {eta}) = {f}"));
            }
            // Same interface seen from inside along the refracted ray gives the same F.
            let st = ti.sin() / eta;
            let ct = (1.0 - st * st).sqrt();
            let back = fresnel_dielectric(ct, 1.0 / eta);
            if k < 90 && (back - f).abs() > 1e-9 {
                problems.push(format!("F inside ≠ outside at {k}°, η = {eta}"));
            }
        }
        let crit = (1.0 / eta).asin();
        if eta > 1.0001 && fresnel_dielectric((crit + 0.01).cos(), 1.0 / eta) != 1.0 {
            problems.push(format!("no TIR beyond the critical angle for η = {eta}"));
        }
    }
    out.push(Check::new(
        "fresnel",
        "dielectric [WMLT07 eq. 22]: 0 ≤ F ≤ 1, F(0°) = ((η−1)/(η+1))², same F from both sides, TIR, η → 1",
        if problems.is_empty() { "all hold".into() } else { problems.join("; ") },
        Verdict::from_bool(problems.is_empty()),
    ));

    let mut problems = Vec::new();
    for k in 0..=100 {
        let c = k as f64 / 100.0;
        if (fresnel_conductor_scalar(c, 1.5, 0.0) - fresnel_dielectric(c, 1.5)).abs() > 1e-12 {
            problems.push(format!("k = 0 differs from dielectric at cos {c}"));
        }
        for m in METALS {
            let f = fresnel_conductor(c, m.eta(), m.k());
            if !(f.min_component() >= 0.0 && f.max_component() <= 1.0) {
                problems.push(format!("{} out of [0,1] at cos {c}", m.name));
            }
        }
    }
    out.push(Check::new(
        "fresnel",
        "conductor: reduces to the dielectric when k = 0; presets within [0, 1]",
        if problems.is_empty() {
            "all hold".into()
        } else {
            problems.join("; ")
        },
        Verdict::from_bool(problems.is_empty()),
    ));

    let mut worst: (f64, f64) = (0.0, 0.0);
    for k in 0..=900 {
        let c = (k as f64 / 10.0).to_radians().cos();
        let e = (fresnel_schlick_dielectric(c, 1.5) - fresnel_dielectric(c, 1.5)).abs();
        if e > worst.0 {
            worst = (e, k as f64 / 10.0);
        }
    }
    out.push(Check::new(
        "fresnel",
        "Schlick vs exact for η = 1.5",
        format!("max |error| {:.4} at θ = {}°", worst.0, worst.1),
        Verdict::Info,
    ));
    out
}

/// Masking checks on random configurations: bounds, symmetry, sidedness.
pub fn masking_checks(seed: u64) -> Vec<Check> {
    let dists = [
        Ndf::Beckmann(Beckmann::new(0.3, 0.8).unwrap()),
        Ndf::Ggx(Ggx::new(0.05, 0.5).unwrap()),
        Ndf::Phong(Phong::new(30.0).unwrap()),
        Ndf::Gaussian(Gaussian::new(0.4).unwrap()),
    ];
    let forms = [
        Masking::SmithSeparable,
        Masking::SmithCorrelated,
        Masking::VCavity,
        Masking::Kelemen,
    ];
    forms
        .par_iter()
        .map(|mk| {
            let mut rng = Pcg32::new(seed, 11);
            let mut problems = Vec::new();
            let mut evaluated = 0usize;
            for d in &dists {
                if mk.is_smith() && !d.supports_smith() {
                    continue;
                }
                for _ in 0..100_000 {
                    let i = square_to_uniform_sphere(rng.next_2d());
                    let o = square_to_uniform_sphere(rng.next_2d());
                    let m = spherical_direction(
                        rng.next_f64() * 1.5,
                        rng.next_f64() * std::f64::consts::TAU,
                    );
                    let g = mk.g(d, i, o, m);
                    let g2 = mk.g(d, o, i, m);
                    evaluated += 1;
                    let sided = (i.dot(m) * i.z > 0.0) && (o.dot(m) * o.z > 0.0);
                    if !(0.0..=1.0).contains(&g) {
                        problems.push(format!("G = {g}"));
                    } else if rel_err(g, g2) > 1e-12 && (g - g2).abs() > 1e-15 {
                        problems.push(format!("G not symmetric: {g} vs {g2}"));
                    } else if !sided && g != 0.0 {
                        problems.push("G > 0 for a back-facing configuration".into());
                    }
                    if problems.len() > 3 {
                        break;
                    }
                }
            }
            Check::new(
                format!("masking {}", mk.name()),
                "0 ≤ G ≤ 1, G(i,o,m) = G(o,i,m), G = 0 on back-facing m (WMLT07 eqs. 5–7)",
                if problems.is_empty() {
                    format!("{evaluated} random configurations hold")
                } else {
                    problems.join("; ")
                },
                Verdict::from_bool(problems.is_empty()),
            )
        })
        .collect()
}

/// The whole core suite, optionally restricted to one family.
pub fn core_suite(opts: &SuiteOptions, only: Option<Family>) -> Report {
    let mut r = Report::new();
    for fam in [
        Family::Beckmann,
        Family::Ggx,
        Family::Gaussian,
        Family::Phong,
    ] {
        if only.is_none() || only == Some(fam) {
            r.extend(distribution_suite(fam, opts).checks);
        }
    }
    if only.is_none() {
        r.extend(masking_checks(opts.seed));
        r.extend(fresnel_checks());
    }
    r
}

/// The material grid of the reference-BSDF suite: every model, rough and near-smooth,
/// isotropic and anisotropic, every distribution and masking where the model allows it.
pub fn material_grid() -> Vec<&'static str> {
    vec![
        r#"{type = "lambert", reflectance = [0.2, 0.5, 0.9]}"#,
        r#"{type = "oren-nayar", sigma = 0.1, reflectance = 0.8}"#,
        r#"{type = "oren-nayar", sigma = 0.5, evaluation = "stochastic"}"#,
        r#"{type = "oren-nayar", sigma = 1.0, samples = 64}"#,
        r#"{type = "oren-nayar", sigma = 0.3, model = "qualitative"}"#,
        r#"{type = "oren-nayar", sigma = 1.0, model = "qualitative", reflectance = 1.0}"#,
        r#"{type = "conductor", distribution = "beckmann", alpha = 0.02, material = "Au"}"#,
        r#"{type = "conductor", distribution = "beckmann", alpha = 0.3}"#,
        r#"{type = "conductor", distribution = "beckmann", alpha = 1.0, sampling = "distribution"}"#,
        r#"{type = "conductor", distribution = "ggx", alpha = 0.02}"#,
        r#"{type = "conductor", distribution = "ggx", alpha = 0.1, material = "Cu"}"#,
        r#"{type = "conductor", distribution = "ggx", alpha = 1.0, masking = "smith-correlated"}"#,
        r#"{type = "conductor", distribution = "ggx", alpha_u = 0.05, alpha_v = 0.4, material = "Al"}"#,
        r#"{type = "conductor", distribution = "beckmann", alpha_u = 0.4, alpha_v = 0.05, sampling = "distribution"}"#,
        r#"{type = "conductor", distribution = "beckmann", alpha = 0.3, masking = "v-cavity"}"#,
        r#"{type = "conductor", distribution = "beckmann", alpha = 0.3, masking = "kelemen", g1 = "rational"}"#,
        r#"{type = "conductor", distribution = "gaussian", sigma = 0.3}"#,
        r#"{type = "conductor", distribution = "phong", exponent = 100, material = "Ag"}"#,
        r#"{type = "conductor", distribution = "phong", exponent = 10, g1 = "numeric"}"#,
        r#"{type = "conductor", alpha = 0, material = "Cr"}"#,
        // The random walks (scattering = "multiple") are not in the grid: their statistical
        // checks need targeted settings (tests/multiple_scattering.rs, docs/materials.md on
        // the heavy tails of their eval).
        r#"{type = "conductor", distribution = "ggx", alpha = 1.0, material = "Cu", energy = "compensated"}"#,
        r#"{type = "conductor", distribution = "beckmann", alpha = 0.1, masking = "smith-correlated", energy = "compensated"}"#,
        r#"{type = "dielectric", distribution = "beckmann", alpha = 0.02}"#,
        r#"{type = "dielectric", distribution = "beckmann", alpha = 0.3, sampling = "distribution"}"#,
        r#"{type = "dielectric", distribution = "beckmann", alpha = 0.3, sampling = "widened"}"#,
        r#"{type = "dielectric", distribution = "beckmann", alpha = 1.0}"#,
        r#"{type = "dielectric", distribution = "ggx", alpha = 0.02, ior = 1.33}"#,
        r#"{type = "dielectric", distribution = "ggx", alpha = 0.1}"#,
        r#"{type = "dielectric", distribution = "ggx", alpha = 0.3, masking = "smith-correlated"}"#,
        // Issue 18's grazing case: GGX glass α = 0.7, checked like every entry at 85° from
        // both sides.
        r#"{type = "dielectric", distribution = "ggx", alpha = 0.7}"#,
        r#"{type = "dielectric", distribution = "ggx", alpha = 1.0, sampling = "distribution"}"#,
        r#"{type = "dielectric", distribution = "ggx", alpha_u = 0.05, alpha_v = 0.4}"#,
        r#"{type = "dielectric", preset = "ground", distribution = "ggx"}"#,
        r#"{type = "dielectric", alpha = 0, ior = 1.5}"#,
        r#"{type = "dielectric", distribution = "ggx", alpha = 0.5, energy = "compensated"}"#,
        r#"{type = "dielectric", distribution = "beckmann", alpha = 1.0, ior = 1.33, masking = "smith-correlated", specular_transmittance = [0.9, 0.8, 0.7], energy = "compensated"}"#,
        r#"{type = "kelemen", distribution = "ward", alpha = 0.05, kd = 0.7, table_samples = 4096}"#,
        r#"{type = "kelemen", distribution = "ward", alpha = 0.8, kd = [0.9, 0.5, 0.2], table_samples = 4096}"#,
        r#"{type = "kelemen", distribution = "beckmann", alpha = 0.3, table_samples = 4096}"#,
        r#"{type = "kelemen", distribution = "phong", exponent = 40, ior = 1.7, table_samples = 4096}"#,
        r#"{type = "il", kd = 0.8, ni = 1.5, alpha = 0}"#,
        r#"{type = "il", kd = [0.9, 0.5, 0.1], ni = 2.0, alpha = 0}"#,
        r#"{type = "il", kd = 0.6, ni = 1.0, distribution = "gaussian", sigma = 0.5}"#,
        r#"{type = "il", kd = 0.6, ni = 1.2, distribution = "gaussian", sigma = 0.05, evaluation = "quadrature", samples = 32}"#,
        r#"{type = "il", kd = 0.9, ni = 1.5, distribution = "beckmann", alpha = 0.07}"#,
        r#"{type = "il", kd = 0.5, ni = 2.0, distribution = "beckmann", alpha = 0.7, masking = "smith", evaluation = "quadrature", samples = 32}"#,
        r#"{type = "il", kd = 0.7, ni = 1.5, distribution = "ggx", alpha = 1.0}"#,
        r#"{type = "il", kd = 0.7, ni = 1.5, distribution = "ggx", alpha_u = 0.05, alpha_v = 0.4}"#,
        r#"{type = "il", kd = 0.7, ni = 1.2, distribution = "beckmann", alpha_u = 0.6, alpha_v = 0.2, masking = "v-cavity"}"#,
        r#"{type = "il", kd = 1.0, ni = 1.5, distribution = "beckmann", alpha = 0.5, scattering = "double"}"#,
        r#"{type = "il", kd = [1.0, 0.6, 0.3], ni = 1.5, distribution = "beckmann", alpha = 1.0, scattering = "multiple"}"#,
        r#"{type = "il", kd = 0.8, ni = 1.33, distribution = "gaussian", sigma = 0.3, scattering = "multiple"}"#,
    ]
}

/// True for the grid entries of the energy options of conductors and dielectrics (`energy =
/// "compensated"`; `scattering = "multiple"` too, were one added), which have their own test
/// (tests/multiple_scattering.rs). Note that IL's `scattering = "multiple"` matches as well.
pub fn is_energy_option(material: &str) -> bool {
    material.contains("scattering = \"multiple\"") || material.contains("energy = \"compensated\"")
}

/// Checks of every material of [`material_grid`] whose TOML contains `filter` (all when
/// `None`).
pub fn material_suite(opts: &SuiteOptions, filter: Option<&str>) -> Report {
    material_suite_matching(opts, |m| filter.is_none_or(|f| m.contains(f)), None)
}

/// Checks of the materials of [`material_grid`] that `select` accepts; `sweep` overrides the
/// number of random pairs of the NaN/Inf sweep (the random-walk models cost a few µs per
/// evaluation).
pub fn material_suite_matching(
    opts: &SuiteOptions,
    select: impl Fn(&str) -> bool,
    sweep: Option<usize>,
) -> Report {
    use super::bsdf_checks::{check_bsdf, BsdfCheckOptions};
    let defaults = BsdfCheckOptions::default();
    let bopts = BsdfCheckOptions {
        chi2: Chi2Config {
            samples: opts.chi2_samples,
            seed: opts.seed,
            ..Chi2Config::default()
        },
        sweep: sweep.unwrap_or(defaults.sweep),
        ..defaults
    };
    let mut r = Report::new();
    for m in material_grid() {
        if !select(m) {
            continue;
        }
        let table = crate::recipe::parse_inline_table(m).expect("grid entries parse");
        let bsdf = crate::recipe::build_material(&table).expect("grid entries build");
        r.extend(check_bsdf(bsdf.as_ref(), &bopts));
    }
    r
}
