//! Measurements the documentation reports: how far an approximation is from its exact
//! counterpart, and how large sampling weights get.

use crate::bsdf::{Bsdf, BsdfContext};
use crate::math::rng::{mix_seed, Pcg32};
use crate::math::spectrum::Spectrum;
use crate::math::spherical_direction;
use crate::microfacet::specular_lobe::{NormalSampling, SpecularLobe};
use crate::microfacet::{Beckmann, Masking, Ndf};
use crate::models::oren_nayar::IntegralEvaluation;
use crate::models::{OrenNayarExact, OrenNayarQualitative, RoughDielectric};
// The Oren–Nayar comparison evaluates upper-hemisphere pairs only: the one-sided models suffice.
use crate::two_sided::OpaqueBsdf;
use rayon::prelude::*;

/// Error of Oren & Nayar's qualitative model against the exact single-scattering integral
/// (Gaussian, V-cavity) for one σ: (mean relative error, max relative error, where).
#[derive(Clone, Debug)]
pub struct OrenNayarError {
    pub sigma: f64,
    pub mean_rel: f64,
    pub max_rel: f64,
    pub worst: (f64, f64, f64),
}

/// Compares Oren & Nayar's qualitative (or, with `l1`, L1) model with the exact one over
/// θ_i, θ_o ∈ {0, 10, …, 80}° and
/// Δφ ∈ {0, 45, 90, 135, 180}°, the exact one by quadrature with `samples` microfacets.
pub fn oren_nayar_error(sigma: f64, samples: usize, l1: bool) -> OrenNayarError {
    let exact = OrenNayarExact::new(
        Spectrum::ONE,
        sigma,
        IntegralEvaluation::Quadrature { samples },
    )
    .expect("valid");
    let approx = if l1 {
        OrenNayarQualitative::l1(Spectrum::ONE, sigma)
    } else {
        OrenNayarQualitative::new(Spectrum::ONE, sigma)
    }
    .expect("valid");
    let mut cases = Vec::new();
    for ti in (0..=80).step_by(10) {
        for to in (0..=80).step_by(10) {
            for dphi in [0.0f64, 45.0, 90.0, 135.0, 180.0] {
                cases.push((ti as f64, to as f64, dphi));
            }
        }
    }
    let errs: Vec<(f64, (f64, f64, f64))> = cases
        .par_iter()
        .map(|&(ti, to, dphi)| {
            let wi = spherical_direction(ti.to_radians(), 0.0);
            let wo = spherical_direction(to.to_radians(), dphi.to_radians());
            let mut rng = Pcg32::new(1, 1);
            let e = exact.eval(wo, wi, &BsdfContext::RADIANCE, &mut rng)[0];
            let a = approx.eval(wo, wi, &BsdfContext::RADIANCE, &mut rng)[0];
            (((a - e) / e).abs(), (ti, to, dphi))
        })
        .collect();
    let mean = errs.iter().map(|e| e.0).sum::<f64>() / errs.len() as f64;
    let (max, worst) = errs.iter().fold(
        (0.0, (0.0, 0.0, 0.0)),
        |acc, e| if e.0 > acc.0 { *e } else { acc },
    );
    OrenNayarError {
        sigma,
        mean_rel: mean,
        max_rel: max,
        worst,
    }
}

/// Largest sample weight of a rough Beckmann dielectric (importance mode: WMLT07 eq. 41's
/// weight) over incidences 0–89° from both sides, for the paper's sampler or the widened
/// α† one: (max weight, incidence where it occurred in degrees, negative = from inside).
pub fn dielectric_max_weight(
    alpha: f64,
    eta: f64,
    widened: bool,
    samples_per_angle: usize,
) -> (f64, f64) {
    let lobe = SpecularLobe::new(
        Ndf::Beckmann(Beckmann::isotropic(alpha).expect("valid")),
        Masking::SmithSeparable,
        NormalSampling::Distribution,
    )
    .expect("valid");
    let d = RoughDielectric::new(eta, Some(lobe), widened, Spectrum::ONE, Spectrum::ONE)
        .expect("valid");
    let angles: Vec<f64> = (0..90).map(|t| t as f64).flat_map(|t| [t, -t]).collect();
    angles
        .par_iter()
        .map(|&t| {
            let w = spherical_direction(t.abs().to_radians(), 0.3);
            let wo = if t < 0.0 {
                crate::math::Vec3::new(w.x, w.y, -w.z)
            } else {
                w
            };
            let mut rng = Pcg32::new(mix_seed(9, t.to_bits()), 4);
            let mut best: f64 = 0.0;
            for _ in 0..samples_per_angle {
                if let Some(s) = d.sample(wo, &BsdfContext::IMPORTANCE, &mut rng) {
                    best = best.max(s.weight.max_component());
                }
            }
            (best, t)
        })
        .reduce(|| (0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
}

/// Mean of the sample weights of `bsdf` from `wo` in importance mode (its directional
/// albedo) and the standard error.
pub fn mean_weight(
    bsdf: &dyn Bsdf,
    wo: crate::math::Vec3,
    samples: usize,
    seed: u64,
) -> (Spectrum, Spectrum) {
    let mut rng = Pcg32::new(seed, 12);
    crate::bsdf::mean_and_stderr(samples, || {
        bsdf.sample(wo, &BsdfContext::IMPORTANCE, &mut rng)
            .map(|s| s.weight)
            .unwrap_or(Spectrum::ZERO)
    })
}

/// Hemispherical–hemispherical reflectance R = (1/π) ∫∫ f cos θ_i cos θ_o dω_i dω_o
/// = 2 ∫_0^1 a(μ) μ dμ, with the directional albedo a(μ) from `samples` sampled weights at
/// each of 8 Gauss–Legendre nodes in μ = cos θ: (R, standard error), green channel.
pub fn hemispherical_reflectance(bsdf: &dyn Bsdf, samples: usize, seed: u64) -> (f64, f64) {
    let gl = crate::math::quadrature::GaussLegendre::new(8);
    let mut r = 0.0;
    let mut var = 0.0;
    for (k, (&x, &w)) in gl.nodes.iter().zip(&gl.weights).enumerate() {
        let mu = 0.5 * (x + 1.0);
        let wo = crate::math::Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
        let (a, se) = mean_weight(bsdf, wo, samples, mix_seed(seed, k as u64));
        // ∫_0^1 g(μ) dμ = ½ Σ w_k g(μ_k);  R = 2 ∫ a μ dμ = Σ w_k a_k μ_k.
        r += w * a[1] * mu;
        var += (w * mu * se[1]).powi(2);
    }
    (r, var.sqrt())
}
