//! Scenes: the TOML description (`description`), its loading with file:line errors
//! (`load`), and the built [`Scene`] the integrator renders.

pub mod description;
pub mod load;

pub use load::{load_scene, load_scene_str, SceneError};

use crate::camera::Camera;
use crate::film::Filter;
use crate::geometry::SceneGeometry;
use crate::lights::{Light, LightSelector};
use crate::materials::SceneMaterial;

/// Film settings of a scene.
#[derive(Clone, Debug)]
pub struct FilmSettings {
    pub width: usize,
    pub height: usize,
    pub spp: usize,
    pub filter: Filter,
    pub exposure: f64,
}

/// Path-tracer settings, in Mitsuba's convention: `max_depth` is the longest path length
/// in segments (the camera ray counts as 1, so 1 shows emitters only, 2 direct lighting),
/// Russian roulette starts after `rr_depth` segments.
#[derive(Clone, Copy, Debug)]
pub struct IntegratorSettings {
    pub max_depth: u32,
    pub rr_depth: u32,
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
}
