//! Textures: Mitsuba's `bitmap` and `checkerboard` as facette texture tables, and colour
//! parameters (constant or textured) as material values.
//!
//! | Mitsuba | facette |
//! |---|---|
//! | `bitmap`: `filename`, `wrap_mode` (repeat, mirror, clamp), `raw`, `to_uv` (scale + translation), `filter_type` | `{ image, wrap, encoding = raw ? "linear" : "srgb", uv_scale, uv_offset }`; `filter_type` is a warning (facette filters trilinearly over the pixel footprint) |
//! | `checkerboard`: `color0` (0.4), `color1` (0.2), `to_uv` (uniform scale s) | `{ texture = "checker", a = color0, b = color1, scale = 2s }` — Mitsuba's check has two squares per unit of uv |

use super::plugin::{ColorParam, Plugin};
use super::translator::Translator;
use crate::scene::SceneError;
use glam::DMat4;

/// The colour parameter `name` of `p` as a material value (`0.5`, `[r, g, b]` or a
/// texture table); `None` when absent.
pub(crate) fn color_value(
    cx: &mut Translator,
    p: &Plugin,
    name: &str,
) -> Result<Option<toml::Value>, SceneError> {
    match p.color(name, &cx.reg)? {
        None => Ok(None),
        Some(ColorParam::Value(c)) => Ok(Some(rgb_value(c))),
        Some(ColorParam::Texture(t)) => Ok(Some(toml::Value::Table(texture_table(cx, &t)?))),
    }
}

/// A constant colour as a material value: a number when grey.
pub(crate) fn rgb_value(c: [f64; 3]) -> toml::Value {
    if c[0] == c[1] && c[1] == c[2] {
        toml::Value::Float(c[0])
    } else {
        toml::Value::Array(c.iter().map(|v| toml::Value::Float(*v)).collect())
    }
}

/// The colour parameter `name` of `p` as a constant (textures are refused: `what` says
/// where they are not supported).
pub(crate) fn constant_color(
    cx: &Translator,
    p: &Plugin,
    name: &str,
    what: &str,
) -> Result<Option<[f64; 3]>, SceneError> {
    match p.color(name, &cx.reg)? {
        None => Ok(None),
        Some(ColorParam::Value(c)) => Ok(Some(c)),
        Some(ColorParam::Texture(t)) => Err(t.err(format!(
            "a texture cannot drive `{name}` of {} ({what}); give an <rgb> or a <float>",
            p.describe()
        ))),
    }
}

/// A texture plugin as a facette texture table.
pub(crate) fn texture_table(cx: &mut Translator, t: &Plugin) -> Result<toml::Table, SceneError> {
    let mut out = toml::Table::new();
    match t.kind.as_str() {
        "bitmap" => {
            let path = cx
                .file(t, "filename")?
                .ok_or_else(|| t.err("needs `filename`"))?;
            let path = path
                .to_str()
                .ok_or_else(|| t.err("the file path is not valid UTF-8"))?
                .to_string();
            out.insert("image".into(), toml::Value::String(path));
            let wrap = t.string("wrap_mode")?.unwrap_or_else(|| "repeat".into());
            if !["repeat", "mirror", "clamp"].contains(&wrap.as_str()) {
                return Err(t.err(format!(
                    "unknown wrap_mode `{wrap}`; valid: repeat, mirror, clamp"
                )));
            }
            out.insert("wrap".into(), toml::Value::String(wrap));
            let raw = t.boolean("raw")?.unwrap_or(false);
            out.insert(
                "encoding".into(),
                toml::Value::String(if raw { "linear" } else { "srgb" }.into()),
            );
            if let Some(filter) = t.string("filter_type")? {
                match filter.as_str() {
                    "bilinear" => {}
                    "nearest" => cx.warn(
                        &t.pos,
                        "bitmap filter_type=\"nearest\": facette filters textures trilinearly over the pixel footprint",
                    ),
                    other => {
                        return Err(t.err(format!(
                            "unknown filter_type `{other}`; valid: bilinear, nearest"
                        )))
                    }
                }
            }
            if let Some(m) = t.transform("to_uv")? {
                let (scale, offset) = uv_scale_offset(t, &m)?;
                out.insert("uv_scale".into(), pair(scale));
                out.insert("uv_offset".into(), pair(offset));
            }
            t.finish(
                &["filename", "wrap_mode", "raw", "filter_type", "to_uv"],
                &cx.reg,
            )?;
        }
        "checkerboard" => {
            let what = "checkerboard colours are constants in facette";
            let a = constant_color(cx, t, "color0", what)?.unwrap_or([0.4; 3]);
            let b = constant_color(cx, t, "color1", what)?.unwrap_or([0.2; 3]);
            let mut scale = 2.0;
            if let Some(m) = t.transform("to_uv")? {
                let (s, o) = uv_scale_offset(t, &m)?;
                if s[0] != s[1] || o != [0.0, 0.0] || !(s[0] > 0.0) {
                    return Err(t.err(
                        "facette's checker takes a uniform positive scale: `to_uv` may only be <scale value=\"s\"/>",
                    ));
                }
                scale *= s[0];
            }
            out.insert("texture".into(), toml::Value::String("checker".into()));
            out.insert("a".into(), rgb_value(a));
            out.insert("b".into(), rgb_value(b));
            out.insert("scale".into(), toml::Value::Float(scale));
            t.finish(&["color0", "color1", "to_uv"], &cx.reg)?;
        }
        other => {
            return Err(t.err(format!(
                "unsupported texture `{other}`; supported: bitmap, checkerboard"
            )))
        }
    }
    Ok(out)
}

/// A `to_uv` transform as uv ↦ uv·scale + offset: Mitsuba applies the 2-D affine part
/// (rows and columns x, y and the translation column); rotation and shear are refused.
fn uv_scale_offset(t: &Plugin, m: &DMat4) -> Result<([f64; 2], [f64; 2]), SceneError> {
    let (c0, c1, c3) = (m.x_axis, m.y_axis, m.w_axis);
    if c0.y != 0.0 || c1.x != 0.0 {
        return Err(
            t.err("`to_uv` may only scale and translate (facette textures have no uv rotation)")
        );
    }
    Ok(([c0.x, c1.y], [c3.x, c3.y]))
}

fn pair(v: [f64; 2]) -> toml::Value {
    toml::Value::Array(v.iter().map(|x| toml::Value::Float(*x)).collect())
}
