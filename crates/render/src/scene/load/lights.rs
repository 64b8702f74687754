//! Lights: area lights from emissive objects, the described lights (point, spot,
//! directional; environments in `super::environment`), and the light selector.

use super::context::Ctx;
use super::environment::{create_constant, create_environment_map};
use super::values::{finite3, vec3};
use crate::geometry::{SceneGeometry, Vec3};
use crate::lights::{Light, LightSelector};
use crate::scene::description::{ColorDesc, LightDesc};
use crate::scene::SceneError;
use facette_bsdf::Spectrum;
use std::ops::Range;
use toml::Spanned;

/// The lights of a scene and which shape is which light.
pub(super) struct Lights {
    pub lights: Vec<Light>,
    /// Area-light index of each shape.
    pub shape_light: Vec<Option<u32>>,
    /// Index of the environment light.
    pub environment: Option<u32>,
}

/// One area light per emissive shape (in shape order), then the described lights.
pub(super) fn create_lights(
    ctx: &Ctx,
    shape_emission: &[Option<(Spectrum, bool)>],
    desc: &[Spanned<LightDesc>],
) -> Result<Lights, SceneError> {
    let mut lights: Vec<Light> = Vec::new();
    let mut shape_light = vec![None; shape_emission.len()];
    for (s, em) in shape_emission.iter().enumerate() {
        if let Some((radiance, two_sided)) = em {
            shape_light[s] = Some(lights.len() as u32);
            lights.push(Light::Area {
                shape: s as u32,
                radiance: *radiance,
                two_sided: *two_sided,
            });
        }
    }
    let mut environment = None;
    for l in desc {
        let site = LightSite {
            ctx,
            span: l.span(),
            d: l.get_ref(),
        };
        let light = site.create()?;
        if matches!(light, Light::Environment(_)) {
            if environment.is_some() {
                return Err(site.err(
                    "the scene already has an environment (one `environment` or `constant` light)"
                        .into(),
                ));
            }
            environment = Some(lights.len() as u32);
        }
        lights.push(light);
    }
    Ok(Lights {
        lights,
        shape_light,
        environment,
    })
}

/// Chooses lights in proportion to their power; the power of infinite lights is taken
/// over a disk as large as the scene.
pub(super) fn create_selector(lights: &[Light], geometry: &SceneGeometry) -> LightSelector {
    let b = geometry.bounds();
    let radius = if b.is_empty() {
        1.0
    } else {
        0.5 * b.extent().length().max(1e-3)
    };
    let powers: Vec<f64> = lights.iter().map(|l| l.power(geometry, radius)).collect();
    let infinite: Vec<bool> = lights.iter().map(Light::is_infinite).collect();
    let reads_position: Vec<bool> = lights.iter().map(Light::reads_position_numbers).collect();
    LightSelector::new(&powers, &infinite, &reads_position)
}

/// One described light with where its errors point.
pub(super) struct LightSite<'a> {
    pub ctx: &'a Ctx<'a>,
    pub span: Range<usize>,
    pub d: &'a LightDesc,
}

impl LightSite<'_> {
    /// An error at the light, naming its type.
    pub fn err(&self, m: String) -> SceneError {
        self.ctx.err(
            Some(self.span.clone()),
            format!("light `{}`: {m}", self.d.kind),
        )
    }

    /// The colour `name`, required, finite and ≥ 0.
    pub fn color(&self, name: &str, c: Option<ColorDesc>) -> Result<Spectrum, SceneError> {
        let s = c
            .ok_or_else(|| self.err(format!("needs `{name}`")))?
            .spectrum();
        for c in 0..3 {
            facette_bsdf::limits::check_radiance(s[c])
                .map_err(|m| self.err(format!("`{name}`: {m}")))?;
        }
        Ok(s)
    }

    /// The point `name`, required and finite.
    fn point(&self, name: &str, a: Option<[f64; 3]>) -> Result<Vec3, SceneError> {
        let a = a.ok_or_else(|| self.err(format!("needs `{name}`")))?;
        finite3(self.ctx, &self.span, name, a)
    }

    fn create(&self) -> Result<Light, SceneError> {
        self.check_keys()?;
        let d = self.d;
        match d.kind.as_str() {
            "point" => Ok(Light::Point {
                position: self.point("position", d.position)?,
                intensity: self.color("intensity", d.intensity)?,
            }),
            "spot" => self.create_spot(),
            "directional" => {
                let dir = self.point("direction", d.direction)?;
                if !(dir.length() > 0.0) {
                    return Err(self.err("`direction` must be non-zero".into()));
                }
                Ok(Light::Directional {
                    direction: dir.normalize(),
                    irradiance: self.color("irradiance", d.irradiance)?,
                })
            }
            "constant" => create_constant(self),
            _ => create_environment_map(self),
        }
    }

    /// Rejects an unknown type and the keys that do not apply to this one.
    fn check_keys(&self) -> Result<(), SceneError> {
        let d = self.d;
        let allowed: &[&str] = match d.kind.as_str() {
            "point" => &["position", "intensity"],
            "spot" => &[
                "position",
                "target",
                "direction",
                "intensity",
                "cutoff_angle",
                "beam_width",
            ],
            "directional" => &["direction", "irradiance"],
            "environment" => &["file", "sky", "scale", "transform"],
            "constant" => &["radiance"],
            other => {
                return Err(self.err(format!("unknown light type `{other}`; valid: point, spot, directional, environment, constant")));
            }
        };
        for (key, present) in [
            ("position", d.position.is_some()),
            ("target", d.target.is_some()),
            ("direction", d.direction.is_some()),
            ("intensity", d.intensity.is_some()),
            ("irradiance", d.irradiance.is_some()),
            ("radiance", d.radiance.is_some()),
            ("cutoff_angle", d.cutoff_angle.is_some()),
            ("beam_width", d.beam_width.is_some()),
            ("file", d.file.is_some()),
            ("sky", d.sky.is_some()),
            ("scale", d.scale.is_some()),
            ("transform", !d.transform.is_empty()),
        ] {
            if present && !allowed.contains(&key) {
                return Err(self.err(format!(
                    "`{key}` does not apply; valid keys: {}",
                    allowed.join(", ")
                )));
            }
        }
        Ok(())
    }

    fn create_spot(&self) -> Result<Light, SceneError> {
        let d = self.d;
        let position = self.point("position", d.position)?;
        let dir = match (d.target, d.direction) {
            (Some(t), None) => vec3(t) - position,
            (None, Some(dd)) => vec3(dd),
            (None, None) => return Err(self.err("needs `target` or `direction`".into())),
            _ => return Err(self.err("give `target` or `direction`, not both".into())),
        };
        if !(dir.length() > 0.0) || !dir.is_finite() {
            return Err(self.err("the spot direction must be a non-zero vector".into()));
        }
        let cutoff = d.cutoff_angle.unwrap_or(20.0);
        let beam = d.beam_width.unwrap_or(0.75 * cutoff);
        if !(cutoff > 0.0 && cutoff <= 90.0 && beam >= 0.0 && beam <= cutoff) {
            return Err(self.err(format!("need 0 < cutoff_angle ≤ 90 and 0 ≤ beam_width ≤ cutoff_angle (degrees), got {cutoff} and {beam}")));
        }
        Ok(Light::Spot {
            position,
            frame: facette_bsdf::math::Frame::from_normal(dir.normalize()),
            intensity: self.color("intensity", d.intensity)?,
            cutoff: cutoff.to_radians(),
            beam: beam.to_radians(),
        })
    }
}
