//! KSK01's coupled specular-matte model as a fitting family: matte colour k (RGB), the
//! Ward roughness m and the Fresnel index η of the specular term [KSK01 eqs. 3–4, §2.2].
//! The specular-albedo tables depend on (m, η) only; they are built once per (m, η) with
//! a fixed QMC set and shared while k varies.

use super::family::{ModelFamily, Parameter};
use super::samples::FitSample;
use facette_bsdf::fresnel::Fresnel;
use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::microfacet::half_vector_density::HalfVectorDensity;
use facette_bsdf::models::Kelemen;
use facette_bsdf::two_sided::TwoSided;
use facette_bsdf::{Bsdf, BsdfContext, ParamError, Spectrum};
use rayon::prelude::*;
use std::sync::{Arc, Mutex};

/// QMC samples per entry of the specular-albedo table while fitting.
pub const FIT_TABLE_SAMPLES: usize = 1024;

/// The model of the last (m, η) evaluated.
type CachedModel = ((u64, u64), Arc<Kelemen>);

pub struct KelemenFamily {
    cache: Mutex<Option<CachedModel>>,
}

impl Default for KelemenFamily {
    fn default() -> Self {
        KelemenFamily {
            cache: Mutex::new(None),
        }
    }
}

impl KelemenFamily {
    fn model(&self, m: f64, eta: f64) -> Result<Arc<Kelemen>, ParamError> {
        let key = (m.to_bits(), eta.to_bits());
        if let Some((k, v)) = self.cache.lock().expect("not poisoned").as_ref() {
            if *k == key {
                return Ok(v.clone());
            }
        }
        let model = Arc::new(Kelemen::new(
            HalfVectorDensity::new("ward", m)?,
            Fresnel::Dielectric { eta },
            Spectrum::splat(0.5),
            FIT_TABLE_SAMPLES,
        )?);
        *self.cache.lock().expect("not poisoned") = Some((key, model.clone()));
        Ok(model)
    }
}

impl ModelFamily for KelemenFamily {
    fn name(&self) -> String {
        "kelemen (KSK01, Ward density)".into()
    }

    fn parameters(&self) -> Vec<Parameter> {
        vec![
            Parameter::new("kd_r", "", 0.0, 1.0),
            Parameter::new("kd_g", "", 0.0, 1.0),
            Parameter::new("kd_b", "", 0.0, 1.0),
            Parameter::new("alpha", "", 0.005, 1.5),
            Parameter::new("ior", "", 1.01, 3.0),
        ]
    }

    fn starts(&self, diffuse: Spectrum) -> Vec<Vec<f64>> {
        [0.05, 0.2, 0.5]
            .iter()
            .map(|&m| vec![diffuse[0], diffuse[1], diffuse[2], m, 1.5])
            .collect()
    }

    fn predict(&self, p: &[f64], samples: &[FitSample]) -> Result<Vec<Spectrum>, ParamError> {
        // Measured samples may lie on either side: the two-sided BRDF, as a material.
        let k = TwoSided::new(
            self.model(p[3], p[4])?
                .with_kd(Spectrum::rgb(p[0], p[1], p[2]))?,
        );
        Ok(samples
            .par_iter()
            .map(|s| k.eval(s.o, s.i, &BsdfContext::RADIANCE, &mut Pcg32::new(1, 1)))
            .collect())
    }

    fn material_toml(&self, p: &[f64]) -> Option<String> {
        Some(format!(
            "{{type = \"kelemen\", kd = [{:.4}, {:.4}, {:.4}], alpha = {:.5}, ior = {:.4}}}",
            p[0], p[1], p[2], p[3], p[4]
        ))
    }
}
