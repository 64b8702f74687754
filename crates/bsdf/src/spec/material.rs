//! Building a BSDF from a material table: `type` selects the model, the other keys are its
//! parameters (documented per model and in `docs/materials.md`).

use super::microfacet::{parse_distribution, parse_masking, MICROFACET_KEYS};
use super::params::{check_spectrum, Params};
use crate::bsdf::Bsdf;
use crate::error::{check_range, Bounds, ParamError, ParamResult};
use crate::fresnel::{fresnel_conductor, Fresnel, MetalPreset};
use crate::math::spectrum::Spectrum;
use crate::microfacet::half_vector_density::HalfVectorDensity;
use crate::microfacet::specular_lobe::{NormalSampling, SpecularLobe};
use crate::microfacet::Ndf;
use crate::models::il_approx::IlApprox;
use crate::models::il_table::BodyTable;
use crate::models::interfaced_lambertian::{BodyEvaluation, Scattering};
use crate::models::kelemen::check_ior;
use crate::models::oren_nayar::IntegralEvaluation;
use crate::models::rough_dielectric::{MEASURED_GLASSES, MEASURED_GLASS_IOR};
use crate::models::{
    InterfacedLambertian, Kelemen, Lambert, OrenNayarExact, OrenNayarQualitative, RoughConductor,
    RoughDielectric,
};
use std::sync::Arc;

/// Every material type.
pub const MATERIAL_TYPES: &[&str] = &[
    "lambert",
    "oren-nayar",
    "conductor",
    "dielectric",
    "kelemen",
];

fn keys(extra: &[&'static str], micro: bool) -> Vec<&'static str> {
    let mut v = vec!["type"];
    if micro {
        v.extend_from_slice(MICROFACET_KEYS);
    }
    v.extend_from_slice(extra);
    v
}

/// Builds the BSDF described by `table`; relative file paths (an IL `table`) are resolved
/// against the current directory.
pub fn build_material(table: &toml::Table) -> ParamResult<Arc<dyn Bsdf>> {
    build_material_in(table, std::path::Path::new("."))
}

/// Builds the BSDF described by `table`, resolving relative file paths against `base_dir`
/// (a scene file's directory).
pub fn build_material_in(
    table: &toml::Table,
    base_dir: &std::path::Path,
) -> ParamResult<Arc<dyn Bsdf>> {
    let ty = match table.get("type") {
        Some(toml::Value::String(s)) => s.as_str(),
        Some(_) => return Err(ParamError::Invalid("`type` must be a string".into())),
        None => {
            return Err(ParamError::MissingKey {
                key: format!("type (one of: {})", MATERIAL_TYPES.join(", ")),
                context: "material".into(),
            })
        }
    };
    let p = Params::new(table, format!("material \"{ty}\""));
    p.str("type")?;
    match ty {
        "lambert" | "diffuse" => {
            let r = p.spectrum("reflectance")?.unwrap_or(Spectrum::splat(0.5));
            p.finish(&keys(&["reflectance"], false))?;
            Ok(Arc::new(Lambert::new(r)?))
        }
        "oren-nayar" => build_oren_nayar(&p),
        "conductor" => build_conductor(&p),
        "dielectric" => build_dielectric(&p),
        "kelemen" => build_kelemen(&p),
        "il" | "interfaced-lambertian" => build_il(&p, base_dir),
        other => Err(ParamError::UnknownChoice {
            what: "material type".into(),
            given: other.into(),
            valid: MATERIAL_TYPES.join(", "),
        }),
    }
}

fn choice(what: &str, given: &str, valid: &[&str]) -> ParamError {
    ParamError::UnknownChoice {
        what: what.into(),
        given: given.into(),
        valid: valid.join(", "),
    }
}

/// `evaluation` and `samples` keys of models with a microfacet integral.
pub fn parse_evaluation(p: &Params, default_samples: usize) -> ParamResult<IntegralEvaluation> {
    let samples = p.usize("samples")?;
    match p.str("evaluation")?.unwrap_or("quadrature") {
        "stochastic" => {
            if samples.is_some() {
                return Err(ParamError::Invalid(
                    "`samples` applies to evaluation = \"quadrature\"".into(),
                ));
            }
            Ok(IntegralEvaluation::Stochastic)
        }
        "quadrature" => Ok(IntegralEvaluation::Quadrature {
            samples: samples.unwrap_or(default_samples),
        }),
        other => Err(choice("evaluation", other, IntegralEvaluation::NAMES)),
    }
}

fn build_oren_nayar(p: &Params) -> ParamResult<Arc<dyn Bsdf>> {
    let r = p.spectrum("reflectance")?.unwrap_or(Spectrum::splat(0.5));
    let sigma = p.required_f64("sigma")?;
    let model = p.str("model")?.unwrap_or("exact");
    let out: Arc<dyn Bsdf> = match model {
        "exact" => {
            let ev = parse_evaluation(p, 256)?;
            p.finish(&keys(
                &["reflectance", "sigma", "model", "evaluation", "samples"],
                false,
            ))?;
            if sigma == 0.0 {
                return Ok(Arc::new(Lambert::new(r)?));
            }
            Arc::new(OrenNayarExact::new(r, sigma, ev)?)
        }
        "qualitative" => {
            p.finish(&keys(&["reflectance", "sigma", "model"], false))?;
            Arc::new(OrenNayarQualitative::new(r, sigma)?)
        }
        "l1" => {
            p.finish(&keys(&["reflectance", "sigma", "model"], false))?;
            Arc::new(OrenNayarQualitative::l1(r, sigma)?)
        }
        other => return Err(choice("model", other, &["exact", "qualitative", "l1"])),
    };
    Ok(out)
}

/// The conductor's Fresnel term from `material`, `eta`/`k` and `fresnel`.
fn parse_conductor_fresnel(p: &Params) -> ParamResult<Fresnel> {
    let preset = p.str("material")?;
    let eta = p.spectrum("eta")?;
    let k = p.spectrum("k")?;
    let (eta, k) = match (preset, eta, k) {
        (Some("none"), None, None) | (None, None, None) => {
            if let Some(f) = p.str("fresnel")? {
                if f != "exact" {
                    return Err(ParamError::Invalid(
                        "`fresnel` needs a metal (`material` or `eta` and `k`); material \"none\" has F = 1".into(),
                    ));
                }
            }
            return Ok(Fresnel::One);
        }
        (Some(name), None, None) => {
            let m = MetalPreset::find(name)?;
            (m.eta(), m.k())
        }
        (None, Some(e), Some(k)) => (
            check_spectrum("eta", e, 1e-4, 100.0)?,
            check_spectrum("k", k, 0.0, 100.0)?,
        ),
        (None, Some(_), None) | (None, None, Some(_)) => {
            return Err(ParamError::Invalid("give both `eta` and `k`".into()))
        }
        _ => {
            return Err(ParamError::Invalid(
                "give either `material` or `eta` and `k`, not both".into(),
            ))
        }
    };
    match p.str("fresnel")?.unwrap_or("exact") {
        "exact" => Ok(Fresnel::Conductor { eta, k }),
        "schlick" => Ok(Fresnel::Schlick {
            f0: fresnel_conductor(1.0, eta, k),
        }),
        other => Err(choice("fresnel", other, &["exact", "schlick"])),
    }
}

fn build_conductor(p: &Params) -> ParamResult<Arc<dyn Bsdf>> {
    let ndf = parse_distribution(p, true)?;
    let masking = parse_masking(p, ndf.as_ref())?;
    let sampling = match p.str("sampling")? {
        None => NormalSampling::Visible,
        Some(s) => NormalSampling::parse(s)?,
    };
    let fresnel = parse_conductor_fresnel(p)?;
    let tint = check_spectrum(
        "specular_reflectance",
        p.spectrum("specular_reflectance")?.unwrap_or(Spectrum::ONE),
        0.0,
        1.0,
    )?;
    p.finish(&keys(
        &["material", "eta", "k", "fresnel", "specular_reflectance"],
        true,
    ))?;
    let lobe = match ndf {
        Some(n) => Some(SpecularLobe::new(n, masking, sampling)?),
        None => None,
    };
    Ok(Arc::new(RoughConductor::new(lobe, fresnel, tint)))
}

fn build_dielectric(p: &Params) -> ParamResult<Arc<dyn Bsdf>> {
    let preset = p.str("preset")?;
    let (ndf, ior) = match preset {
        Some(name) => {
            let g = MEASURED_GLASSES
                .iter()
                .find(|g| g.name == name)
                .ok_or_else(|| {
                    choice(
                        "glass preset",
                        name,
                        &MEASURED_GLASSES.iter().map(|g| g.name).collect::<Vec<_>>(),
                    )
                })?;
            for k in ["alpha", "alpha_u", "alpha_v", "sigma", "exponent", "ior"] {
                if p.has(k) {
                    return Err(ParamError::Invalid(format!(
                        "`{k}` cannot be combined with `preset` (the preset fixes roughness and ior = {MEASURED_GLASS_IOR})"
                    )));
                }
            }
            let ndf = match p.str("distribution")?.unwrap_or("beckmann") {
                "beckmann" => {
                    Ndf::Beckmann(crate::microfacet::Beckmann::isotropic(g.beckmann_alpha)?)
                }
                "ggx" => Ndf::Ggx(crate::microfacet::Ggx::isotropic(g.ggx_alpha)?),
                other => {
                    return Err(choice(
                        "distribution (with preset)",
                        other,
                        &["beckmann", "ggx"],
                    ))
                }
            };
            (Some(ndf), MEASURED_GLASS_IOR)
        }
        None => (parse_distribution(p, true)?, p.f64_or("ior", 1.5)?),
    };
    check_range("ior", ior, 0.0, 100.0, Bounds::OpenClosed)?;
    let ext = check_range(
        "ext_ior",
        p.f64_or("ext_ior", 1.0)?,
        0.0,
        100.0,
        Bounds::OpenClosed,
    )?;
    let masking = parse_masking(p, ndf.as_ref())?;
    let (sampling, widened) = match p.str("sampling")?.unwrap_or("visible") {
        "widened" => (NormalSampling::Distribution, true),
        s => (
            NormalSampling::parse(s)
                .map_err(|_| choice("sampling", s, &["visible", "distribution", "widened"]))?,
            false,
        ),
    };
    let rt = check_spectrum(
        "specular_reflectance",
        p.spectrum("specular_reflectance")?.unwrap_or(Spectrum::ONE),
        0.0,
        1.0,
    )?;
    let tt = check_spectrum(
        "specular_transmittance",
        p.spectrum("specular_transmittance")?
            .unwrap_or(Spectrum::ONE),
        0.0,
        1.0,
    )?;
    p.finish(&keys(
        &[
            "ior",
            "ext_ior",
            "preset",
            "specular_reflectance",
            "specular_transmittance",
        ],
        true,
    ))?;
    let lobe = match ndf {
        Some(n) => Some(SpecularLobe::new(n, masking, sampling)?),
        None => None,
    };
    Ok(Arc::new(RoughDielectric::new(
        ior / ext,
        lobe,
        widened,
        rt,
        tt,
    )?))
}

fn build_il(p: &Params, base_dir: &std::path::Path) -> ParamResult<Arc<dyn Bsdf>> {
    let kd = p.spectrum("kd")?.unwrap_or(Spectrum::splat(0.5));
    let ni = p.f64_or("ni", 1.5)?;
    let scattering = Scattering::parse(p.str("scattering")?.unwrap_or("single"))?;
    let ndf = parse_distribution(p, true)?;
    let masking = match p.str("masking")? {
        Some(m) => crate::microfacet::Masking::parse(m)?,
        None if scattering != Scattering::Single => crate::microfacet::Masking::VCavity,
        None => parse_masking(p, ndf.as_ref())?,
    };
    let sampling = match p.str("sampling")? {
        None => NormalSampling::Visible,
        Some(s) => NormalSampling::parse(s)?,
    };
    let samples = p.usize("samples")?;
    let table_path = p.str("table")?;
    let evaluation = match p.str("evaluation")?.unwrap_or(if table_path.is_some() {
        "table"
    } else {
        "stochastic"
    }) {
        "stochastic" => BodyEvaluation::Stochastic,
        "quadrature" => BodyEvaluation::Quadrature {
            samples: samples.unwrap_or(1024),
        },
        "table" => {
            let path = table_path.ok_or_else(|| ParamError::MissingKey {
                key: "table (path of a file written by `facette tabulate`)".into(),
                context: p.context().into(),
            })?;
            let full = base_dir.join(path);
            let t = BodyTable::load(&full).map_err(|e| ParamError::Invalid(e.to_string()))?;
            BodyEvaluation::Table(Arc::new(t))
        }
        "approx" => match &ndf {
            Some(n) => {
                let lobe = SpecularLobe::new(n.clone(), masking, sampling)?;
                BodyEvaluation::Approx(Arc::new(IlApprox::new(&lobe, ni)?))
            }
            // Flat IL is closed-form already.
            None => BodyEvaluation::Stochastic,
        },
        other => return Err(choice("evaluation", other, BodyEvaluation::NAMES)),
    };
    if samples.is_some() && !matches!(evaluation, BodyEvaluation::Quadrature { .. }) {
        return Err(ParamError::Invalid(
            "`samples` applies to evaluation = \"quadrature\"".into(),
        ));
    }
    if table_path.is_some() && !matches!(evaluation, BodyEvaluation::Table(_)) {
        return Err(ParamError::Invalid(
            "`table` applies to evaluation = \"table\"".into(),
        ));
    }
    p.finish(&keys(
        &["kd", "ni", "evaluation", "samples", "table", "scattering"],
        true,
    ))?;
    let lobe = match ndf {
        Some(n) => Some(SpecularLobe::new(n, masking, sampling)?),
        None => None,
    };
    Ok(Arc::new(InterfacedLambertian::new(
        kd, ni, lobe, evaluation, scattering,
    )?))
}

fn build_kelemen(p: &Params) -> ParamResult<Arc<dyn Bsdf>> {
    let name = p.str("distribution")?.unwrap_or("ward");
    let rough = match name {
        "phong" => p.required_f64("exponent")?,
        _ => p.required_f64("alpha")?,
    };
    let density = HalfVectorDensity::new(name, rough)?;
    let ior = check_ior(p.f64_or("ior", 1.5)?)?;
    let kd = p.spectrum("kd")?.unwrap_or(Spectrum::splat(0.5));
    let samples = p.usize("table_samples")?.unwrap_or(16384);
    p.finish(&keys(
        &[
            "distribution",
            "alpha",
            "exponent",
            "ior",
            "kd",
            "table_samples",
        ],
        false,
    ))?;
    Ok(Arc::new(Kelemen::new(
        density,
        Fresnel::Dielectric { eta: ior },
        kd,
        samples,
    )?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::parse_inline_table;

    fn build(s: &str) -> ParamResult<Arc<dyn Bsdf>> {
        build_material(&parse_inline_table(s).unwrap())
    }

    #[test]
    fn every_type_builds() {
        for s in [
            r#"{type = "lambert", reflectance = [0.2, 0.4, 0.6]}"#,
            r#"{type = "oren-nayar", sigma = 0.3}"#,
            r#"{type = "oren-nayar", sigma = 0.3, model = "qualitative"}"#,
            r#"{type = "conductor", distribution = "ggx", alpha_u = 0.1, alpha_v = 0.3, material = "Au"}"#,
            r#"{type = "conductor", alpha = 0}"#,
            r#"{type = "dielectric", distribution = "ggx", alpha = 0.3, ior = 1.5}"#,
            r#"{type = "dielectric", preset = "ground", distribution = "ggx"}"#,
            r#"{type = "dielectric", alpha = 0.2, sampling = "widened"}"#,
            r#"{type = "kelemen", alpha = 0.3, kd = 0.8, table_samples = 256}"#,
            r#"{type = "kelemen", distribution = "phong", exponent = 40, table_samples = 256}"#,
        ] {
            let b = build(s).unwrap_or_else(|e| panic!("{s}: {e}"));
            assert!(!b.describe().is_empty());
        }
    }

    #[test]
    fn errors_list_valid_choices() {
        let e = build(r#"{type = "plastic"}"#).err().unwrap().to_string();
        assert!(
            e.contains("lambert, oren-nayar, conductor, dielectric, kelemen"),
            "{e}"
        );
        let e = build(r#"{type = "dielectric", alpha = 0.1, ior = 1.5, iorr = 2}"#)
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.contains("unknown key `iorr`") && e.contains("ext_ior"),
            "{e}"
        );
        let e = build(r#"{type = "dielectric", preset = "sand"}"#)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("ground, frosted, etched, antiglare"), "{e}");
        let e = build(r#"{type = "dielectric", alpha = 0.1, ior = -1}"#)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("`ior` = -1"), "{e}");
        let e = build(r#"{type = "dielectric", alpha = 0.1, ior = 1.0}"#)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("must differ"), "{e}");
        let e = build(r#"{type = "conductor", alpha = 0.1, material = "gold"}"#)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("Au, Ag, Cu, Al, Cr"), "{e}");
        let e = build(r#"{type = "lambert", reflectance = 1.5}"#)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("reflectance"), "{e}");
        let e = build(r#"{reflectance = 0.5}"#).err().unwrap().to_string();
        assert!(e.contains("missing required key `type"), "{e}");
        let e = build(r#"{type = "dielectric", alpha = 0.1, masking = "v-cavity"}"#)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("not defined for refraction"), "{e}");
    }
}
