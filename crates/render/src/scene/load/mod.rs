//! Building a scene from its description, in the manner of pbrt-v4's `scene.cpp`: one
//! `create_*` function per kind of thing, each in the file of its concern —
//! [`settings`] (film, integrator), [`camera`], [`materials`], [`objects`] (shapes and
//! emission), [`lights`] and [`environment`] — reading values with [`values`]. Every
//! error names the file and line of the description element at fault ([`context`]).
//!
//! Two readers feed it: [`load_scene_str`] (facette's TOML) and `super::mitsuba` (Mitsuba
//! XML translated into the same description), which calls [`build_scene`].

mod camera;
mod context;
mod environment;
mod lights;
mod materials;
mod objects;
mod settings;
mod toml_errors;
mod values;

pub use values::parse_transform;

use super::description::SceneDesc;
use super::source::{fnv1a, Spans};
use super::{Scene, SceneError};
use crate::geometry::SceneGeometry;
use context::Ctx;
use std::path::{Path, PathBuf};

/// Loads a TOML scene from its text; `path` names it in errors and anchors relative paths.
pub fn load_scene_str(source: &str, path: &Path) -> Result<Scene, SceneError> {
    let spans = Spans::Text { file: path, source };
    let desc: SceneDesc = toml::from_str(source).map_err(|e| {
        spans.err(
            e.span(),
            toml_errors::rewrite(e.message(), source, e.span()),
        )
    })?;
    let base_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    build_scene(spans, base_dir, desc, fnv1a(source.as_bytes()))
}

/// Validates a description and builds the scene. `spans` says what the description's
/// spans index (for error lines), `base_dir` anchors its relative paths, `source_hash`
/// identifies its source (see [`Scene::source_hash`]).
pub(crate) fn build_scene(
    spans: Spans,
    base_dir: PathBuf,
    desc: SceneDesc,
    source_hash: u64,
) -> Result<Scene, SceneError> {
    let ctx = Ctx { spans, base_dir };
    let film = settings::create_film(&ctx, desc.film)?;
    let integrator = settings::create_integrator(&ctx, desc.integrator)?;
    let camera = camera::create_camera(&ctx, desc.camera, &film)?;
    let mut materials = materials::MaterialTable::create(&ctx, &desc.materials)?;
    let objects = objects::create_objects(&ctx, &desc.objects, &mut materials)?;
    let geometry = SceneGeometry::new(objects.shapes).map_err(|x| ctx.err(None, x.to_string()))?;
    let lights = lights::create_lights(&ctx, &objects.shape_emission, &desc.lights)?;
    let selector = lights::create_selector(&lights.lights, &geometry);
    let warnings = materials
        .list
        .iter()
        .filter_map(|m| {
            let w = m.render_cost_warning()?;
            Some(format!("material `{}`: {w}", m.name))
        })
        .collect();
    Ok(Scene {
        geometry,
        shape_material: objects.shape_material,
        shape_light: lights.shape_light,
        materials: materials.list,
        lights: lights.lights,
        selector,
        environment: lights.environment,
        camera,
        film,
        integrator,
        source_hash,
        warnings,
    })
}
