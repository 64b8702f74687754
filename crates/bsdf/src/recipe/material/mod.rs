//! Material tables parsed into recipes, and recipes built into BSDFs: `type` selects the
//! model, the other keys are its parameters (documented per model and in
//! `docs/materials.md`). This file holds what every family shares — the [`MaterialRecipe`]
//! enum, the dispatch on `type`, texture overrides — and each family of models has its
//! file: [`diffuse`] (Lambert, Oren–Nayar), [`microfacet_models`] (conductors and
//! dielectrics, single or multiple scattering, compensated), [`kelemen`], [`il`]
//! (interfaced Lambertian) and [`glint`].

mod diffuse;
pub mod glint;
mod il;
mod kelemen;
mod microfacet_models;

pub use diffuse::{parse_evaluation, OrenNayarModel};
pub use il::IlEvaluation;
pub use microfacet_models::MicrofacetEnergy;

use super::microfacet::{with_roughness, MICROFACET_KEYS};
use super::params::Params;
use crate::bsdf::Bsdf;
use crate::checks::{check_range, check_reflectance, Bounds};
use crate::error::{ParamError, ParamResult};
use crate::fresnel::Fresnel;
use crate::math::spectrum::Spectrum;
use crate::microfacet::specular_lobe::SpecularLobe;
use crate::microfacet::Ndf;
use crate::models::il::interfaced_lambertian::Scattering;
use crate::models::lane_models::{LaneBsdf, LaneFresnel, LaneNdf};
use crate::models::oren_nayar::IntegralEvaluation;
use crate::models::Kelemen;
use crate::two_sided::TwoSided;
use diffuse::{LAMBERT_KEYS, OREN_NAYAR_KEYS};
use glint::{parse_glint, GlintRecipe, NormalMapReader, GLINT_KEYS};
use il::IL_KEYS;
use kelemen::KELEMEN_KEYS;
use microfacet_models::{CONDUCTOR_KEYS, DIELECTRIC_KEYS};
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

/// The keys of a material type: `type`, the microfacet keys where the type has a
/// microfacet lobe, and `extra` — the type's own keys, checked before anything else so that
/// a misspelt key is reported as unknown, with the valid ones, rather than as a missing
/// required key.
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
        /// `multiple_evaluation = "quadrature"`: the V-cavity multiple scattering by
        /// quadrature to this relative tolerance (`None`: the walk).
        multiple_tolerance: Option<f64>,
    },
    /// Glints [CCM19]: its BSDF depends on the footprint of each shading point
    /// ([`MaterialRecipe::build_at`]).
    Glint(GlintRecipe),
}

impl MaterialRecipe {
    /// The lane model of the recipe (`models::lane_models`: the renderer's packet kernel
    /// evaluates it in f32 lanes), or `None` where the recipe needs its f64 model.
    pub fn lane_model(&self) -> Option<LaneBsdf> {
        let lobe_ndf = |lobe: &Option<crate::microfacet::specular_lobe::SpecularLobe>| {
            let l = lobe.as_ref()?;
            let plain = l.masking == crate::microfacet::Masking::SmithSeparable
                && l.sampling() == crate::microfacet::specular_lobe::NormalSampling::Visible;
            if plain {
                LaneNdf::from_ndf(&l.ndf)
            } else {
                None
            }
        };
        match self {
            MaterialRecipe::Lambert { reflectance } => Some(LaneBsdf::Lambert {
                reflectance: reflectance.0,
            }),
            MaterialRecipe::Conductor {
                lobe,
                fresnel,
                tint,
                energy: microfacet_models::MicrofacetEnergy::Single,
            } => Some(LaneBsdf::Conductor {
                ndf: lobe_ndf(lobe)?,
                fresnel: LaneFresnel::from_fresnel(fresnel)?,
                tint: tint.0,
            }),
            MaterialRecipe::Dielectric {
                lobe,
                eta,
                widened: false,
                reflect_tint,
                transmit_tint,
                energy: microfacet_models::MicrofacetEnergy::Single,
            } => Some(LaneBsdf::Dielectric {
                ndf: lobe_ndf(lobe)?,
                eta: *eta,
                reflect_tint: reflect_tint.0,
                transmit_tint: transmit_tint.0,
            }),
            MaterialRecipe::Il {
                kd,
                ni,
                lobe: lobe @ Some(_),
                evaluation: il::IlEvaluation::Stochastic,
                scattering: crate::models::il::interfaced_lambertian::Scattering::Single,
                multiple_tolerance: None,
            } => {
                let ndf = lobe_ndf(lobe)?;
                let model = crate::models::il::InterfacedLambertian::new(
                    *kd,
                    *ni,
                    lobe.clone(),
                    crate::models::il::interfaced_lambertian::BodyEvaluation::Stochastic,
                    crate::models::il::interfaced_lambertian::Scattering::Single,
                )
                .ok()?;
                Some(LaneBsdf::il(ndf, &model))
            }
            _ => None,
        }
    }

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
            "lambert" | "diffuse" => diffuse::parse_lambert(&p),
            "oren-nayar" => diffuse::parse_oren_nayar(&p),
            "conductor" => microfacet_models::parse_conductor(&p),
            "dielectric" => microfacet_models::parse_dielectric(&p),
            "kelemen" => kelemen::parse_kelemen(&p),
            "il" | "interfaced-lambertian" => il::parse_il(&p, base_dir),
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
        match self {
            MaterialRecipe::Lambert { reflectance } => diffuse::build_lambert(*reflectance),
            MaterialRecipe::OrenNayar {
                reflectance,
                sigma,
                model,
                evaluation,
            } => diffuse::build_oren_nayar(*reflectance, *sigma, *model, *evaluation),
            MaterialRecipe::Conductor {
                lobe,
                fresnel,
                tint,
                energy,
            } => microfacet_models::build_conductor(lobe, *fresnel, *tint, *energy),
            MaterialRecipe::Dielectric {
                lobe,
                eta,
                widened,
                reflect_tint,
                transmit_tint,
                energy,
            } => microfacet_models::build_dielectric(
                lobe,
                *eta,
                *widened,
                (*reflect_tint, *transmit_tint),
                *energy,
            ),
            // The recipe keeps the model (its tables are shared by textured copies); the
            // BSDF is its two-sided view.
            MaterialRecipe::Kelemen(k) => Ok(Arc::new(TwoSided::new(Kelemen::clone(k)))),
            MaterialRecipe::Il {
                kd,
                ni,
                lobe,
                evaluation,
                scattering,
                multiple_tolerance,
            } => il::build_il(*kd, *ni, lobe, evaluation, *scattering, *multiple_tolerance),
            MaterialRecipe::Glint(g) => Ok(g.build_default()),
        }
    }

    /// Why evaluating this material costs far more than a path tracer expects, if it does:
    /// adaptive quadrature (IL or exact Oren–Nayar `evaluation = "quadrature"` without
    /// `samples`) integrates to its tolerance at every evaluation, about 2 ms each. The
    /// renderer warns about it; the lab wants exactly that.
    pub fn render_cost_warning(&self) -> Option<&'static str> {
        let adaptive = match self {
            MaterialRecipe::Il {
                evaluation,
                multiple_tolerance,
                ..
            } => {
                matches!(evaluation, IlEvaluation::Adaptive { .. }) || multiple_tolerance.is_some()
            }
            MaterialRecipe::OrenNayar { evaluation, .. } => matches!(
                evaluation,
                crate::models::oren_nayar::IntegralEvaluation::Adaptive { .. }
            ),
            _ => false,
        };
        adaptive.then_some(
            "evaluation = \"quadrature\" (or multiple_evaluation = \"quadrature\") integrates \
             adaptively to its tolerance at every shading point (milliseconds each): renders \
             want evaluation = \"stochastic\" or a fixed set, samples = N, and the V-cavity walk",
        )
    }

    /// True when the BSDF depends on the shading point's footprint (glints): the renderer
    /// must build it per hit with [`MaterialRecipe::build_at`].
    pub fn varies_per_hit(&self) -> bool {
        matches!(self, MaterialRecipe::Glint(_))
    }

    /// Whether the renderer should give this material the footprint of the whole pixel at a
    /// camera ray's first hit (glints with `footprint = "pixel"`).
    pub fn reads_pixel_footprint(&self) -> bool {
        matches!(self, MaterialRecipe::Glint(g) if g.reads_pixel_footprint())
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
            r#"{type = "kelemen", alpha = 0.3, table_tolerance = 1e-5}"#,
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
    fn kelemen_table_tolerance_is_validated() {
        for (s, want) in [
            (
                r#"{type = "kelemen", alpha = 0.3, table_tolerance = 0.5}"#,
                "table_tolerance",
            ),
            (
                r#"{type = "kelemen", alpha = 0.3, table_tolerance = 0}"#,
                "<= 0.1",
            ),
            (
                r#"{type = "kelemen", alpha = 0.3, table_tolerance = nan}"#,
                "table_tolerance",
            ),
            (
                r#"{type = "kelemen", alpha = 0.3, table_tolerance = 1e-4, table_samples = 256}"#,
                "exclusive",
            ),
        ] {
            let e = build(s).err().unwrap_or_else(|| panic!("{s}")).to_string();
            assert!(e.contains(want), "{s}: {e}");
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
