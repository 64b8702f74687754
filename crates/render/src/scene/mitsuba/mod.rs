//! Mitsuba 3 XML scenes, read into facette's own scene description so that everything
//! after loading — validation, geometry, materials, lights, camera, rendering — is shared
//! with TOML scenes. docs/scene-format.md (section "Mitsuba scenes") lists the supported
//! subset, the mapping of every plugin and what differs.
//!
//! The stages, one file each:
//! - [`xml`]: the files as element trees that keep every element's file and line;
//! - [`preprocess`]: `version` (and the upgrade of old files), `<default>` and `$name`
//!   substitution with `-D` overrides, `<include>`;
//! - [`plugin`]: objects and their typed properties; whatever a translation does not read
//!   is an error naming it (Mitsuba's "unreferenced property");
//! - [`transform`], [`values`], [`ior`]: the value syntaxes;
//! - [`sensor`], [`integrator`], [`bsdf`], [`texture`], [`shape`], [`emitter`]: one plugin
//!   kind each, mapped onto the description's camera, film, integrator, materials, objects
//!   and lights;
//! - [`translator`]: the state they share (ids, locations, materials, warnings).
//!
//! Meshes stored without normals are marked for Mitsuba's vertex normals
//! (`MeshNormals::ComputedIfMissing`), which the builder computes.
//!
//! The result is built by the scene builder's public entry, [`build_scene`]; this module
//! imports nothing else of `super::load`.
//!
//! Errors name the file and line of the element at fault; parameters that only change the
//! noise (a sampler type, say) are warnings, printed once, in [`Scene::warnings`].

mod bsdf;
mod emitter;
mod integrator;
mod ior;
mod plugin;
mod preprocess;
mod sensor;
mod shape;
mod texture;
mod transform;
mod translator;
mod values;
mod xml;

use super::description::SceneDesc;
use super::load::build_scene;
use super::source::{fnv1a, Spans};
use super::{Scene, SceneError};
use plugin::{Plugin, Registry, Value};
use std::path::Path;
use toml::Spanned;
use translator::Translator;

/// The object classes a scene may hold at its top level.
const TOP_LEVEL: &[&str] = &[
    "sensor",
    "integrator",
    "shape",
    "emitter",
    "bsdf",
    "texture",
];

/// Loads a Mitsuba 3 XML scene; `defines` (`-D name=value`) set `$name` parameters,
/// overriding the file's `<default>`s.
pub fn load_mitsuba_scene(path: &Path, defines: &[(String, String)]) -> Result<Scene, SceneError> {
    let pre = preprocess::preprocess(path, defines)?;
    let scene = Plugin::from_element(&pre.root)?;
    let mut reg = Registry::default();
    reg.add(&scene)?;
    reg.check_references(&scene)?;
    let main_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut cx = Translator::new(reg, main_dir.clone());
    for w in &pre.warnings {
        cx.warnings.push(format!("{}: {w}", path.display()));
    }

    for p in &scene.props {
        if let Value::Object(o) = &p.value {
            if !TOP_LEVEL.contains(&o.class.as_str()) {
                return Err(o.err(format!(
                    "<{}> is not supported; a scene may hold: {}",
                    o.class,
                    TOP_LEVEL.join(", ")
                )));
            }
        }
    }

    let sensors = scene.objects("sensor", &cx.reg)?;
    let Some(first) = sensors.first() else {
        return Err(scene.err(
            "the scene has no <sensor>: facette renders through a perspective or thinlens sensor",
        ));
    };
    for extra in &sensors[1..] {
        cx.warn(
            &extra.pos,
            "facette renders the first <sensor> of the scene; this one is not used",
        );
    }
    let (camera, film, clip) = sensor::sensor(&mut cx, first)?;

    let integrators = scene.objects("integrator", &cx.reg)?;
    if let Some(second) = integrators.get(1) {
        return Err(second.err("a scene takes one <integrator>, this is a second one"));
    }
    let integrator = match integrators.first() {
        Some(p) => {
            let d = integrator::integrator(&cx, p)?;
            Spanned::new(cx.span(&p.pos), d)
        }
        None => Spanned::new(cx.span(&scene.pos), integrator::default_integrator()),
    };

    // Scene-level BSDFs and textures are checked even when no shape uses them, as Mitsuba
    // instantiates them.
    for b in scene.objects("bsdf", &cx.reg)? {
        bsdf::material(&mut cx, &b)?;
    }
    for t in scene.objects("texture", &cx.reg)? {
        texture::texture_table(&mut cx, &t)?;
    }
    let mut objects = Vec::new();
    for s in scene.objects("shape", &cx.reg)? {
        objects.push(shape::object(&mut cx, &s)?);
    }
    let mut lights = Vec::new();
    for e in scene.objects("emitter", &cx.reg)? {
        lights.push(emitter::light(&mut cx, &e)?);
    }
    scene.finish(&[], &cx.reg)?;

    let desc = SceneDesc {
        camera,
        film: Some(film),
        integrator: Some(integrator),
        materials: std::mem::take(&mut cx.materials),
        objects,
        lights,
    };
    let mut hashed = pre.texts.join("\u{0}");
    for (k, v) in defines {
        hashed.push_str(&format!("\u{0}-D{k}={v}"));
    }
    let spans = Spans::Table {
        file: path,
        locations: &cx.locations,
    };
    let mut built = build_scene(spans, main_dir, desc, fnv1a(hashed.as_bytes()))?;
    let mut warnings = std::mem::take(&mut cx.warnings);
    clip.check(&built, &mut warnings);
    warnings.append(&mut built.warnings);
    built.warnings = warnings;
    Ok(built)
}
