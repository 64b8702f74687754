//! The diffuse family: `lambert` (alias `diffuse`) and `oren-nayar` (exact, qualitative,
//! L1). Keys and ranges are documented in the models' module docs and `docs/materials.md`.

use super::{keys, MaterialRecipe};
use crate::bsdf::Bsdf;
use crate::error::{ParamError, ParamResult};
use crate::math::spectrum::Spectrum;
use crate::microfacet::integral::{check_tolerance, DEFAULT_TOLERANCE};
use crate::models::oren_nayar::IntegralEvaluation;
use crate::models::{Lambert, OrenNayarExact, OrenNayarQualitative};
use crate::recipe::params::{choice, Params};
use crate::two_sided::TwoSided;
use std::sync::Arc;

pub(super) const LAMBERT_KEYS: &[&str] = &["reflectance"];
pub(super) const OREN_NAYAR_KEYS: &[&str] = &[
    "reflectance",
    "sigma",
    "model",
    "evaluation",
    "samples",
    "tolerance",
];

/// Oren–Nayar variants.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OrenNayarModel {
    Exact,
    Qualitative,
    L1,
}

pub(super) fn parse_lambert(p: &Params) -> ParamResult<MaterialRecipe> {
    let r = p.spectrum("reflectance")?.unwrap_or(Spectrum::splat(0.5));
    p.finish(&keys(LAMBERT_KEYS, false))?;
    Lambert::new(r)?;
    Ok(MaterialRecipe::Lambert { reflectance: r })
}

/// `evaluation`, `samples` and `tolerance` keys of models with a microfacet integral:
/// "quadrature" is adaptive to `tolerance` (default 1e-6) unless `samples = N` asks for a
/// fixed set of N microfacets; when none of the three keys is given, the fixed set of
/// `default_samples` microfacets (the cheaper choice for rendering).
pub fn parse_evaluation(p: &Params, default_samples: usize) -> ParamResult<IntegralEvaluation> {
    let samples = p.count("samples")?;
    let tolerance = p.f64("tolerance")?;
    let given = p.str("evaluation")?;
    match given.unwrap_or("quadrature") {
        "stochastic" => {
            for (key, set) in [
                ("samples", samples.is_some()),
                ("tolerance", tolerance.is_some()),
            ] {
                if set {
                    return Err(ParamError::Invalid(format!(
                        "`{key}` applies to evaluation = \"quadrature\""
                    )));
                }
            }
            Ok(IntegralEvaluation::Stochastic)
        }
        "quadrature" => match (samples, tolerance) {
            (Some(_), Some(_)) => Err(super::il::samples_and_tolerance()),
            (Some(n), None) => Ok(IntegralEvaluation::Quadrature { samples: n }),
            (None, None) if given.is_none() => Ok(IntegralEvaluation::Quadrature {
                samples: default_samples,
            }),
            (None, t) => Ok(IntegralEvaluation::Adaptive {
                tolerance: check_tolerance(t.unwrap_or(DEFAULT_TOLERANCE))?,
            }),
        },
        other => Err(choice("evaluation", other, IntegralEvaluation::NAMES)),
    }
}

pub(super) fn parse_oren_nayar(p: &Params) -> ParamResult<MaterialRecipe> {
    let r = p.spectrum("reflectance")?.unwrap_or(Spectrum::splat(0.5));
    let sigma = p.required_f64("sigma")?;
    let (model, evaluation) = match p.str("model")?.unwrap_or("exact") {
        "exact" => {
            let ev = parse_evaluation(p, 256)?;
            p.finish(&keys(OREN_NAYAR_KEYS, false))?;
            (OrenNayarModel::Exact, ev)
        }
        "qualitative" => {
            p.finish(&keys(&["reflectance", "sigma", "model"], false))?;
            (OrenNayarModel::Qualitative, IntegralEvaluation::Stochastic)
        }
        "l1" => {
            p.finish(&keys(&["reflectance", "sigma", "model"], false))?;
            (OrenNayarModel::L1, IntegralEvaluation::Stochastic)
        }
        other => return Err(choice("model", other, &["exact", "qualitative", "l1"])),
    };
    let recipe = MaterialRecipe::OrenNayar {
        reflectance: r,
        sigma,
        model,
        evaluation,
    };
    recipe.build()?;
    Ok(recipe)
}

pub(super) fn build_lambert(reflectance: Spectrum) -> ParamResult<Arc<dyn Bsdf>> {
    Ok(Arc::new(TwoSided::new(Lambert::new(reflectance)?)))
}

/// Oren–Nayar; σ = 0 is Lambert.
pub(super) fn build_oren_nayar(
    reflectance: Spectrum,
    sigma: f64,
    model: OrenNayarModel,
    evaluation: IntegralEvaluation,
) -> ParamResult<Arc<dyn Bsdf>> {
    if sigma == 0.0 {
        return build_lambert(reflectance);
    }
    Ok(match model {
        OrenNayarModel::Exact => Arc::new(TwoSided::new(OrenNayarExact::new(
            reflectance,
            sigma,
            evaluation,
        )?)),
        OrenNayarModel::Qualitative => Arc::new(TwoSided::new(OrenNayarQualitative::new(
            reflectance,
            sigma,
        )?)),
        OrenNayarModel::L1 => {
            Arc::new(TwoSided::new(OrenNayarQualitative::l1(reflectance, sigma)?))
        }
    })
}
