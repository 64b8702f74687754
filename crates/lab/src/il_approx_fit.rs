//! The fitting program of the approximate interfaced-Lambertian body term (IL18 §4.2,
//! rebuilt because its appendix is missing — ERRATA 1). `facette il-approx fit` runs it and
//! regenerates `crates/bsdf/src/models/il/il_approx_coefficients.rs`; `facette il-approx
//! accuracy` measures the result against the quadrature.
//!
//! For every node of the (σ, n_i) grid of a family (Gaussian/V-cavity, Beckmann/V-cavity,
//! Beckmann/Smith) the body integral is computed by quadrature (randomized QMC with
//! `samples` microfacets) on θ_i, θ_o ∈ {0, 10, …, 80}°, Δφ ∈ {0, 45, …, 180}°, and the
//! structure's free coefficients are fitted by Levenberg–Marquardt on the log error:
//! first, at n_i = 1, the scales of Oren & Nayar's L1 coefficients for Beckmann facets (the
//! Gaussian uses Oren & Nayar's own, unscaled); then a, b, k at every n_i > 1 with those
//! fixed. Nodes with σ = 0 or n_i = 1
//! keep the exact limits (a = 1, b = 0, k = 0).

use crate::least_squares::minimize;
use facette_bsdf::fresnel::external_diffuse_reflectance;
use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::math::{spherical_direction, Vec3};
use facette_bsdf::microfacet::specular_lobe::{NormalSampling, SpecularLobe};
use facette_bsdf::microfacet::{Beckmann, Gaussian, Masking, Ndf};
use facette_bsdf::models::il::il_approx::{
    approx_integral, ApproxCoefficients, ApproxFamily, IlApprox,
};
use facette_bsdf::models::il::il_approx_coefficients::{NI_NODES, SIGMA_NODES};
use facette_bsdf::models::il::interfaced_lambertian::{BodyEvaluation, Scattering};
use facette_bsdf::models::InterfacedLambertian;
use facette_bsdf::Spectrum;
use rayon::prelude::*;

/// One fitted node.
#[derive(Clone, Debug)]
pub struct NodeFit {
    pub sigma: f64,
    pub ni: f64,
    /// (a, b, k).
    pub params: [f64; 3],
    /// Mean and maximum relative error over the fitting directions.
    pub mean_rel: f64,
    pub max_rel: f64,
}

/// A family's fit: nodes `[σ][n_i]` and the L1 scales per σ.
#[derive(Clone, Debug)]
pub struct FamilyFit {
    pub family: ApproxFamily,
    pub nodes: Vec<Vec<NodeFit>>,
    pub on: Vec<[f64; 3]>,
}

/// The microfacet lobe of a family at Gaussian-equivalent roughness σ.
pub fn lobe_for(family: ApproxFamily, sigma: f64) -> SpecularLobe {
    let (ndf, masking) = match family {
        ApproxFamily::GaussianVCavity => (
            Ndf::Gaussian(Gaussian::new(sigma).expect("σ in range")),
            Masking::VCavity,
        ),
        ApproxFamily::BeckmannVCavity => (
            Ndf::Beckmann(
                Beckmann::isotropic(std::f64::consts::SQRT_2 * sigma).expect("α in range"),
            ),
            Masking::VCavity,
        ),
        ApproxFamily::BeckmannSmith => (
            Ndf::Beckmann(
                Beckmann::isotropic(std::f64::consts::SQRT_2 * sigma).expect("α in range"),
            ),
            Masking::SmithSeparable,
        ),
    };
    SpecularLobe::new(ndf, masking, NormalSampling::Distribution).expect("valid lobe")
}

/// Direction pairs (i, o) of a grid: θ_i, θ_o over `thetas` (degrees), Δφ over `phis`.
pub fn direction_grid(thetas: &[f64], phis: &[f64]) -> Vec<(Vec3, Vec3)> {
    let mut v = Vec::new();
    for &ti in thetas {
        for &to in thetas {
            for &p in phis {
                v.push((
                    spherical_direction(ti.to_radians(), 0.0),
                    spherical_direction(to.to_radians(), p.to_radians()),
                ));
            }
        }
    }
    v
}

/// The fitting directions.
pub fn fit_directions() -> Vec<(Vec3, Vec3)> {
    let thetas: Vec<f64> = (0..=8).map(|k| 10.0 * k as f64).collect();
    direction_grid(&thetas, &[0.0, 45.0, 90.0, 135.0, 180.0])
}

/// Quadrature body integrals of a family at (σ, n_i) on `dirs`.
pub fn exact_integrals(
    family: ApproxFamily,
    sigma: f64,
    ni: f64,
    dirs: &[(Vec3, Vec3)],
    samples: usize,
) -> Vec<f64> {
    let il = InterfacedLambertian::new(
        Spectrum::splat(0.5),
        ni,
        Some(lobe_for(family, sigma)),
        BodyEvaluation::Quadrature { samples },
        Scattering::Single,
    )
    .expect("valid material");
    let mut rng = Pcg32::new(1, 1);
    dirs.iter()
        .map(|&(i, o)| il.body_integral(i, o, 0, &mut rng).0)
        .collect()
}

fn rel_errors(
    c: &ApproxCoefficients,
    dirs: &[(Vec3, Vec3)],
    exact: &[f64],
    ni: f64,
    re: f64,
) -> (f64, f64) {
    let mut sum = 0.0;
    let mut max: f64 = 0.0;
    let mut n = 0usize;
    for (&(i, o), &e) in dirs.iter().zip(exact) {
        if e <= 1e-12 {
            continue;
        }
        let r = ((approx_integral(c, i, o, ni, re) - e) / e).abs();
        sum += r;
        max = max.max(r);
        n += 1;
    }
    (sum / n.max(1) as f64, max)
}

/// Fits one family over the whole grid. `progress(done, total)` counts nodes.
pub fn fit_family(
    family: ApproxFamily,
    samples: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> FamilyFit {
    let dirs = fit_directions();
    let total = SIGMA_NODES.len() * NI_NODES.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let per_sigma: Vec<(Vec<NodeFit>, [f64; 3])> = SIGMA_NODES
        .par_iter()
        .map(|&sigma| {
            if sigma == 0.0 {
                let nodes = NI_NODES
                    .iter()
                    .map(|&ni| NodeFit {
                        sigma,
                        ni,
                        params: [1.0, 0.0, 0.0],
                        mean_rel: 0.0,
                        max_rel: 0.0,
                    })
                    .collect();
                done.fetch_add(NI_NODES.len(), std::sync::atomic::Ordering::Relaxed);
                return (nodes, [1.0, 1.0, 1.0]);
            }
            // The Oren–Nayar-shaped term at n_i = 1.
            let lambertian = exact_integrals(family, sigma, 1.0, &dirs, samples);
            let on = match family {
                ApproxFamily::GaussianVCavity => [1.0, 1.0, 1.0],
                _ => {
                    let fit = minimize(&[1.0, 1.0, 1.0], |p| {
                        let c = ApproxCoefficients {
                            sigma,
                            a: 1.0,
                            b: 0.0,
                            k: 0.0,
                            on: [p[0], p[1], p[2]],
                        };
                        log_residuals(&c, &dirs, &lambertian, 1.0, 0.0)
                    });
                    [fit.params[0], fit.params[1], fit.params[2]]
                }
            };
            let nodes = NI_NODES
                .iter()
                .map(|&ni| {
                    let re = external_diffuse_reflectance(ni);
                    let exact = if ni == 1.0 {
                        lambertian.clone()
                    } else {
                        exact_integrals(family, sigma, ni, &dirs, samples)
                    };
                    let params = if ni == 1.0 {
                        [1.0, 0.0, 0.0]
                    } else {
                        let fit = minimize(&[1.0, 0.0, 0.0], |p| {
                            let c = ApproxCoefficients {
                                sigma,
                                a: p[0],
                                b: p[1],
                                k: p[2],
                                on,
                            };
                            log_residuals(&c, &dirs, &exact, ni, re)
                        });
                        [fit.params[0], fit.params[1], fit.params[2]]
                    };
                    let c = ApproxCoefficients {
                        sigma,
                        a: params[0],
                        b: params[1],
                        k: params[2],
                        on,
                    };
                    let (mean_rel, max_rel) = rel_errors(&c, &dirs, &exact, ni, re);
                    let d = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                    progress(d, total);
                    NodeFit {
                        sigma,
                        ni,
                        params,
                        mean_rel,
                        max_rel,
                    }
                })
                .collect();
            (nodes, on)
        })
        .collect();
    FamilyFit {
        family,
        nodes: per_sigma.iter().map(|p| p.0.clone()).collect(),
        on: per_sigma.iter().map(|p| p.1).collect(),
    }
}

fn log_residuals(
    c: &ApproxCoefficients,
    dirs: &[(Vec3, Vec3)],
    exact: &[f64],
    ni: f64,
    re: f64,
) -> Vec<f64> {
    dirs.iter()
        .zip(exact)
        .map(|(&(i, o), &e)| {
            let a = approx_integral(c, i, o, ni, re).max(1e-12);
            if e > 1e-12 {
                a.ln() - e.ln()
            } else {
                0.0
            }
        })
        .collect()
}

/// Renders the fitted families as the Rust source of `il_approx_coefficients.rs`.
pub fn coefficients_source(fits: &[FamilyFit], samples: usize) -> String {
    let table = |f: &FamilyFit| {
        let mut s = String::from("[\n");
        for row in &f.nodes {
            s += "    [";
            s += &row
                .iter()
                .map(|n| {
                    format!(
                        "[{:.8}, {:.8}, {:.8}]",
                        n.params[0], n.params[1], n.params[2]
                    )
                })
                .collect::<Vec<_>>()
                .join(", ");
            s += "],\n";
        }
        s + "]"
    };
    let on = |f: &FamilyFit| {
        let mut s = String::from("[\n");
        for ab in &f.on {
            s += &format!("    [{:.8}, {:.8}, {:.8}],\n", ab[0], ab[1], ab[2]);
        }
        s + "]"
    };
    let get = |fam: ApproxFamily| {
        fits.iter()
            .find(|f| f.family == fam)
            .expect("all families fitted")
    };
    let (g, bv, bs) = (
        get(ApproxFamily::GaussianVCavity),
        get(ApproxFamily::BeckmannVCavity),
        get(ApproxFamily::BeckmannSmith),
    );
    let (ns, nn) = (SIGMA_NODES.len(), NI_NODES.len());
    format!(
        "//! Fitted coefficients of the approximate IL body term (see `il_approx`). GENERATED by\n\
         //! `facette il-approx fit --samples {samples}`; do not edit by hand.\n\n\
         /// Gaussian-equivalent roughness nodes σ (radians).\n\
         pub const SIGMA_NODES: [f64; {ns}] = {:?};\n\
         /// Relative index nodes n_i.\n\
         pub const NI_NODES: [f64; {nn}] = {:?};\n\n\
         /// [σ][n_i] → [a, b, k].\n\
         pub const GAUSSIAN_VCAVITY: [[[f64; 3]; {nn}]; {ns}] = {};\n\
         pub const BECKMANN_VCAVITY: [[[f64; 3]; {nn}]; {ns}] = {};\n\
         pub const BECKMANN_SMITH: [[[f64; 3]; {nn}]; {ns}] = {};\n\n\
         /// [σ] → scales of Oren–Nayar's L1 coefficients (C1's σ term, C2, C3) for Beckmann facets.\n\
         pub const BECKMANN_VCAVITY_ON: [[f64; 3]; {ns}] = {};\n\
         pub const BECKMANN_SMITH_ON: [[f64; 3]; {ns}] = {};\n",
        SIGMA_NODES,
        NI_NODES,
        table(g),
        table(bv),
        table(bs),
        on(bv),
        on(bs)
    )
}

/// Error statistics of the approximation at one (σ, n_i).
#[derive(Clone, Copy, Debug)]
pub struct Accuracy {
    pub mean: f64,
    pub p95: f64,
    pub max: f64,
}

/// Accuracy of the shipped approximation against the quadrature at roughness `sigma` and
/// index `ni`, off the fitting grid (θ_i, θ_o ∈ {5, 15, …, 85}°, Δφ ∈ {0, 30, …, 180}°):
/// mean, 95th percentile and maximum of the relative error.
pub fn accuracy(family: ApproxFamily, sigma: f64, ni: f64, samples: usize) -> Accuracy {
    let thetas: Vec<f64> = (0..9).map(|k| 5.0 + 10.0 * k as f64).collect();
    let dirs = direction_grid(&thetas, &[0.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0]);
    let exact = exact_integrals(family, sigma, ni, &dirs, samples);
    let approx = IlApprox::for_family(family, sigma, ni).expect("inside the fitted domain");
    let re = external_diffuse_reflectance(ni);
    let mut errs: Vec<f64> = dirs
        .iter()
        .zip(&exact)
        .filter(|(_, &e)| e > 1e-12)
        .map(|(&(i, o), &e)| ((approx.body_integral(i, o, ni, re) - e) / e).abs())
        .collect();
    errs.sort_by(f64::total_cmp);
    let n = errs.len().max(1);
    Accuracy {
        mean: errs.iter().sum::<f64>() / n as f64,
        p95: errs[((0.95 * n as f64) as usize).min(n - 1)],
        max: *errs.last().unwrap_or(&0.0),
    }
}
