//! Shape plugins as facette objects. facette's shapes already follow Mitsuba's
//! parameterizations (rectangle [−1, 1]² at z = 0, disk, cube [−1, 1]³, sphere placed by
//! `to_world · translate(center) · scale(radius)`, OBJ `v` flipped on load), so the
//! translation is one to one.
//!
//! | Mitsuba | facette |
//! |---|---|
//! | every shape: `to_world`, `flip_normals`, a `<bsdf>` (default, as in Mitsuba: `diffuse` 0.5, or black for an emitter), an `area` `<emitter>` | `transform`, `flip_normals`, `material`, `emission` |
//! | `obj` (`filename`, `face_normals`, `flip_tex_coords`), `ply` (`filename`, `face_normals`) | `obj`, `ply` |
//! | `sphere` (`center`, `radius`), `rectangle`, `disk`, `cube` | the same |

use super::bsdf::material;
use super::emitter::{area_radiance, matrix_step};
use super::plugin::Plugin;
use super::translator::Translator;
use crate::scene::description::{MaterialRef, MeshNormals, ObjectDesc};
use crate::scene::SceneError;
use std::rc::Rc;
use toml::Spanned;

/// The shape plugins facette reads.
pub(crate) const MITSUBA_SHAPES: &[&str] = &["obj", "ply", "sphere", "rectangle", "disk", "cube"];

/// Names of the materials given to shapes without a BSDF (Mitsuba's defaults).
const DEFAULT_MATERIAL: &str = "default diffuse";
const DEFAULT_EMITTER_MATERIAL: &str = "default emitter (black)";

/// A scene-level shape as a facette object.
pub(crate) fn object(
    cx: &mut Translator,
    p: &Rc<Plugin>,
) -> Result<Spanned<ObjectDesc>, SceneError> {
    let kind = p.kind.as_str();
    if !MITSUBA_SHAPES.contains(&kind) {
        return Err(p.err(format!(
            "unsupported shape `{kind}`; supported: {}",
            MITSUBA_SHAPES.join(", ")
        )));
    }
    let mut o = ObjectDesc {
        shape: kind.into(),
        center: None,
        radius: None,
        file: None,
        triangles: None,
        transform: Vec::new(),
        material: None,
        emission: None,
        two_sided: false,
        flip_normals: p.boolean("flip_normals")?.unwrap_or(false),
        mesh_normals: MeshNormals::AsStored,
        flip_tex_coords: None,
    };
    if let Some(m) = p.transform("to_world")? {
        o.transform = vec![matrix_step(&m)];
    }
    let mut keys = vec!["to_world", "flip_normals"];
    match kind {
        "obj" | "ply" => {
            let path = cx
                .file(p, "filename")?
                .ok_or_else(|| p.err("needs `filename`"))?;
            o.file = Some(
                path.to_str()
                    .ok_or_else(|| p.err("the file path is not valid UTF-8"))?
                    .to_string(),
            );
            o.mesh_normals = if p.boolean("face_normals")?.unwrap_or(false) {
                MeshNormals::Face
            } else {
                MeshNormals::ComputedIfMissing
            };
            keys.extend(["filename", "face_normals"]);
            if kind == "obj" {
                o.flip_tex_coords = p.boolean("flip_tex_coords")?;
                keys.push("flip_tex_coords");
            }
        }
        "sphere" => {
            o.center = p.vector("center")?;
            o.radius = p.float("radius")?;
            keys.extend(["center", "radius"]);
        }
        _ => {}
    }
    let bsdf = p.object("bsdf", &cx.reg)?;
    let emitter = p.object("emitter", &cx.reg)?;
    if let Some(e) = &emitter {
        o.emission = Some(area_radiance(cx, e)?);
    }
    let (name, at) = match &bsdf {
        Some(b) => (material(cx, b)?, b.pos.clone()),
        None => (default_material(cx, p, emitter.is_some()), p.pos.clone()),
    };
    let span = cx.span(&at);
    o.material = Some(Spanned::new(span, MaterialRef::Name(name)));
    p.finish(&keys, &cx.reg)?;
    let span = cx.span(&p.pos);
    Ok(Spanned::new(span, o))
}

/// Mitsuba gives a shape without a BSDF a `diffuse` one of reflectance 0.5, and an
/// emitting shape a black one.
fn default_material(cx: &mut Translator, p: &Plugin, emitter: bool) -> String {
    let (name, reflectance) = if emitter {
        (DEFAULT_EMITTER_MATERIAL, 0.0)
    } else {
        (DEFAULT_MATERIAL, 0.5)
    };
    if !cx.materials.contains_key(name) {
        let mut t = toml::Table::new();
        t.insert("type".into(), "lambert".into());
        t.insert("reflectance".into(), toml::Value::Float(reflectance));
        let span = cx.span(&p.pos);
        cx.materials.insert(name.into(), Spanned::new(span, t));
    }
    name.into()
}
