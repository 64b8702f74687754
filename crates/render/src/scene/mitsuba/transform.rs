//! `<transform name="…">`: its operations, each applied after the ones before it (the
//! matrix is left-multiplied), as Mitsuba 3 does:
//!
//! | element | attributes | meaning |
//! |---|---|---|
//! | `<translate>` | `x`, `y`, `z` (default 0) or `value="x y z"` | translation |
//! | `<scale>` | `x`, `y`, `z` (default 1) or `value="s"` / `value="x y z"` | scaling |
//! | `<rotate>` | axis `x`, `y`, `z` (or `value`), `angle` in degrees | right-handed rotation |
//! | `<lookat>` | `origin`, `target`, `up` (optional) | Mitsuba's look-at frame |
//! | `<matrix>` | `value`: 16 numbers (4×4, row-major) or 9 (3×3, upper left) | any matrix |

use super::values::{parse_numbers, parse_vec3};
use super::xml::Element;
use crate::geometry::{Transform, Vec3};
use crate::scene::SceneError;
use glam::{DMat3, DMat4};

/// The matrix of a `<transform>` element.
pub(crate) fn parse_transform(e: &Element) -> Result<DMat4, SceneError> {
    let mut m = DMat4::IDENTITY;
    for op in &e.children {
        let step = match op.tag.as_str() {
            "translate" => DMat4::from_translation(xyz(op, 0.0)?),
            "scale" => DMat4::from_scale(xyz(op, 1.0)?),
            "rotate" => {
                op.check_attrs(&["x", "y", "z", "value", "angle"], &["angle"])?;
                let axis = xyz(op, 0.0)?;
                let angle = number(op, "angle")?;
                Transform::rotate(axis, angle)
                    .map_err(|x| op.pos.err(format!("<rotate>: {x}")))?
                    .matrix()
                    .to_owned()
            }
            "lookat" => {
                op.check_attrs(&["origin", "target", "up"], &["origin", "target"])?;
                let origin = named_vec3(op, "origin")?;
                let target = named_vec3(op, "target")?;
                let mut up = match op.attr("up") {
                    Some(_) => named_vec3(op, "up")?,
                    None => Vec3::ZERO,
                };
                if up == Vec3::ZERO {
                    // Mitsuba picks the first tangent of its coordinate system around the
                    // viewing direction.
                    up = first_tangent((target - origin).normalize_or_zero());
                }
                Transform::look_at(origin, target, up)
                    .map_err(|x| op.pos.err(format!("invalid <lookat>: {x}")))?
                    .matrix()
                    .to_owned()
            }
            "matrix" => {
                op.check_attrs(&["value"], &["value"])?;
                let v = parse_numbers(op.attr("value").unwrap_or(""))
                    .map_err(|x| op.pos.err(format!("<matrix>: {x}")))?;
                match v.len() {
                    // Row-major in the file, column-major in glam.
                    16 => DMat4::from_cols_slice(&v).transpose(),
                    9 => DMat4::from_mat3(DMat3::from_cols_slice(&v).transpose()),
                    n => {
                        return Err(op.pos.err(format!(
                            "<matrix> needs 16 values (4×4, row-major) or 9 (3×3), got {n}"
                        )))
                    }
                }
            }
            other => {
                return Err(op.pos.err(format!(
                    "<{other}> cannot occur in a <transform>; valid: translate, scale, rotate, lookat, matrix"
                )))
            }
        };
        if !step.is_finite() {
            return Err(op
                .pos
                .err(format!("<{}> gives a non-finite matrix", op.tag)));
        }
        m = step * m;
    }
    Ok(m)
}

/// `x`, `y`, `z` attributes (each defaulting to `default`) or `value` with one or three
/// numbers (one is repeated).
fn xyz(op: &Element, default: f64) -> Result<Vec3, SceneError> {
    if op.tag != "rotate" {
        op.check_attrs(&["x", "y", "z", "value"], &[])?;
    }
    if let Some(v) = op.attr("value") {
        if ["x", "y", "z"].iter().any(|k| op.attr(k).is_some()) {
            return Err(op.pos.err(format!(
                "<{}>: give `value` or `x`/`y`/`z`, not both",
                op.tag
            )));
        }
        let n = parse_numbers(v).map_err(|x| op.pos.err(format!("<{}>: {x}", op.tag)))?;
        return match n.len() {
            1 => Ok(Vec3::splat(n[0])),
            3 => Ok(Vec3::new(n[0], n[1], n[2])),
            k => Err(op.pos.err(format!(
                "<{}>: `value` needs 1 or 3 numbers, got {k}",
                op.tag
            ))),
        };
    }
    let mut out = [default; 3];
    for (i, k) in ["x", "y", "z"].iter().enumerate() {
        if op.attr(k).is_some() {
            out[i] = number(op, k)?;
        }
    }
    Ok(Vec3::from_array(out))
}

fn number(op: &Element, attr: &str) -> Result<f64, SceneError> {
    let v = op.attr(attr).unwrap_or("");
    let n = parse_numbers(v).map_err(|x| op.pos.err(format!("<{}> `{attr}`: {x}", op.tag)))?;
    match n.as_slice() {
        [x] => Ok(*x),
        _ => Err(op.pos.err(format!(
            "<{}> `{attr}` must be one number, got \"{v}\"",
            op.tag
        ))),
    }
}

fn named_vec3(op: &Element, attr: &str) -> Result<Vec3, SceneError> {
    parse_vec3(op.attr(attr).unwrap_or(""))
        .map_err(|x| op.pos.err(format!("<{}> `{attr}`: {x}", op.tag)))
}

/// The first tangent of the orthonormal basis Mitsuba builds around a unit vector `n`
/// (Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 6(1), 2017, listing 3).
fn first_tangent(n: Vec3) -> Vec3 {
    let sign = 1f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::mitsuba::xml::parse_xml;
    use std::path::Path;

    fn transform(inner: &str) -> Result<DMat4, SceneError> {
        let e = parse_xml(
            &format!("<transform name=\"to_world\">{inner}</transform>"),
            Path::new("t.xml"),
        )
        .unwrap();
        parse_transform(&e)
    }

    #[test]
    fn operations_apply_in_document_order() {
        // Scale first, then translate: (1, 0, 0) ↦ (2, 0, 0) ↦ (2, 3, 0).
        let m = transform("<scale value=\"2\"/><translate y=\"3\"/>").unwrap();
        assert!((m.transform_point3(Vec3::X) - Vec3::new(2.0, 3.0, 0.0)).length() < 1e-12);
        // Rotation by 90° about +z takes +x to +y.
        let m = transform("<rotate z=\"1\" angle=\"90\"/>").unwrap();
        assert!((m.transform_vector3(Vec3::X) - Vec3::Y).length() < 1e-12);
        // Scale defaults missing components to 1.
        let m = transform("<scale x=\"-1\"/>").unwrap();
        assert_eq!(m.transform_vector3(Vec3::ONE), Vec3::new(-1.0, 1.0, 1.0));
        // Row-major matrices.
        let m = transform("<matrix value=\"1 0 0 5  0 1 0 6  0 0 1 7  0 0 0 1\"/>").unwrap();
        assert_eq!(m.transform_point3(Vec3::ZERO), Vec3::new(5.0, 6.0, 7.0));
    }

    #[test]
    fn lookat_without_up_uses_mitsubas_tangent() {
        let t = first_tangent(Vec3::new(0.0, 0.6, 0.8));
        assert!(t.dot(Vec3::new(0.0, 0.6, 0.8)).abs() < 1e-12 && (t.length() - 1.0).abs() < 1e-12);
        let m = transform("<lookat origin=\"0, 0, 0\" target=\"0 0 1\"/>").unwrap();
        assert!((m.transform_vector3(Vec3::Z) - Vec3::Z).length() < 1e-12);
    }

    #[test]
    fn bad_operations_are_errors_with_the_line() {
        let e = transform("\n<rotate x=\"1\"/>").unwrap_err().to_string();
        assert!(e.contains("t.xml:2") && e.contains("`angle`"), "{e}");
        let e = transform("<matrix value=\"1 2 3\"/>")
            .unwrap_err()
            .to_string();
        assert!(e.contains("16 values"), "{e}");
        let e = transform("<shear x=\"1\"/>").unwrap_err().to_string();
        assert!(e.contains("valid: translate"), "{e}");
        let e = transform("<translate x=\"one\"/>").unwrap_err().to_string();
        assert!(e.contains("`x`") && e.contains("one"), "{e}");
    }
}
