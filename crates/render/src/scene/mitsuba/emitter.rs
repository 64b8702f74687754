//! Emitter plugins as facette lights.
//!
//! | Mitsuba | facette |
//! |---|---|
//! | `area` (`radiance`, default 1), inside a shape | the object's `emission` (front side only, as in Mitsuba) |
//! | `point` (`intensity` 1, `position` or `to_world`) | `point` at to_world · (0, 0, 0) |
//! | `spot` (`intensity` 1, `cutoff_angle` 20°, `beam_width` ¾ cutoff, `to_world`) | `spot` at to_world · (0, 0, 0) shining along to_world · (0, 0, 1) |
//! | `directional` (`irradiance` 1, `direction` or `to_world`) | `directional` along `direction` or to_world · (0, 0, 1) |
//! | `constant` (`radiance` 1) | `constant` |
//! | `envmap` (`filename`, `scale` 1, `to_world`) | `environment` (same lat-long mapping and orientation) |

use super::plugin::Plugin;
use super::texture::constant_color;
use super::translator::Translator;
use crate::scene::description::{ColorDesc, LightDesc};
use crate::scene::SceneError;
use glam::{DMat4, DVec3};
use toml::Spanned;

/// The emitter plugins facette reads.
pub(crate) const MITSUBA_EMITTERS: &[&str] =
    &["area", "point", "spot", "directional", "constant", "envmap"];

const WHAT: &str = "facette's lights have constant colours";

fn color(cx: &Translator, p: &Plugin, name: &str, default: f64) -> Result<ColorDesc, SceneError> {
    let c = constant_color(cx, p, name, WHAT)?.unwrap_or([default; 3]);
    Ok(ColorDesc::Rgb(c))
}

/// The radiance of an `area` emitter attached to a shape.
pub(crate) fn area_radiance(cx: &mut Translator, p: &Plugin) -> Result<ColorDesc, SceneError> {
    if p.kind != "area" {
        return Err(p.err(if MITSUBA_EMITTERS.contains(&p.kind.as_str()) {
            "only `area` emitters attach to shapes; put this one at the scene level".to_string()
        } else {
            unsupported(&p.kind)
        }));
    }
    let c = color(cx, p, "radiance", 1.0)?;
    p.finish(&["radiance"], &cx.reg)?;
    Ok(c)
}

fn unsupported(kind: &str) -> String {
    format!(
        "unsupported emitter `{kind}`; supported: {}",
        MITSUBA_EMITTERS.join(", ")
    )
}

fn empty_light(kind: &str) -> LightDesc {
    LightDesc {
        kind: kind.into(),
        position: None,
        target: None,
        direction: None,
        intensity: None,
        irradiance: None,
        radiance: None,
        cutoff_angle: None,
        beam_width: None,
        file: None,
        sky: None,
        scale: None,
        transform: Vec::new(),
    }
}

/// A `<transform>` as one facette transform step.
pub(crate) fn matrix_step(m: &DMat4) -> toml::Table {
    let rows = m.transpose().to_cols_array();
    let mut t = toml::Table::new();
    t.insert(
        "matrix".into(),
        toml::Value::Array(rows.iter().map(|v| toml::Value::Float(*v)).collect()),
    );
    t
}

/// A scene-level emitter as a facette light.
pub(crate) fn light(cx: &mut Translator, p: &Plugin) -> Result<Spanned<LightDesc>, SceneError> {
    let to_world = p.transform("to_world")?;
    let origin = to_world.map(|m| m.transform_point3(DVec3::ZERO).to_array());
    let axis = to_world.map(|m| m.transform_vector3(DVec3::Z).to_array());
    let light = match p.kind.as_str() {
        "point" => {
            let mut l = empty_light("point");
            l.intensity = Some(color(cx, p, "intensity", 1.0)?);
            l.position = match (p.vector("position")?, origin) {
                (Some(_), Some(_)) => return Err(p.err("give `position` or `to_world`, not both")),
                (Some(v), None) | (None, Some(v)) => Some(v),
                (None, None) => Some([0.0; 3]),
            };
            p.finish(&["intensity", "position", "to_world"], &cx.reg)?;
            l
        }
        "spot" => {
            let mut l = empty_light("spot");
            l.intensity = Some(color(cx, p, "intensity", 1.0)?);
            l.position = Some(origin.unwrap_or([0.0; 3]));
            l.direction = Some(axis.unwrap_or([0.0, 0.0, 1.0]));
            l.cutoff_angle = p.float("cutoff_angle")?;
            l.beam_width = p.float("beam_width")?;
            p.finish(
                &["intensity", "cutoff_angle", "beam_width", "to_world"],
                &cx.reg,
            )?;
            l
        }
        "directional" => {
            let mut l = empty_light("directional");
            l.irradiance = Some(color(cx, p, "irradiance", 1.0)?);
            l.direction = match (p.vector("direction")?, axis) {
                (Some(_), Some(_)) => return Err(p.err("give `direction` or `to_world`, not both")),
                (Some(v), None) | (None, Some(v)) => Some(v),
                (None, None) => Some([0.0, 0.0, 1.0]),
            };
            p.finish(&["irradiance", "direction", "to_world"], &cx.reg)?;
            l
        }
        "constant" => {
            let mut l = empty_light("constant");
            l.radiance = Some(color(cx, p, "radiance", 1.0)?);
            p.finish(&["radiance"], &cx.reg)?;
            l
        }
        "envmap" => {
            let mut l = empty_light("environment");
            let path = cx
                .file(p, "filename")?
                .ok_or_else(|| p.err("needs `filename` (a lat-long EXR, HDR or PNG image)"))?;
            l.file = Some(
                path.to_str()
                    .ok_or_else(|| p.err("the file path is not valid UTF-8"))?
                    .to_string(),
            );
            l.scale = p.float("scale")?;
            if let Some(m) = to_world {
                l.transform = vec![matrix_step(&m)];
            }
            if p.boolean("mis_compensation")? == Some(true) {
                cx.warn(
                    &p.pos,
                    "envmap mis_compensation only changes noise; facette samples the map by luminance",
                );
            }
            p.finish(
                &["filename", "scale", "to_world", "mis_compensation"],
                &cx.reg,
            )?;
            l
        }
        "area" => return Err(p.err("an area emitter belongs inside a <shape>")),
        other => return Err(p.err(unsupported(other))),
    };
    let span = cx.span(&p.pos);
    Ok(Spanned::new(span, light))
}
