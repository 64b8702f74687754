//! Interfaced Lambertian as a fitting family [IL18 §5, Fig. 19]: parameters K_d (RGB),
//! n_i and the Gaussian-equivalent roughness σ (radians; Beckmann and GGX use α = √2 σ,
//! ERRATA 6). IL18 fits "IL, Beckm, SB" — Beckmann with Smith masking — which is the
//! default; the Gaussian uses the V-cavity masking of IL18 Table 2.
//!
//! f = f_s + K_d/(π n_i² (1 − K_d r_i)) · I(i, o; n_i, σ)  [IL18 eqs. 4, 13]: the specular
//! lobe and the body integral I depend on (n_i, σ) only, so they are computed once per
//! (n_i, σ) and reused while K_d varies — three of the six Jacobian columns come for free.
//! I is evaluated deterministically: by quadrature with a fixed microfacet set
//! (randomized QMC with a fixed seed, so the objective is a smooth function of the
//! parameters) or by the approximate closed form of IL18 §4.2.

use super::family::{ModelFamily, Parameter};
use super::samples::FitSample;
use facette_bsdf::fresnel::{fresnel_dielectric, internal_diffuse_reflectance};
use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::microfacet::specular_lobe::{NormalSampling, SpecularLobe};
use facette_bsdf::microfacet::{Beckmann, Gaussian, Ggx, Masking, Ndf};
use facette_bsdf::models::il::il_approx::IlApprox;
use facette_bsdf::models::il::interfaced_lambertian::{BodyEvaluation, Scattering};
use facette_bsdf::models::InterfacedLambertian;
use facette_bsdf::{ParamError, Spectrum};
use rayon::prelude::*;
use std::f64::consts::{PI, SQRT_2};
use std::sync::{Arc, Mutex};

/// The microfacet distribution of the fitted IL.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IlDistribution {
    /// Beckmann, α = √2 σ, Smith masking (IL18 Fig. 19's "Beckm, SB").
    Beckmann,
    /// GGX, α = √2 σ, Smith masking.
    Ggx,
    /// Gaussian of width σ with V-cavity masking (Oren–Nayar's).
    Gaussian,
}

impl IlDistribution {
    pub const NAMES: &'static [&'static str] = &["beckmann", "ggx", "gaussian"];

    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "beckmann" => Some(IlDistribution::Beckmann),
            "ggx" => Some(IlDistribution::Ggx),
            "gaussian" => Some(IlDistribution::Gaussian),
            _ => None,
        }
    }

    pub fn name(&self) -> &'static str {
        Self::NAMES[*self as usize]
    }

    /// The specular lobe at Gaussian-equivalent roughness σ.
    pub fn lobe(&self, sigma: f64) -> Result<SpecularLobe, ParamError> {
        let (ndf, masking) = match self {
            IlDistribution::Beckmann => (
                Ndf::Beckmann(Beckmann::isotropic(SQRT_2 * sigma)?),
                Masking::SmithSeparable,
            ),
            IlDistribution::Ggx => (
                Ndf::Ggx(Ggx::isotropic(SQRT_2 * sigma)?),
                Masking::SmithSeparable,
            ),
            IlDistribution::Gaussian => (Ndf::Gaussian(Gaussian::new(sigma)?), Masking::VCavity),
        };
        SpecularLobe::new(ndf, masking, NormalSampling::Distribution)
    }
}

/// How the body integral is evaluated while fitting.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IlFitEvaluation {
    /// Quadrature with this many microfacets (fixed seed).
    Quadrature(usize),
    /// The approximate closed form [IL18 §4.2].
    Approx,
}

/// Per-sample specular value (scalar: the interface is achromatic) and body integral.
type Parts = Vec<(f64, f64)>;

/// The parts of the last (n_i, σ, sample set) evaluated.
type CachedParts = ((u64, u64, u64), Arc<Parts>);

/// A fingerprint of a sample set's directions (FNV-1a over their bits): the cache must not
/// serve the parts of one set for another of the same length.
fn fingerprint(samples: &[FitSample]) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for s in samples {
        for v in [s.i.x, s.i.y, s.i.z, s.o.x, s.o.y, s.o.z] {
            h = (h ^ v.to_bits()).wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

pub struct IlFamily {
    pub distribution: IlDistribution,
    pub evaluation: IlFitEvaluation,
    cache: Mutex<Option<CachedParts>>,
}

impl IlFamily {
    pub fn new(distribution: IlDistribution, evaluation: IlFitEvaluation) -> Self {
        IlFamily {
            distribution,
            evaluation,
            cache: Mutex::new(None),
        }
    }

    fn parts(&self, ni: f64, sigma: f64, samples: &[FitSample]) -> Result<Arc<Parts>, ParamError> {
        let key = (ni.to_bits(), sigma.to_bits(), fingerprint(samples));
        if let Some((k, v)) = self.cache.lock().expect("not poisoned").as_ref() {
            if *k == key && v.len() == samples.len() {
                return Ok(v.clone());
            }
        }
        let lobe = self.distribution.lobe(sigma)?;
        let evaluation = match self.evaluation {
            IlFitEvaluation::Quadrature(n) => BodyEvaluation::Quadrature { samples: n },
            IlFitEvaluation::Approx => BodyEvaluation::Approx(Arc::new(IlApprox::new(&lobe, ni)?)),
        };
        let il = InterfacedLambertian::new(
            Spectrum::splat(0.5),
            ni,
            Some(lobe.clone()),
            evaluation,
            Scattering::Single,
        )?;
        let parts: Parts = samples
            .par_iter()
            .map(|s| {
                let spec = lobe.eval(s.o, s.i, |c| Spectrum::splat(fresnel_dielectric(c, ni)))[0];
                let body = il.body_integral(s.i, s.o, 0, &mut Pcg32::new(1, 1)).0;
                (spec, body)
            })
            .collect();
        let parts = Arc::new(parts);
        *self.cache.lock().expect("not poisoned") = Some((key, parts.clone()));
        Ok(parts)
    }
}

impl ModelFamily for IlFamily {
    fn name(&self) -> String {
        format!(
            "il ({}, {})",
            self.distribution.name(),
            match self.evaluation {
                IlFitEvaluation::Quadrature(n) => format!("quadrature with {n} microfacets"),
                IlFitEvaluation::Approx => "approximate body term".into(),
            }
        )
    }

    fn parameters(&self) -> Vec<Parameter> {
        vec![
            Parameter::new("kd_r", "", 0.0, 1.0),
            Parameter::new("kd_g", "", 0.0, 1.0),
            Parameter::new("kd_b", "", 0.0, 1.0),
            Parameter::new("ni", "", 1.0, 3.0),
            Parameter::new("sigma", "rad", 0.005, 1.2),
        ]
    }

    fn starts(&self, diffuse: Spectrum) -> Vec<Vec<f64>> {
        // The body term of IL is darker than a Lambertian K_d (the interface transmits
        // (1 − r_e)² / n_i² of it): start K_d above the diffuse estimate.
        let kd = diffuse.map(|v| (1.3 * v).clamp(0.05, 0.95));
        [0.05, 0.2, 0.5]
            .iter()
            .map(|&s| vec![kd[0], kd[1], kd[2], 1.4, s])
            .collect()
    }

    fn predict(&self, p: &[f64], samples: &[FitSample]) -> Result<Vec<Spectrum>, ParamError> {
        let (kd, ni, sigma) = (Spectrum::rgb(p[0], p[1], p[2]), p[3], p[4]);
        let parts = self.parts(ni, sigma, samples)?;
        let ri = internal_diffuse_reflectance(ni);
        // K_d/(π n_i² (1 − K_d r_i))  [IL18 eq. 13].
        let factor = kd.map(|k| k / (PI * ni * ni * (1.0 - k * ri)));
        Ok(parts
            .iter()
            .map(|&(s, b)| Spectrum::splat(s) + factor * b)
            .collect())
    }

    fn material_toml(&self, p: &[f64]) -> Option<String> {
        let rough = match self.distribution {
            IlDistribution::Gaussian => format!("distribution = \"gaussian\", sigma = {:.5}", p[4]),
            d => format!(
                "distribution = \"{}\", alpha = {:.5}",
                d.name(),
                SQRT_2 * p[4]
            ),
        };
        Some(format!(
            "{{type = \"il\", kd = [{:.4}, {:.4}, {:.4}], ni = {:.4}, {rough}}}",
            p[0], p[1], p[2], p[3]
        ))
    }
}
