//! Reading parameter values: numbers and triples of the TOML, finite vectors, and the
//! transform steps shared by objects and environment lights.

use super::context::Ctx;
use crate::geometry::{Transform, Vec3};
use crate::scene::SceneError;
use std::ops::Range;

pub(super) fn vec3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// `a` as a vector, or an error at `span` naming the key when a component is not finite.
pub(super) fn finite3(
    ctx: &Ctx,
    span: &Range<usize>,
    name: &str,
    a: [f64; 3],
) -> Result<Vec3, SceneError> {
    if a.iter().all(|v| v.is_finite()) {
        Ok(vec3(a))
    } else {
        Err(ctx.err(
            Some(span.clone()),
            format!("`{name}` must be three finite numbers"),
        ))
    }
}

/// A TOML number; integers count (`1` as well as `1.0`).
pub(super) fn number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Float(f) => Some(*f),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

/// A TOML array of three numbers.
pub(super) fn triple(v: &toml::Value) -> Option<Vec3> {
    match v {
        toml::Value::Array(a) if a.len() == 3 => {
            Some(Vec3::new(number(&a[0])?, number(&a[1])?, number(&a[2])?))
        }
        _ => None,
    }
}

/// Transform steps, applied in the order listed: `{translate = [x, y, z]}`,
/// `{scale = s | [x, y, z]}`, `{rotate = {axis = [x, y, z], angle = degrees}}`,
/// `{look_at = {origin, target, up}}`, `{matrix = [16 numbers, row-major]}`.
pub fn parse_transform(steps: &[toml::Table]) -> Result<Transform, String> {
    let mut t = Transform::identity();
    for step in steps {
        if step.len() != 1 {
            return Err("each transform step is a table with exactly one of translate, scale, rotate, look_at, matrix".into());
        }
        let (k, v) = step.iter().next().expect("one entry");
        t = t.then(&transform_step(k, v)?);
    }
    Ok(t)
}

/// One step `{k = v}` of [`parse_transform`].
fn transform_step(k: &str, v: &toml::Value) -> Result<Transform, String> {
    match k {
        "translate" => Transform::translate(triple(v).ok_or("`translate` expects [x, y, z]")?),
        "scale" => {
            let s = match v {
                toml::Value::Array(_) => {
                    triple(v).ok_or("`scale` expects a number or [x, y, z]")?
                }
                _ => Vec3::splat(number(v).ok_or("`scale` expects a number or [x, y, z]")?),
            };
            Transform::scale(s)
        }
        "rotate" => {
            let r = v
                .as_table()
                .ok_or("`rotate` expects {axis = [x, y, z], angle = degrees}")?;
            let axis = r
                .get("axis")
                .and_then(triple)
                .ok_or("`rotate` needs `axis = [x, y, z]`")?;
            let angle = r
                .get("angle")
                .and_then(number)
                .ok_or("`rotate` needs `angle` (degrees)")?;
            Transform::rotate(axis, angle)
        }
        "look_at" => {
            let r = v
                .as_table()
                .ok_or("`look_at` expects {origin, target, up}")?;
            let g = |name: &str| {
                r.get(name)
                    .and_then(triple)
                    .ok_or(format!("`look_at` needs `{name} = [x, y, z]`"))
            };
            Transform::look_at(g("origin")?, g("target")?, g("up")?)
        }
        "matrix" => {
            let a = v
                .as_array()
                .filter(|a| a.len() == 16)
                .ok_or("`matrix` expects 16 numbers (row-major)")?;
            let mut m = [0.0; 16];
            for (i, x) in a.iter().enumerate() {
                m[i] = number(x).ok_or("`matrix` expects 16 numbers")?;
            }
            // Row-major in the file, column-major in glam.
            Transform::try_new(glam::DMat4::from_cols_array(&m).transpose())
        }
        other => {
            return Err(format!(
                "unknown transform `{other}`; valid: translate, scale, rotate, look_at, matrix"
            ))
        }
    }
    .map_err(|e| e.to_string())
}
