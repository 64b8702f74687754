//! The interfaced-Lambertian family (`il`, alias `interfaced-lambertian`): flat or rough,
//! its body term stochastic, by quadrature, tabulated (`facette tabulate`) or approximate,
//! with single, double or multiple V-cavity scattering [IL18].

use super::{keys, MaterialRecipe};
use crate::bsdf::Bsdf;
use crate::error::{ParamError, ParamResult};
use crate::math::spectrum::Spectrum;
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

pub(super) const IL_KEYS: &[&str] = &["kd", "ni", "evaluation", "samples", "table", "scattering"];

/// How an interfaced-Lambertian recipe evaluates its body term.
#[derive(Clone, Debug)]
pub enum IlEvaluation {
    Stochastic,
    Quadrature {
        samples: usize,
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
    let table_path = p.str("table")?;
    let evaluation = match p.str("evaluation")?.unwrap_or(if table_path.is_some() {
        "table"
    } else {
        "stochastic"
    }) {
        "stochastic" => IlEvaluation::Stochastic,
        "quadrature" => IlEvaluation::Quadrature {
            samples: samples.unwrap_or(1024),
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
    if samples.is_some() && !matches!(evaluation, IlEvaluation::Quadrature { .. }) {
        return Err(ParamError::Invalid(
            "`samples` applies to evaluation = \"quadrature\"".into(),
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
    };
    recipe.build()?;
    Ok(recipe)
}

/// The IL model; the approximation's coefficients are looked up here, for the lobe's
/// current roughness.
pub(super) fn build_il(
    kd: Spectrum,
    ni: f64,
    lobe: &Option<SpecularLobe>,
    evaluation: &IlEvaluation,
    scattering: Scattering,
) -> ParamResult<Arc<dyn Bsdf>> {
    let ev = match evaluation {
        IlEvaluation::Stochastic => BodyEvaluation::Stochastic,
        IlEvaluation::Quadrature { samples } => BodyEvaluation::Quadrature { samples: *samples },
        IlEvaluation::Table(t) => BodyEvaluation::Table(t.clone()),
        IlEvaluation::Approx => match lobe {
            Some(l) => BodyEvaluation::Approx(Arc::new(IlApprox::new(l, ni)?)),
            None => BodyEvaluation::Stochastic,
        },
    };
    Ok(Arc::new(TwoSided::new(InterfacedLambertian::new(
        kd,
        ni,
        lobe.clone(),
        ev,
        scattering,
    )?)))
}
