//! Building a BSDF from a material table: `type` selects the model, the other keys are its
//! parameters (documented per model and in `docs/materials.md`).

use super::glint::{parse_glint, GlintRecipe, NormalMapReader, GLINT_KEYS};
use super::microfacet::{parse_distribution, parse_masking, MICROFACET_KEYS};
use super::params::Params;
use crate::bsdf::Bsdf;
use crate::checks::{
    check_alpha_or_smooth, check_ior, check_range, check_reflectance, check_spectrum, Bounds,
};
use crate::error::{ParamError, ParamResult};
use crate::fresnel::{fresnel_conductor, Fresnel, MetalPreset};
use crate::math::spectrum::Spectrum;
use crate::microfacet::half_vector_density::HalfVectorDensity;
use crate::microfacet::specular_lobe::{NormalSampling, SpecularLobe};
use crate::microfacet::Ndf;
use crate::models::il_approx::IlApprox;
use crate::models::il_table::BodyTable;
use crate::models::interfaced_lambertian::{BodyEvaluation, Scattering};
use crate::models::oren_nayar::IntegralEvaluation;
use crate::models::rough_dielectric::{MEASURED_GLASSES, MEASURED_GLASS_IOR};
use crate::models::smith_microsurface::HeightDistribution;
use crate::models::{
    CompensatedConductor, CompensatedDielectric, InterfacedLambertian, Kelemen, Lambert,
    MultipleScatteringConductor, MultipleScatteringDielectric, OrenNayarExact,
    OrenNayarQualitative, RoughConductor, RoughDielectric,
};
use std::sync::Arc;

/// Every material type.
pub const MATERIAL_TYPES: &[&str] = &[
    "lambert",
    "oren-nayar",
    "conductor",
    "dielectric",
    "kelemen",
    "il",
    "glint",
];

/// The keys of each material type besides `type` (and the microfacet keys where the type
/// has a microfacet lobe): checked before anything else, so that a misspelt key is reported
/// as unknown, with the valid ones, rather than as a missing required key.
const LAMBERT_KEYS: &[&str] = &["reflectance"];
const OREN_NAYAR_KEYS: &[&str] = &["reflectance", "sigma", "model", "evaluation", "samples"];
const CONDUCTOR_KEYS: &[&str] = &[
    "material",
    "eta",
    "k",
    "fresnel",
    "specular_reflectance",
    "scattering",
    "energy",
    "height_distribution",
];
const DIELECTRIC_KEYS: &[&str] = &[
    "ior",
    "ext_ior",
    "preset",
    "specular_reflectance",
    "specular_transmittance",
    "scattering",
    "energy",
    "height_distribution",
];
const KELEMEN_KEYS: &[&str] = &[
    "distribution",
    "alpha",
    "exponent",
    "ior",
    "kd",
    "table_samples",
];
const IL_KEYS: &[&str] = &["kd", "ni", "evaluation", "samples", "table", "scattering"];

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
    MaterialRecipe::parse(table, base_dir)?.build()
}

/// Builds the BSDF described by `table`, reading image files (a glint `normal_map`) with
/// `reader`; relative paths are resolved against `base_dir`.
pub fn build_material_with_reader(
    table: &toml::Table,
    base_dir: &std::path::Path,
    reader: &dyn NormalMapReader,
) -> ParamResult<Arc<dyn Bsdf>> {
    MaterialRecipe::parse_with_reader(table, base_dir, Some(reader))?.build()
}

/// Oren–Nayar variants.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OrenNayarModel {
    Exact,
    Qualitative,
    L1,
}

/// What a conductor or dielectric does with the light that meets several microfacets
/// (`scattering` and `energy` keys).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MicrofacetEnergy {
    /// Single scattering (WMLT07): that light is lost.
    Single,
    /// `scattering = "multiple"`: the random walk on the Smith microsurface (HHdD16).
    Multiple(HeightDistribution),
    /// `energy = "compensated"`: the Kulla–Conty compensation lobe (KC17).
    Compensated,
}

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

/// A validated material with its parameters as numbers: what a material table parses to,
/// built into a BSDF by [`MaterialRecipe::build`]. The renderer keeps recipes of textured
/// materials and overrides their textured parameters per shading point
/// ([`set_spectrum`](Self::set_spectrum), [`set_scalar`](Self::set_scalar)) before building;
/// expensive precomputations (Kelemen's albedo tables, IL body tables, the Gaussian's
/// normalization table) are shared, not redone.
#[derive(Clone, Debug)]
pub enum MaterialRecipe {
    Lambert {
        reflectance: Spectrum,
    },
    OrenNayar {
        reflectance: Spectrum,
        sigma: f64,
        model: OrenNayarModel,
        evaluation: IntegralEvaluation,
    },
    Conductor {
        lobe: Option<SpecularLobe>,
        fresnel: Fresnel,
        tint: Spectrum,
        energy: MicrofacetEnergy,
    },
    Dielectric {
        lobe: Option<SpecularLobe>,
        eta: f64,
        widened: bool,
        reflect_tint: Spectrum,
        transmit_tint: Spectrum,
        energy: MicrofacetEnergy,
    },
    Kelemen(Arc<Kelemen>),
    Il {
        kd: Spectrum,
        ni: f64,
        lobe: Option<SpecularLobe>,
        evaluation: IlEvaluation,
        scattering: Scattering,
    },
    /// Glints [CCM19]: its BSDF depends on the footprint of each shading point
    /// ([`MaterialRecipe::build_at`]).
    Glint(GlintRecipe),
}

impl MaterialRecipe {
    /// Parses and validates a material table (without an image reader: a glint
    /// `normal_map` file is an error, see [`MaterialRecipe::parse_with_reader`]).
    pub fn parse(table: &toml::Table, base_dir: &std::path::Path) -> ParamResult<MaterialRecipe> {
        Self::parse_with_reader(table, base_dir, None)
    }

    /// Parses and validates a material table, reading image files with `reader`.
    pub fn parse_with_reader(
        table: &toml::Table,
        base_dir: &std::path::Path,
        reader: Option<&dyn NormalMapReader>,
    ) -> ParamResult<MaterialRecipe> {
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
        let known = match ty {
            "lambert" | "diffuse" => Some(keys(LAMBERT_KEYS, false)),
            "oren-nayar" => Some(keys(OREN_NAYAR_KEYS, false)),
            "conductor" => Some(keys(CONDUCTOR_KEYS, true)),
            "dielectric" => Some(keys(DIELECTRIC_KEYS, true)),
            "kelemen" => Some(keys(KELEMEN_KEYS, false)),
            "il" | "interfaced-lambertian" => Some(keys(IL_KEYS, true)),
            "glint" => Some(keys(GLINT_KEYS, false)),
            _ => None,
        };
        if let Some(known) = known {
            p.check_known(&known)?;
        }
        match ty {
            "lambert" | "diffuse" => {
                let r = p.spectrum("reflectance")?.unwrap_or(Spectrum::splat(0.5));
                p.finish(&keys(LAMBERT_KEYS, false))?;
                Lambert::new(r)?;
                Ok(MaterialRecipe::Lambert { reflectance: r })
            }
            "oren-nayar" => parse_oren_nayar(&p),
            "conductor" => parse_conductor(&p),
            "dielectric" => parse_dielectric(&p),
            "kelemen" => parse_kelemen(&p),
            "il" | "interfaced-lambertian" => parse_il(&p, base_dir),
            "glint" => {
                let g = parse_glint(&p, base_dir, reader)?;
                p.finish(&keys(GLINT_KEYS, false))?;
                Ok(MaterialRecipe::Glint(g))
            }
            other => Err(ParamError::UnknownChoice {
                what: "material type".into(),
                given: other.into(),
                valid: MATERIAL_TYPES.join(", "),
            }),
        }
    }

    /// Builds the BSDF.
    pub fn build(&self) -> ParamResult<Arc<dyn Bsdf>> {
        Ok(match self {
            MaterialRecipe::Lambert { reflectance } => Arc::new(Lambert::new(*reflectance)?),
            MaterialRecipe::OrenNayar {
                reflectance,
                sigma,
                model,
                evaluation,
            } => {
                if *sigma == 0.0 {
                    return Ok(Arc::new(Lambert::new(*reflectance)?));
                }
                match model {
                    OrenNayarModel::Exact => {
                        Arc::new(OrenNayarExact::new(*reflectance, *sigma, *evaluation)?)
                    }
                    OrenNayarModel::Qualitative => {
                        Arc::new(OrenNayarQualitative::new(*reflectance, *sigma)?)
                    }
                    OrenNayarModel::L1 => Arc::new(OrenNayarQualitative::l1(*reflectance, *sigma)?),
                }
            }
            MaterialRecipe::Conductor {
                lobe,
                fresnel,
                tint,
                energy,
            } => {
                let single = RoughConductor::new(lobe.clone(), *fresnel, *tint);
                // A smooth surface has no inter-reflections: every mode is the mirror.
                match (energy, lobe) {
                    (MicrofacetEnergy::Multiple(h), Some(_)) => {
                        Arc::new(MultipleScatteringConductor::new(single, *h)?)
                    }
                    (MicrofacetEnergy::Compensated, Some(_)) => {
                        Arc::new(CompensatedConductor::new(single)?)
                    }
                    _ => Arc::new(single),
                }
            }
            MaterialRecipe::Dielectric {
                lobe,
                eta,
                widened,
                reflect_tint,
                transmit_tint,
                energy,
            } => {
                let single = RoughDielectric::new(
                    *eta,
                    lobe.clone(),
                    *widened,
                    *reflect_tint,
                    *transmit_tint,
                )?;
                match (energy, lobe) {
                    (MicrofacetEnergy::Multiple(h), Some(_)) => {
                        Arc::new(MultipleScatteringDielectric::new(single, *h)?)
                    }
                    (MicrofacetEnergy::Compensated, Some(_)) => {
                        Arc::new(CompensatedDielectric::new(single)?)
                    }
                    _ => Arc::new(single),
                }
            }
            MaterialRecipe::Kelemen(k) => k.clone(),
            MaterialRecipe::Il {
                kd,
                ni,
                lobe,
                evaluation,
                scattering,
            } => {
                let ev = match evaluation {
                    IlEvaluation::Stochastic => BodyEvaluation::Stochastic,
                    IlEvaluation::Quadrature { samples } => {
                        BodyEvaluation::Quadrature { samples: *samples }
                    }
                    IlEvaluation::Table(t) => BodyEvaluation::Table(t.clone()),
                    IlEvaluation::Approx => match lobe {
                        Some(l) => BodyEvaluation::Approx(Arc::new(IlApprox::new(l, *ni)?)),
                        None => BodyEvaluation::Stochastic,
                    },
                };
                Arc::new(InterfacedLambertian::new(
                    *kd,
                    *ni,
                    lobe.clone(),
                    ev,
                    *scattering,
                )?)
            }
            MaterialRecipe::Glint(g) => g.build_default(),
        })
    }

    /// True when the BSDF depends on the shading point's footprint (glints): the renderer
    /// must build it per hit with [`MaterialRecipe::build_at`].
    pub fn varies_per_hit(&self) -> bool {
        matches!(self, MaterialRecipe::Glint(_))
    }

    /// Builds the BSDF of a shading point with texture coordinates `uv` and screen-space
    /// derivatives `[du/dx, dv/dx, du/dy, dv/dy]` (all zero when unknown). Only glints use
    /// them; every other material is [`MaterialRecipe::build`].
    pub fn build_at(&self, uv: crate::math::Vec2, derivs: [f64; 4]) -> ParamResult<Arc<dyn Bsdf>> {
        match self {
            MaterialRecipe::Glint(g) => Ok(g.build_at(uv, derivs)),
            _ => self.build(),
        }
    }

    /// Spectrum-valued keys a texture may drive.
    pub fn texturable_spectrum_keys(&self) -> &'static [&'static str] {
        match self {
            MaterialRecipe::Lambert { .. } | MaterialRecipe::OrenNayar { .. } => &["reflectance"],
            MaterialRecipe::Conductor { .. } => &["specular_reflectance"],
            MaterialRecipe::Dielectric { .. } => {
                &["specular_reflectance", "specular_transmittance"]
            }
            MaterialRecipe::Kelemen(_) | MaterialRecipe::Il { .. } => &["kd"],
            MaterialRecipe::Glint(_) => &["specular_reflectance"],
        }
    }

    /// Scalar keys (roughness) a texture may drive.
    pub fn texturable_scalar_keys(&self) -> &'static [&'static str] {
        let lobe = match self {
            MaterialRecipe::OrenNayar { .. } => return &["sigma"],
            MaterialRecipe::Conductor { lobe, .. } | MaterialRecipe::Dielectric { lobe, .. } => {
                lobe
            }
            MaterialRecipe::Il {
                lobe, evaluation, ..
            } => {
                if matches!(evaluation, IlEvaluation::Table(_)) {
                    return &[];
                }
                lobe
            }
            _ => return &[],
        };
        match lobe.as_ref().map(|l| &l.ndf) {
            Some(Ndf::Beckmann(_)) | Some(Ndf::Ggx(_)) => &["alpha", "alpha_u", "alpha_v"],
            Some(Ndf::Gaussian(_)) => &["sigma"],
            Some(Ndf::Phong(p)) if p.g1_form() == crate::microfacet::PhongG1::Rational => {
                &["exponent"]
            }
            _ => &[],
        }
    }

    /// Replaces a spectrum parameter (validated like the table's value).
    pub fn set_spectrum(&mut self, key: &str, v: Spectrum) -> ParamResult<()> {
        let valid = self.texturable_spectrum_keys();
        let bad = || {
            ParamError::Invalid(format!(
                "`{key}` cannot be textured here; texturable: {}",
                valid.join(", ")
            ))
        };
        check_reflectance(key, v)?;
        match (self, key) {
            (MaterialRecipe::Lambert { reflectance }, "reflectance")
            | (MaterialRecipe::OrenNayar { reflectance, .. }, "reflectance")
            | (
                MaterialRecipe::Conductor {
                    tint: reflectance, ..
                },
                "specular_reflectance",
            )
            | (
                MaterialRecipe::Dielectric {
                    reflect_tint: reflectance,
                    ..
                },
                "specular_reflectance",
            )
            | (
                MaterialRecipe::Dielectric {
                    transmit_tint: reflectance,
                    ..
                },
                "specular_transmittance",
            )
            | (
                MaterialRecipe::Il {
                    kd: reflectance, ..
                },
                "kd",
            ) => *reflectance = v,
            (MaterialRecipe::Kelemen(k), "kd") => *k = Arc::new(k.with_kd(v)?),
            (MaterialRecipe::Glint(g), "specular_reflectance") => g.params.tint = v,
            _ => return Err(bad()),
        }
        Ok(())
    }

    /// Replaces a roughness parameter (validated like the table's value).
    pub fn set_scalar(&mut self, key: &str, v: f64) -> ParamResult<()> {
        let valid = self.texturable_scalar_keys();
        if !valid.contains(&key) {
            return Err(ParamError::Invalid(format!(
                "`{key}` cannot be textured here; texturable: {}",
                if valid.is_empty() {
                    "none".to_string()
                } else {
                    valid.join(", ")
                }
            )));
        }
        match self {
            MaterialRecipe::OrenNayar { sigma, .. } => {
                *sigma = check_range(
                    "sigma",
                    v,
                    0.0,
                    0.5 * std::f64::consts::PI,
                    Bounds::ClosedOpen,
                )?;
            }
            MaterialRecipe::Conductor { lobe: Some(l), .. }
            | MaterialRecipe::Dielectric { lobe: Some(l), .. }
            | MaterialRecipe::Il { lobe: Some(l), .. } => {
                let ndf = with_roughness(&l.ndf, key, v)?;
                *l = SpecularLobe::new(ndf, l.masking, l.sampling())?;
            }
            _ => {}
        }
        Ok(())
    }
}

/// The distribution with one roughness parameter replaced (small widths are clamped to the
/// smallest rough width, 1e-4). Each value is range-checked once: a width α here (the
/// constructors then take it as checked), σ and the Phong exponent by their constructors.
fn with_roughness(ndf: &Ndf, key: &str, v: f64) -> ParamResult<Ndf> {
    use crate::microfacet::{Beckmann, Gaussian, Ggx, Phong, SMOOTH_ALPHA};
    let width = || check_alpha_or_smooth(key, v).map(|a| a.max(SMOOTH_ALPHA));
    Ok(match (ndf, key) {
        (Ndf::Beckmann(b), "alpha") => {
            let w = width()?;
            Ndf::Beckmann(Beckmann::from_checked(w, w).with_g1(b.g1_form()))
        }
        (Ndf::Beckmann(b), "alpha_u") => {
            Ndf::Beckmann(Beckmann::from_checked(width()?, b.alpha_y()).with_g1(b.g1_form()))
        }
        (Ndf::Beckmann(b), "alpha_v") => {
            Ndf::Beckmann(Beckmann::from_checked(b.alpha_x(), width()?).with_g1(b.g1_form()))
        }
        (Ndf::Ggx(_), "alpha") => {
            let w = width()?;
            Ndf::Ggx(Ggx::from_checked(w, w))
        }
        (Ndf::Ggx(g), "alpha_u") => Ndf::Ggx(Ggx::from_checked(width()?, g.alpha_y())),
        (Ndf::Ggx(g), "alpha_v") => Ndf::Ggx(Ggx::from_checked(g.alpha_x(), width()?)),
        // σ = 0 is the smooth limit, clamped like α; a negative σ must not be clamped.
        (Ndf::Gaussian(_), "sigma") if v >= 0.0 => {
            Ndf::Gaussian(Gaussian::new(v.max(SMOOTH_ALPHA))?)
        }
        (Ndf::Gaussian(_), "sigma") => Ndf::Gaussian(Gaussian::new(v)?),
        (Ndf::Phong(_), "exponent") => Ndf::Phong(Phong::new(v)?),
        _ => {
            return Err(ParamError::Invalid(format!(
                "`{key}` is not a roughness parameter of {}",
                crate::microfacet::Distribution::describe(ndf)
            )))
        }
    })
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

fn parse_oren_nayar(p: &Params) -> ParamResult<MaterialRecipe> {
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

/// The conductor's Fresnel term from `material`, `eta`/`k` and `fresnel`.
pub(super) fn parse_conductor_fresnel(p: &Params) -> ParamResult<Fresnel> {
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

/// The `scattering`, `energy` and `height_distribution` keys of conductors and dielectrics.
fn parse_energy(p: &Params) -> ParamResult<MicrofacetEnergy> {
    let multiple = match p.str("scattering")?.unwrap_or("single") {
        "single" => false,
        "multiple" => true,
        other => return Err(choice("scattering", other, &["single", "multiple"])),
    };
    let compensated = match p.str("energy")?.unwrap_or("uncompensated") {
        "uncompensated" => false,
        "compensated" => true,
        other => return Err(choice("energy", other, &["uncompensated", "compensated"])),
    };
    let heights = p.str("height_distribution")?;
    if heights.is_some() && !multiple {
        return Err(ParamError::Invalid(
            "`height_distribution` applies to scattering = \"multiple\"".into(),
        ));
    }
    match (multiple, compensated) {
        (true, true) => Err(ParamError::Invalid(
            "energy = \"compensated\" approximates what scattering = \"multiple\" computes: \
             choose one"
                .into(),
        )),
        (true, false) => Ok(MicrofacetEnergy::Multiple(match heights {
            Some(h) => HeightDistribution::parse(h)?,
            None => HeightDistribution::Uniform,
        })),
        (false, true) => Ok(MicrofacetEnergy::Compensated),
        (false, false) => Ok(MicrofacetEnergy::Single),
    }
}

/// `masking`, defaulting to the height-correlated Smith form with scattering = "multiple"
/// (the random walk's first order).
fn parse_masking_for(
    p: &Params,
    ndf: Option<&Ndf>,
    energy: MicrofacetEnergy,
) -> ParamResult<crate::microfacet::Masking> {
    match energy {
        MicrofacetEnergy::Multiple(_) if !p.has("masking") => {
            Ok(crate::microfacet::Masking::SmithCorrelated)
        }
        _ => parse_masking(p, ndf),
    }
}

fn parse_conductor(p: &Params) -> ParamResult<MaterialRecipe> {
    let ndf = parse_distribution(p, true)?;
    let energy = parse_energy(p)?;
    let masking = parse_masking_for(p, ndf.as_ref(), energy)?;
    let sampling = match p.str("sampling")? {
        None => NormalSampling::Visible,
        Some(s) => NormalSampling::parse(s)?,
    };
    let fresnel = parse_conductor_fresnel(p)?;
    let tint = check_reflectance(
        "specular_reflectance",
        p.spectrum("specular_reflectance")?.unwrap_or(Spectrum::ONE),
    )?;
    p.finish(&keys(CONDUCTOR_KEYS, true))?;
    let lobe = match ndf {
        Some(n) => Some(SpecularLobe::new(n, masking, sampling)?),
        None => None,
    };
    let recipe = MaterialRecipe::Conductor {
        lobe,
        fresnel,
        tint,
        energy,
    };
    if energy != MicrofacetEnergy::Single {
        // Reports unsupported combinations now (and builds the shared tables once).
        recipe.build()?;
    }
    Ok(recipe)
}

fn parse_dielectric(p: &Params) -> ParamResult<MaterialRecipe> {
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
    let energy = parse_energy(p)?;
    let masking = parse_masking_for(p, ndf.as_ref(), energy)?;
    let (sampling, widened) = match p.str("sampling")?.unwrap_or("visible") {
        "widened" => (NormalSampling::Distribution, true),
        s => (
            NormalSampling::parse(s)
                .map_err(|_| choice("sampling", s, &["visible", "distribution", "widened"]))?,
            false,
        ),
    };
    let rt = check_reflectance(
        "specular_reflectance",
        p.spectrum("specular_reflectance")?.unwrap_or(Spectrum::ONE),
    )?;
    let tt = check_reflectance(
        "specular_transmittance",
        p.spectrum("specular_transmittance")?
            .unwrap_or(Spectrum::ONE),
    )?;
    p.finish(&keys(DIELECTRIC_KEYS, true))?;
    let lobe = match ndf {
        Some(n) => Some(SpecularLobe::new(n, masking, sampling)?),
        None => None,
    };
    let recipe = MaterialRecipe::Dielectric {
        lobe,
        eta: ior / ext,
        widened,
        reflect_tint: rt,
        transmit_tint: tt,
        energy,
    };
    recipe.build()?;
    Ok(recipe)
}

fn parse_il(p: &Params, base_dir: &std::path::Path) -> ParamResult<MaterialRecipe> {
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

fn parse_kelemen(p: &Params) -> ParamResult<MaterialRecipe> {
    let name = p.str("distribution")?.unwrap_or("ward");
    let rough = match name {
        "phong" => p.required_f64("exponent")?,
        _ => p.required_f64("alpha")?,
    };
    let density = HalfVectorDensity::new(name, rough)?;
    let ior = check_ior(p.f64_or("ior", 1.5)?)?;
    let kd = p.spectrum("kd")?.unwrap_or(Spectrum::splat(0.5));
    let samples = p.usize("table_samples")?.unwrap_or(16384);
    p.finish(&keys(KELEMEN_KEYS, false))?;
    Ok(MaterialRecipe::Kelemen(Arc::new(Kelemen::new(
        density,
        Fresnel::Dielectric { eta: ior },
        kd,
        samples,
    )?)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recipe::parse_inline_table;

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
    fn recipes_take_texture_overrides() {
        let t = parse_inline_table(r#"{type = "il", kd = 0.5, distribution = "ggx", alpha = 0.3}"#)
            .unwrap();
        let mut r = MaterialRecipe::parse(&t, std::path::Path::new(".")).unwrap();
        r.set_spectrum("kd", Spectrum::rgb(0.9, 0.1, 0.1)).unwrap();
        r.set_scalar("alpha", 0.05).unwrap();
        let d = r.build().unwrap().describe();
        assert!(
            d.contains("kd=[0.9, 0.1, 0.1]") && d.contains("ggx(alpha=0.05)"),
            "{d}"
        );
        let e = r.set_scalar("sigma", 0.2).unwrap_err().to_string();
        assert!(e.contains("texturable: alpha, alpha_u, alpha_v"), "{e}");
        let e = r
            .set_spectrum("kd", Spectrum::splat(1.5))
            .unwrap_err()
            .to_string();
        assert!(e.contains("kd"), "{e}");
        let t =
            parse_inline_table(r#"{type = "kelemen", alpha = 0.3, table_samples = 256}"#).unwrap();
        let mut k = MaterialRecipe::parse(&t, std::path::Path::new(".")).unwrap();
        k.set_spectrum("kd", Spectrum::splat(0.25)).unwrap();
        assert!(k.texturable_scalar_keys().is_empty());
        let t = parse_inline_table(r#"{type = "conductor", alpha = 0}"#).unwrap();
        let mut c = MaterialRecipe::parse(&t, std::path::Path::new(".")).unwrap();
        assert!(
            c.set_scalar("alpha", 0.2).is_err(),
            "a smooth conductor has no roughness to texture"
        );
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
