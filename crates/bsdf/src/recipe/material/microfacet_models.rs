//! The microfacet family: `conductor` and `dielectric` — rough or smooth, with single
//! scattering, the multiple-scattering random walk (`scattering = "multiple"`) or the
//! energy-compensation lobe (`energy = "compensated"`). The conductor's Fresnel keys are
//! shared with `glint`.

use super::{keys, MaterialRecipe};
use crate::bsdf::Bsdf;
use crate::checks::{check_range, check_reflectance, check_spectrum, Bounds};
use crate::error::{ParamError, ParamResult};
use crate::fresnel::{fresnel_conductor, Fresnel, MetalPreset};
use crate::math::spectrum::Spectrum;
use crate::microfacet::specular_lobe::{NormalSampling, SpecularLobe};
use crate::microfacet::{Masking, Ndf};
use crate::models::multiple_scattering::smith_microsurface::HeightDistribution;
use crate::models::rough_dielectric::{MEASURED_GLASSES, MEASURED_GLASS_IOR};
use crate::models::{
    CompensatedConductor, CompensatedDielectric, MultipleScatteringConductor,
    MultipleScatteringDielectric, RoughConductor, RoughDielectric,
};
use crate::recipe::microfacet::{parse_distribution, parse_masking};
use crate::recipe::params::{choice, Params};
use crate::two_sided::TwoSided;
use std::sync::Arc;

pub(super) const CONDUCTOR_KEYS: &[&str] = &[
    "material",
    "eta",
    "k",
    "fresnel",
    "specular_reflectance",
    "scattering",
    "energy",
    "height_distribution",
];
pub(super) const DIELECTRIC_KEYS: &[&str] = &[
    "ior",
    "ext_ior",
    "preset",
    "specular_reflectance",
    "specular_transmittance",
    "scattering",
    "energy",
    "height_distribution",
];

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

/// The conductor's Fresnel term from `material`, `eta`/`k` and `fresnel`.
pub(in crate::recipe) fn parse_conductor_fresnel(p: &Params) -> ParamResult<Fresnel> {
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
) -> ParamResult<Masking> {
    match energy {
        MicrofacetEnergy::Multiple(_) if !p.has("masking") => Ok(Masking::SmithCorrelated),
        _ => parse_masking(p, ndf),
    }
}

pub(super) fn parse_conductor(p: &Params) -> ParamResult<MaterialRecipe> {
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

pub(super) fn parse_dielectric(p: &Params) -> ParamResult<MaterialRecipe> {
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
    // The model's own range is on the ratio; it is reported under the keys the user wrote.
    let eta = ior / ext;
    if !(1e-3..=1e3).contains(&eta) {
        return Err(ParamError::OutOfRange {
            name: "ior / ext_ior".into(),
            value: eta,
            expected: "1e-3 <= ior / ext_ior <= 1e3".into(),
        });
    }
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

/// A rough or smooth conductor; a smooth surface has no inter-reflections, so every energy
/// mode is the mirror.
pub(super) fn build_conductor(
    lobe: &Option<SpecularLobe>,
    fresnel: Fresnel,
    tint: Spectrum,
    energy: MicrofacetEnergy,
) -> ParamResult<Arc<dyn Bsdf>> {
    let single = RoughConductor::new(lobe.clone(), fresnel, tint);
    Ok(match (energy, lobe) {
        (MicrofacetEnergy::Multiple(h), Some(_)) => {
            Arc::new(TwoSided::new(MultipleScatteringConductor::new(single, h)?))
        }
        (MicrofacetEnergy::Compensated, Some(_)) => {
            Arc::new(TwoSided::new(CompensatedConductor::new(single)?))
        }
        _ => Arc::new(TwoSided::new(single)),
    })
}

/// A rough or smooth dielectric (relative index `eta`).
pub(super) fn build_dielectric(
    lobe: &Option<SpecularLobe>,
    eta: f64,
    widened: bool,
    tints: (Spectrum, Spectrum),
    energy: MicrofacetEnergy,
) -> ParamResult<Arc<dyn Bsdf>> {
    let single = RoughDielectric::new(eta, lobe.clone(), widened, tints.0, tints.1)?;
    Ok(match (energy, lobe) {
        (MicrofacetEnergy::Multiple(h), Some(_)) => {
            Arc::new(MultipleScatteringDielectric::new(single, h)?)
        }
        (MicrofacetEnergy::Compensated, Some(_)) => Arc::new(CompensatedDielectric::new(single)?),
        _ => Arc::new(single),
    })
}
