//! The interfaced-Lambertian family (`il`, alias `interfaced-lambertian`): flat or rough,
//! its body term stochastic, by quadrature, tabulated (`facette tabulate`) or approximate,
//! with single, double or multiple V-cavity scattering [IL18].

use super::{keys, MaterialRecipe};
use crate::bsdf::Bsdf;
use crate::error::{ParamError, ParamResult};
use crate::math::spectrum::Spectrum;
use crate::microfacet::integral::{check_tolerance, DEFAULT_TOLERANCE};
use crate::microfacet::specular_lobe::{NormalSampling, SpecularLobe};
use crate::microfacet::Masking;
use crate::models::il::il_approx::IlApprox;
use crate::models::il::il_table::BodyTable;
use crate::models::il::interfaced_lambertian::{BodyEvaluation, Scattering};
use crate::models::InterfacedLambertian;
use crate::recipe::microfacet::{parse_distribution, parse_masking};
use crate::recipe::params::{choice, Params};
use crate::two_sided::TwoSided;
use std::sync::Arc;

pub(super) const IL_KEYS: &[&str] = &[
    "kd",
    "ni",
    "evaluation",
    "samples",
    "tolerance",
    "table",
    "scattering",
    "multiple_evaluation",
];

/// Default relative tolerance of `multiple_evaluation = "quadrature"`.
pub const DEFAULT_MULTIPLE_TOLERANCE: f64 = 1e-4;

/// How an interfaced-Lambertian recipe evaluates its body term.
#[derive(Clone, Debug)]
pub enum IlEvaluation {
    Stochastic,
    /// `samples = N`: a fixed set of N microfacets.
    Quadrature {
        samples: usize,
    },
    /// Adaptive quadrature to a relative tolerance (the default of "quadrature").
    Adaptive {
        tolerance: f64,
    },
    Table(Arc<BodyTable>),
    /// The approximation's coefficients are looked up at build time (they depend on the
    /// roughness, which a texture may change).
    Approx,
}

pub(super) fn parse_il(p: &Params, base_dir: &std::path::Path) -> ParamResult<MaterialRecipe> {
    let kd = p.spectrum("kd")?.unwrap_or(Spectrum::splat(0.5));
    let ni = p.f64_or("ni", 1.5)?;
    let scattering = Scattering::parse(p.str("scattering")?.unwrap_or("single"))?;
    let ndf = parse_distribution(p, true)?;
    let masking = match p.str("masking")? {
        Some(m) => Masking::parse(m)?,
        None if scattering != Scattering::Single => Masking::VCavity,
        None => parse_masking(p, ndf.as_ref())?,
    };
    let sampling = match p.str("sampling")? {
        None => NormalSampling::Visible,
        Some(s) => NormalSampling::parse(s)?,
    };
    let samples = p.count("samples")?;
    let tolerance = p.f64("tolerance")?;
    let table_path = p.str("table")?;
    let evaluation = match p.str("evaluation")?.unwrap_or(if table_path.is_some() {
        "table"
    } else {
        "stochastic"
    }) {
        "stochastic" => IlEvaluation::Stochastic,
        "quadrature" => match (samples, tolerance) {
            (Some(_), Some(_)) => return Err(samples_and_tolerance()),
            (Some(n), None) => IlEvaluation::Quadrature { samples: n },
            (None, t) => IlEvaluation::Adaptive {
                tolerance: check_tolerance(t.unwrap_or(DEFAULT_TOLERANCE))?,
            },
        },
        "table" => {
            let path = table_path.ok_or_else(|| ParamError::MissingKey {
                key: "table (path of a file written by `facette tabulate`)".into(),
                context: p.context().into(),
            })?;
            let full = base_dir.join(path);
            let t = BodyTable::load(&full).map_err(|e| ParamError::Invalid(e.to_string()))?;
            IlEvaluation::Table(Arc::new(t))
        }
        "approx" => IlEvaluation::Approx,
        other => return Err(choice("evaluation", other, BodyEvaluation::NAMES)),
    };
    let quadrature = matches!(
        evaluation,
        IlEvaluation::Quadrature { .. } | IlEvaluation::Adaptive { .. }
    );
    let multiple_tolerance = match p.str("multiple_evaluation")? {
        None | Some("stochastic") => None,
        Some("quadrature") => {
            if scattering == Scattering::Single {
                return Err(ParamError::Invalid(
                    "`multiple_evaluation` applies to scattering = \"double\" or \"multiple\""
                        .into(),
                ));
            }
            if ndf.is_none() {
                return Err(ParamError::Invalid(
                    "`multiple_evaluation` needs a rough IL (flat IL has no V-cavities)".into(),
                ));
            }
            // `tolerance` also sets the body quadrature's when evaluation = "quadrature".
            Some(check_tolerance(
                tolerance.unwrap_or(DEFAULT_MULTIPLE_TOLERANCE),
            )?)
        }
        Some(other) => {
            return Err(choice(
                "multiple_evaluation",
                other,
                &["stochastic", "quadrature"],
            ))
        }
    };
    if samples.is_some() && !quadrature {
        return Err(ParamError::Invalid(
            "`samples` applies to evaluation = \"quadrature\"".into(),
        ));
    }
    if tolerance.is_some() && !quadrature && multiple_tolerance.is_none() {
        return Err(ParamError::Invalid(
            "`tolerance` applies to evaluation = \"quadrature\" or multiple_evaluation = \"quadrature\""
                .into(),
        ));
    }
    if table_path.is_some() && !matches!(evaluation, IlEvaluation::Table(_)) {
        return Err(ParamError::Invalid(
            "`table` applies to evaluation = \"table\"".into(),
        ));
    }
    p.finish(&keys(IL_KEYS, true))?;
    let lobe = match ndf {
        Some(n) => Some(SpecularLobe::new(n, masking, sampling)?),
        None => None,
    };
    let recipe = MaterialRecipe::Il {
        kd,
        ni,
        lobe,
        evaluation,
        scattering,
        multiple_tolerance,
    };
    recipe.build()?;
    Ok(recipe)
}

/// `samples` (fixed N) and `tolerance` (adaptive) are the two forms of "quadrature".
pub(super) fn samples_and_tolerance() -> ParamError {
    ParamError::Invalid(
        "`samples` (a fixed set of N microfacets) and `tolerance` (adaptive quadrature) \
         are exclusive forms of evaluation = \"quadrature\": give one"
            .into(),
    )
}

/// The IL model; the approximation's coefficients are looked up here, for the lobe's
/// current roughness.
pub(super) fn build_il(
    kd: Spectrum,
    ni: f64,
    lobe: &Option<SpecularLobe>,
    evaluation: &IlEvaluation,
    scattering: Scattering,
    multiple_tolerance: Option<f64>,
) -> ParamResult<Arc<dyn Bsdf>> {
    let ev = match evaluation {
        IlEvaluation::Stochastic => BodyEvaluation::Stochastic,
        IlEvaluation::Quadrature { samples } => BodyEvaluation::Quadrature { samples: *samples },
        IlEvaluation::Adaptive { tolerance } => BodyEvaluation::Adaptive {
            tolerance: *tolerance,
        },
        IlEvaluation::Table(t) => BodyEvaluation::Table(t.clone()),
        IlEvaluation::Approx => match lobe {
            Some(l) => BodyEvaluation::Approx(Arc::new(IlApprox::new(l, ni)?)),
            None => BodyEvaluation::Stochastic,
        },
    };
    let mut il = InterfacedLambertian::new(kd, ni, lobe.clone(), ev, scattering)?;
    if let Some(t) = multiple_tolerance {
        il = il.with_multiple_quadrature(t)?;
    }
    Ok(Arc::new(TwoSided::new(il)))
}
