//! Scenes: the TOML description (`description`), its building into a [`Scene`] with
//! file:line errors (`load`), Mitsuba 3 XML scenes translated into the same description
//! (`mitsuba`), and the built [`Scene`] the integrator renders.
//!
//! Imports run one way: `mitsuba` → `load` → `source`, `error`, `description`; `load`
//! never imports `mitsuba`.

pub mod description;
mod error;
pub mod load;
pub mod mitsuba;
mod source;

pub use error::SceneError;
pub use load::load_scene_str;

use std::path::Path;

use crate::camera::Camera;
use crate::film::Filter;
use crate::geometry::SceneGeometry;
use crate::lights::{Light, LightSelector};
use crate::materials::SceneMaterial;
use crate::sampler::SamplerKind;

/// Film settings of a scene.
#[derive(Clone, Debug)]
pub struct FilmSettings {
    pub width: usize,
    pub height: usize,
    pub spp: usize,
    pub filter: Filter,
    pub exposure: f64,
    pub sampler: SamplerKind,
}

/// Path-tracer settings, in Mitsuba's convention: `max_depth` is the longest path length
/// in segments (the camera ray counts as 1, so 1 shows emitters only, 2 direct lighting),
/// Russian roulette starts after `rr_depth` segments.
#[derive(Clone, Copy, Debug)]
pub struct IntegratorSettings {
    pub max_depth: u32,
    pub rr_depth: u32,
    /// The render kernel (`kernel = "scalar" | "packet"`).
    pub kernel: crate::kernel::Kernel,
}

/// A loaded scene.
pub struct Scene {
    pub geometry: SceneGeometry,
    /// Material index of each shape.
    pub shape_material: Vec<u32>,
    /// Area-light index (into `lights`) of each shape.
    pub shape_light: Vec<Option<u32>>,
    pub materials: Vec<SceneMaterial>,
    pub lights: Vec<Light>,
    pub selector: LightSelector,
    /// Index of the environment light in `lights`.
    pub environment: Option<u32>,
    pub camera: Camera,
    pub film: FilmSettings,
    pub integrator: IntegratorSettings,
    /// Hash of the scene source, identifying renders of the same scene.
    pub source_hash: u64,
    /// What loading accepted but could not honour exactly (Mitsuba parameters that only
    /// affect quality, such as a sampler type), one line each, for the user to read.
    pub warnings: Vec<String>,
}

impl Scene {
    /// What went wrong at shading points during renders so far, one line per material: the
    /// points whose textured values were not valid parameters (non-finite texels), where
    /// the paths ended.
    pub fn shading_warnings(&self) -> Vec<String> {
        self.materials
            .iter()
            .filter(|m| m.failed_shading_points() > 0)
            .map(|m| {
                format!(
                    "material `{}`: {} shading points had texture values that are not valid \
                     parameters; their paths ended there",
                    m.name,
                    m.failed_shading_points()
                )
            })
            .collect()
    }
}

/// How to load a scene file.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// `name = value` pairs substituted for `$name` in a Mitsuba XML scene (the command
    /// line's `-D name=value`); they take precedence over the file's `<default>`s.
    pub defines: Vec<(String, String)>,
}

/// Loads a scene file: Mitsuba 3 XML for `.xml` (case-insensitive), facette's TOML
/// format otherwise.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    load_scene_with(path, &LoadOptions::default())
}

/// [`load_scene`] with options; `defines` apply to XML scenes only.
pub fn load_scene_with(path: &Path, options: &LoadOptions) -> Result<Scene, SceneError> {
    let is_xml = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("xml"));
    if is_xml {
        return mitsuba::load_mitsuba_scene(path, &options.defines);
    }
    if let Some((name, _)) = options.defines.first() {
        return Err(SceneError {
            file: path.to_path_buf(),
            line: None,
            message: format!(
                "`-D {name}=…` applies to Mitsuba XML scenes (.xml) only; this is a TOML scene"
            ),
        });
    }
    let source = source::read_scene_text(path)?;
    load_scene_str(&source, path)
}
