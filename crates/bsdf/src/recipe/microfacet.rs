//! The microfacet keys shared by every rough model.
//!
//! | key | values | default |
//! |---|---|---|
//! | `distribution` | `beckmann`, `ggx`, `gaussian`, `phong` | `beckmann` |
//! | `alpha` | isotropic width (Beckmann, GGX; Phong via α_p = 2/α² − 2), 0 = smooth | — |
//! | `alpha_u`, `alpha_v` | anisotropic widths along the tangent and bitangent | — |
//! | `sigma` | Gaussian width in radians, (0, π/2) | — |
//! | `exponent` | Phong exponent α_p ≥ 0 | — |
//! | `g1` | `exact` or `rational` (Beckmann), `rational` or `numeric` (Phong) | `exact` / `rational` |
//! | `masking` | `smith`, `smith-correlated`, `v-cavity`, `kelemen` | `smith` (`v-cavity` for gaussian) |
//! | `sampling` | `visible`, `distribution` | `visible` |

use super::params::{choice, Params};
use crate::checks::{check_alpha, check_alpha_or_smooth};
use crate::error::{ParamError, ParamResult};
use crate::microfacet::specular_lobe::{NormalSampling, SpecularLobe};
use crate::microfacet::{
    Beckmann, BeckmannG1, Gaussian, Ggx, Masking, Ndf, Phong, PhongG1, SMOOTH_ALPHA,
};

pub const MICROFACET_KEYS: &[&str] = &[
    "distribution",
    "alpha",
    "alpha_u",
    "alpha_v",
    "sigma",
    "exponent",
    "g1",
    "masking",
    "sampling",
];

pub const DISTRIBUTION_NAMES: &[&str] = &["beckmann", "ggx", "gaussian", "phong"];

/// Reads the distribution keys. `Ok(None)` means a perfectly smooth surface (alpha = 0,
/// or below 1e-4), which only models with delta lobes accept (`allow_smooth`).
pub fn parse_distribution(p: &Params, allow_smooth: bool) -> ParamResult<Option<Ndf>> {
    let name = p.str("distribution")?.unwrap_or("beckmann");
    let g1 = p.str("g1")?;
    let ndf = match name {
        "beckmann" | "ggx" => {
            let (ax, ay) = match (p.f64("alpha")?, p.f64("alpha_u")?, p.f64("alpha_v")?) {
                (Some(a), None, None) => {
                    check_alpha_or_smooth("alpha", a)?;
                    (a, a)
                }
                // Each width is checked under the key the user wrote. Anisotropic widths
                // are positive: a smooth surface is written `alpha = 0`, and a zero along
                // one axis only would be silently widened.
                (None, Some(u), Some(v)) => {
                    (check_alpha("alpha_u", u)?, check_alpha("alpha_v", v)?)
                }
                (None, None, None) => {
                    return Err(ParamError::MissingKey {
                        key: "alpha (or alpha_u and alpha_v)".into(),
                        context: p.context().into(),
                    })
                }
                _ => {
                    return Err(ParamError::Invalid(
                        "give either `alpha`, or both `alpha_u` and `alpha_v`".into(),
                    ))
                }
            };
            // The range check above is the one of a table's widths: the constructors below
            // take them as checked.
            if ax < SMOOTH_ALPHA && ay < SMOOTH_ALPHA {
                if g1.is_some() {
                    return Err(ParamError::Invalid(
                        "`g1` has no effect on a smooth surface".into(),
                    ));
                }
                return smooth(allow_smooth, ax.max(ay));
            }
            let (ax, ay) = (ax.max(SMOOTH_ALPHA), ay.max(SMOOTH_ALPHA));
            if name == "beckmann" {
                let form = match g1.unwrap_or("exact") {
                    "exact" => BeckmannG1::Exact,
                    "rational" => BeckmannG1::Rational,
                    other => return Err(choice("g1", other, &["exact", "rational"])),
                };
                Ndf::Beckmann(Beckmann::from_checked(ax, ay).with_g1(form))
            } else {
                if let Some(other) = g1 {
                    if other != "exact" {
                        return Err(choice("g1", other, &["exact"]));
                    }
                }
                Ndf::Ggx(Ggx::from_checked(ax, ay))
            }
        }
        "gaussian" => {
            let sigma = p.f64("sigma")?.ok_or_else(|| ParamError::MissingKey {
                key: "sigma".into(),
                context: p.context().into(),
            })?;
            if sigma == 0.0 {
                return smooth(allow_smooth, 0.0);
            }
            if g1.is_some() {
                return Err(ParamError::Invalid(
                    "`g1` does not apply to the gaussian distribution".into(),
                ));
            }
            Ndf::Gaussian(Gaussian::new(sigma)?)
        }
        "phong" => {
            let ph = match (p.f64("exponent")?, p.f64("alpha")?) {
                (Some(n), None) => Phong::new(n)?,
                (None, Some(a)) => Phong::from_beckmann_alpha(a)?,
                (None, None) => {
                    return Err(ParamError::MissingKey {
                        key: "exponent (or alpha)".into(),
                        context: p.context().into(),
                    })
                }
                _ => {
                    return Err(ParamError::Invalid(
                        "give either `exponent` or `alpha` for the phong distribution".into(),
                    ))
                }
            };
            let form = match g1.unwrap_or("rational") {
                "rational" => PhongG1::Rational,
                "numeric" => PhongG1::Numeric,
                other => return Err(choice("g1", other, &["rational", "numeric"])),
            };
            Ndf::Phong(ph.with_g1(form))
        }
        other => return Err(choice("distribution", other, DISTRIBUTION_NAMES)),
    };
    Ok(Some(ndf))
}

fn smooth(allow: bool, alpha: f64) -> ParamResult<Option<Ndf>> {
    if allow {
        Ok(None)
    } else {
        Err(ParamError::OutOfRange {
            name: "alpha".into(),
            value: alpha,
            expected: format!("alpha >= {SMOOTH_ALPHA} (this model has no smooth limit)"),
        })
    }
}

/// Reads `masking` (default: `smith`, or `v-cavity` for the Gaussian).
pub fn parse_masking(p: &Params, ndf: Option<&Ndf>) -> ParamResult<Masking> {
    match p.str("masking")? {
        Some(m) => Masking::parse(m),
        None => Ok(match ndf {
            Some(Ndf::Gaussian(_)) => Masking::VCavity,
            _ => Masking::SmithSeparable,
        }),
    }
}

/// Reads `sampling` (default: visible normals).
pub fn parse_sampling(p: &Params) -> ParamResult<NormalSampling> {
    match p.str("sampling")? {
        Some(s) => NormalSampling::parse(s),
        None => Ok(NormalSampling::Visible),
    }
}

/// The distribution with one roughness parameter replaced (small widths are clamped to the
/// smallest rough width, 1e-4). Each value is range-checked once: a width α here (the
/// constructors then take it as checked), σ and the Phong exponent by their constructors.
pub fn with_roughness(ndf: &Ndf, key: &str, v: f64) -> ParamResult<Ndf> {
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

/// Distribution, masking and sampling together; `Ok(None)` for a smooth surface.
pub fn parse_specular_lobe(p: &Params, allow_smooth: bool) -> ParamResult<Option<SpecularLobe>> {
    let ndf = parse_distribution(p, allow_smooth)?;
    let masking = parse_masking(p, ndf.as_ref())?;
    let sampling = parse_sampling(p)?;
    match ndf {
        None => Ok(None),
        Some(n) => SpecularLobe::new(n, masking, sampling).map(Some),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::microfacet::Distribution;
    use crate::recipe::parse_inline_table;

    fn lobe(s: &str) -> ParamResult<Option<SpecularLobe>> {
        let t = parse_inline_table(s).unwrap();
        let p = Params::new(&t, "test");
        let r = parse_specular_lobe(&p, true)?;
        p.finish(MICROFACET_KEYS)?;
        Ok(r)
    }

    #[test]
    fn parses_every_distribution() {
        let l = lobe(r#"{distribution = "ggx", alpha_u = 0.1, alpha_v = 0.4}"#)
            .unwrap()
            .unwrap();
        assert_eq!(l.ndf.describe(), "ggx(alpha_u=0.1, alpha_v=0.4)");
        let l = lobe(r#"{distribution = "gaussian", sigma = 0.3}"#)
            .unwrap()
            .unwrap();
        assert_eq!(l.masking, Masking::VCavity);
        let l = lobe(r#"{distribution = "phong", alpha = 0.2, g1 = "numeric"}"#)
            .unwrap()
            .unwrap();
        assert_eq!(l.ndf.describe(), "phong(exponent=48, numeric G1)");
        assert!(lobe(r#"{alpha = 0}"#).unwrap().is_none());
    }

    #[test]
    fn bad_parameters_are_clear_errors() {
        let e = lobe(r#"{alpha = -0.1}"#).unwrap_err().to_string();
        assert!(e.contains("`alpha` = -0.1 is out of range"), "{e}");
        let e = lobe(r#"{distribution = "gauss", sigma = 0.3}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("beckmann, ggx, gaussian, phong"), "{e}");
        let e = lobe(r#"{distribution = "gaussian", sigma = 2.0}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("sigma"), "{e}");
        let e = lobe(r#"{distribution = "gaussian", sigma = 0.3, masking = "smith"}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("Smith Λ diverges"), "{e}");
        let e = lobe(r#"{alpha = 0.3, alhpa_u = 2}"#)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("unknown key `alhpa_u`") && e.contains("alpha_u"),
            "{e}"
        );
        let e = lobe(r#"{alpha = "rough"}"#).unwrap_err().to_string();
        assert!(e.contains("expected a number"), "{e}");
        let e = lobe(r#"{alpha = nan}"#).unwrap_err().to_string();
        assert!(e.contains("finite"), "{e}");
    }
}
