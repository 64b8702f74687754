//! Environment lights: a constant radiance, or a lat-long map read from a file or made by
//! the procedural sky (whose keys are read here).

use super::lights::LightSite;
use super::values::{number, parse_transform, triple};
use crate::image::{
    generate_sky, load_or_generate_sky, read_image, ColorEncoding, ConstantEnvironment,
    EnvironmentMap, SkyParams,
};
use crate::lights::{Environment, Light};
use crate::scene::SceneError;
use facette_bsdf::Spectrum;
use glam::DMat3;

/// A `constant` light: the same radiance from every direction.
pub(super) fn create_constant(site: &LightSite) -> Result<Light, SceneError> {
    Ok(Light::Environment(Environment::Constant(
        ConstantEnvironment::new(site.color("radiance", site.d.radiance)?)
            .map_err(|x| site.err(x.to_string()))?,
    )))
}

/// An `environment` light: an image (`file`), a sky (`sky`), or both, the file then being
/// the sky's cache (written on first use); scaled and rotated by `transform`.
pub(super) fn create_environment_map(site: &LightSite) -> Result<Light, SceneError> {
    let d = site.d;
    let base_dir = &site.ctx.base_dir;
    let e = |m: String| site.err(m);
    let image = match (&d.file, &d.sky) {
        (Some(f), None) => {
            read_image(base_dir.join(f), ColorEncoding::Srgb).map_err(|x| e(x.to_string()))?
        }
        (None, Some(sky)) => {
            generate_sky(&parse_sky(sky).map_err(e)?).map_err(|x| e(x.to_string()))?
        }
        (Some(f), Some(sky)) => load_or_generate_sky(base_dir.join(f), &parse_sky(sky).map_err(e)?)
            .map_err(|x| e(x.to_string()))?,
        (None, None) => {
            return Err(e(
                "needs `file` (an EXR/HDR/PNG lat-long image) or `sky = { … }`".into(),
            ))
        }
    };
    let scale = d.scale.unwrap_or(1.0);
    facette_bsdf::limits::check_radiance(scale).map_err(|m| e(format!("`scale`: {m}")))?;
    let t = parse_transform(&d.transform).map_err(e)?;
    let m = t.matrix();
    let rot = DMat3::from_cols(
        m.x_axis.truncate(),
        m.y_axis.truncate(),
        m.z_axis.truncate(),
    );
    Ok(Light::Environment(Environment::Map(Box::new(
        EnvironmentMap::new(image, rot, scale).map_err(|x| e(x.to_string()))?,
    ))))
}

/// Procedural sky keys: `zenith`, `horizon`, `ground` (colours), `sun_direction` (toward
/// the sun), `sun_angular_radius` (degrees), `sun_radiance` (colour), `sun_softness`,
/// `gradient_exponent`, `width`, `height`.
fn parse_sky(t: &toml::Table) -> Result<SkyParams, String> {
    let mut p = SkyParams::default();
    let col = |v: &toml::Value, k: &str| -> Result<Spectrum, String> {
        match v {
            toml::Value::Array(_) => triple(v).map(|t| Spectrum::rgb(t.x, t.y, t.z)),
            _ => number(v).map(Spectrum::splat),
        }
        .ok_or(format!("sky `{k}` must be a number or [r, g, b]"))
    };
    for (k, v) in t {
        match k.as_str() {
            "zenith" => p.zenith = col(v, k)?,
            "horizon" => p.horizon = col(v, k)?,
            "ground" => p.ground = col(v, k)?,
            "sun_radiance" => p.sun_radiance = col(v, k)?,
            "sun_direction" => p.sun_direction = triple(v).ok_or("sky `sun_direction` must be [x, y, z]")?,
            "sun_angular_radius" => p.sun_angular_radius = number(v).ok_or("sky `sun_angular_radius` must be a number (degrees)")?.to_radians(),
            "sun_softness" => p.sun_softness = number(v).ok_or("sky `sun_softness` must be a number")?,
            "gradient_exponent" => p.gradient_exponent = number(v).ok_or("sky `gradient_exponent` must be a number")?,
            "width" => p.width = number(v).ok_or("sky `width` must be an integer")? as usize,
            "height" => p.height = number(v).ok_or("sky `height` must be an integer")? as usize,
            other => {
                return Err(format!(
                    "unknown sky key `{other}`; valid: zenith, horizon, ground, sun_direction, sun_angular_radius, sun_radiance, sun_softness, gradient_exponent, width, height"
                ))
            }
        }
    }
    p.validate().map_err(|e| e.to_string())?;
    Ok(p)
}
