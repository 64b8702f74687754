//! Objects: each one's shape (placed by its transform), material and emission.

use super::context::Ctx;
use super::materials::MaterialTable;
use super::values::{parse_transform, vec3};
use crate::geometry::generate::{cube_mesh_data, TorusKnot};
use crate::geometry::vertex_normals::add_vertex_normals;
use crate::geometry::{
    Disk, GeometryError, Rectangle, Shape, Sphere, Transform, TriangleMesh, Vec3,
};
use crate::scene::description::{MeshNormals, ObjectDesc};
use crate::scene::SceneError;
use facette_bsdf::Spectrum;
use std::sync::Arc;
use toml::Spanned;

/// The shapes of a scene with, for each, its material index and its emission (radiance
/// and two-sidedness) when it is an area light.
pub(super) struct Objects {
    pub shapes: Vec<Shape>,
    pub shape_material: Vec<u32>,
    pub shape_emission: Vec<Option<(Spectrum, bool)>>,
}

/// All objects of the description, in order; inline materials join `materials`.
pub(super) fn create_objects(
    ctx: &Ctx,
    desc: &[Spanned<ObjectDesc>],
    materials: &mut MaterialTable,
) -> Result<Objects, SceneError> {
    let mut out = Objects {
        shapes: Vec::new(),
        shape_material: Vec::new(),
        shape_emission: Vec::new(),
    };
    for (k, obj) in desc.iter().enumerate() {
        let span = obj.span();
        let o = obj.get_ref();
        let what = format!("object {} ({})", k + 1, o.shape);
        let e = |m: String| ctx.err(Some(span.clone()), format!("{what}: {m}"));
        let to_world = parse_transform(&o.transform).map_err(e)?;
        check_shape_keys(o, &e)?;
        let shape = create_shape(ctx, o, &to_world, &e)?;
        let material = materials.for_object(ctx, k, &what, o, &e)?;
        let emission = create_emission(o, &e)?;
        out.shapes.push(shape);
        out.shape_material.push(material);
        out.shape_emission.push(emission);
    }
    Ok(out)
}

/// Rejects an unknown shape and the shape keys that do not apply to this one.
fn check_shape_keys(o: &ObjectDesc, e: &dyn Fn(String) -> SceneError) -> Result<(), SceneError> {
    let allowed: &[&str] = match o.shape.as_str() {
        "sphere" => &["center", "radius"],
        "rectangle" | "disk" | "cube" => &[],
        "obj" | "ply" => &["file"],
        "torus-knot" => &["triangles"],
        other => {
            return Err(e(format!("unknown shape `{other}`; valid: sphere, rectangle, disk, cube, obj, ply, torus-knot")));
        }
    };
    for (key, present) in [
        ("center", o.center.is_some()),
        ("radius", o.radius.is_some()),
        ("file", o.file.is_some()),
        ("triangles", o.triangles.is_some()),
    ] {
        if present && !allowed.contains(&key) {
            return Err(e(format!("`{key}` does not apply to a {}", o.shape)));
        }
    }
    Ok(())
}

/// The shape of `o` placed by `to_world` (its name already checked).
fn create_shape(
    ctx: &Ctx,
    o: &ObjectDesc,
    to_world: &Transform,
    e: &dyn Fn(String) -> SceneError,
) -> Result<Shape, SceneError> {
    let geometry = |x: GeometryError| e(x.to_string());
    let shape = match o.shape.as_str() {
        "sphere" => {
            let center = o.center.map(vec3).unwrap_or(Vec3::ZERO);
            let radius = o.radius.unwrap_or(1.0);
            Shape::Sphere(
                Sphere::with_transform(center, radius, to_world, o.flip_normals)
                    .map_err(geometry)?,
            )
        }
        "rectangle" => {
            Shape::Rectangle(Rectangle::new(to_world, o.flip_normals).map_err(geometry)?)
        }
        "disk" => Shape::Disk(Disk::new(to_world, o.flip_normals).map_err(geometry)?),
        "cube" => Shape::Mesh(Arc::new(
            cube_mesh_data()
                .into_mesh(to_world, o.flip_normals)
                .map_err(geometry)?,
        )),
        "obj" | "ply" => Shape::Mesh(Arc::new(read_mesh_file(ctx, o, to_world, e)?)),
        _ => {
            let n = o.triangles.unwrap_or(100_000);
            if !(100..=20_000_000).contains(&n) {
                return Err(e(format!("`triangles` = {n} must be in 100…20000000")));
            }
            let mesh: TriangleMesh = TorusKnot::with_triangles(n)
                .mesh(to_world)
                .map_err(geometry)?;
            Shape::Mesh(Arc::new(mesh))
        }
    };
    let b = shape.bounds();
    let reach = b.min.abs().max(b.max.abs()).max_element();
    if !(reach <= facette_bsdf::limits::MAX_COORDINATE) {
        return Err(e(format!(
            "the object reaches {} in world space, beyond the coordinate limit {:e} (areas and bounding boxes would overflow); scale the scene down",
            facette_bsdf::math::fmt_num(reach),
            facette_bsdf::limits::MAX_COORDINATE
        )));
    }
    Ok(shape)
}

/// The OBJ or PLY mesh of `o`, with the normals it asks for.
fn read_mesh_file(
    ctx: &Ctx,
    o: &ObjectDesc,
    to_world: &Transform,
    e: &dyn Fn(String) -> SceneError,
) -> Result<TriangleMesh, SceneError> {
    let file = o.file.as_ref().ok_or_else(|| e("needs `file`".into()))?;
    let path = ctx.base_dir.join(file);
    let mut data = match (o.shape.as_str(), o.flip_tex_coords) {
        ("obj", Some(flip)) => crate::geometry::mesh_io::read_obj(&path, flip),
        _ => crate::geometry::mesh_io::read_mesh(&path),
    }
    .map_err(|x| e(x.to_string()))?;
    match o.mesh_normals {
        MeshNormals::AsStored => {}
        MeshNormals::Face => data.normals = None,
        MeshNormals::ComputedIfMissing => {
            if data.normals.is_none() {
                add_vertex_normals(&mut data, to_world);
            }
        }
    }
    data.into_mesh(to_world, o.flip_normals)
        .map_err(|x| match x {
            x @ GeometryError::InFile { .. } => x,
            x => x.in_file(&path, None),
        })
        .map_err(|x| e(x.to_string()))
}

/// The emission of `o` (radiance, two-sided), if it is an area light.
fn create_emission(
    o: &ObjectDesc,
    e: &dyn Fn(String) -> SceneError,
) -> Result<Option<(Spectrum, bool)>, SceneError> {
    let emission = match &o.emission {
        None => None,
        Some(c) => {
            let s = c.spectrum();
            for c in 0..3 {
                facette_bsdf::limits::check_radiance(s[c])
                    .map_err(|m| e(format!("`emission`: {m}")))?;
            }
            Some((s, o.two_sided))
        }
    };
    if o.two_sided && emission.is_none() {
        return Err(e(
            "`two_sided` applies to emitters (objects with `emission`)".into(),
        ));
    }
    Ok(emission)
}
