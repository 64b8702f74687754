//! The scene file as written (TOML), deserialized with serde; `load/` validates it and
//! builds the [`Scene`](super::Scene). `docs/scene-format.md` documents every key.
//!
//! Mitsuba XML scenes are translated into this same description (`super::mitsuba`); the
//! few things only they can say are `#[serde(skip)]` fields, out of reach of TOML.

use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

fn default_up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}
fn default_fov() -> f64 {
    40.0
}
fn default_size() -> usize {
    512
}
fn default_sampler() -> String {
    crate::sampler::SamplerKind::default().name().to_string()
}

fn default_spp() -> usize {
    16
}
fn default_filter() -> String {
    "gaussian".into()
}
fn default_stddev() -> f64 {
    0.5
}
fn default_radius() -> f64 {
    1.5
}
fn default_max_depth() -> u32 {
    8
}
fn default_rr_depth() -> u32 {
    5
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    pub camera: Spanned<CameraDesc>,
    #[serde(default)]
    pub film: Option<Spanned<FilmDesc>>,
    #[serde(default)]
    pub integrator: Option<Spanned<IntegratorDesc>>,
    #[serde(default)]
    pub materials: BTreeMap<String, Spanned<toml::Table>>,
    #[serde(default)]
    pub objects: Vec<Spanned<ObjectDesc>>,
    #[serde(default)]
    pub lights: Vec<Spanned<LightDesc>>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    pub position: [f64; 3],
    pub target: [f64; 3],
    #[serde(default = "default_up")]
    pub up: [f64; 3],
    /// Field of view in degrees along `fov_axis`.
    #[serde(default = "default_fov")]
    pub fov: f64,
    #[serde(default)]
    pub fov_axis: Option<String>,
    #[serde(default)]
    pub aperture_radius: f64,
    #[serde(default)]
    pub focus_distance: Option<f64>,
    /// Camera-to-world transform replacing `look_at(position, target, up)` (Mitsuba XML:
    /// the sensor's `to_world`, which may mirror the image).
    #[serde(skip)]
    pub to_world: Option<crate::geometry::Transform>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct FilmDesc {
    #[serde(default = "default_size")]
    pub width: usize,
    #[serde(default = "default_size")]
    pub height: usize,
    #[serde(default = "default_spp")]
    pub spp: usize,
    #[serde(default = "default_filter")]
    pub filter: String,
    #[serde(default = "default_stddev")]
    pub filter_stddev: f64,
    #[serde(default = "default_radius")]
    pub filter_radius: f64,
    /// Exposure in stops applied when writing.
    #[serde(default)]
    pub exposure: f64,
    /// The pixel sampler: `sobol`, `independent` or `stratified`.
    #[serde(default = "default_sampler")]
    pub sampler: String,
}

impl Default for FilmDesc {
    fn default() -> Self {
        FilmDesc {
            width: default_size(),
            height: default_size(),
            spp: default_spp(),
            filter: default_filter(),
            filter_stddev: default_stddev(),
            filter_radius: default_radius(),
            exposure: 0.0,
            sampler: default_sampler(),
        }
    }
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct IntegratorDesc {
    #[serde(default = "default_max_depth")]
    pub max_depth: u32,
    #[serde(default = "default_rr_depth")]
    pub rr_depth: u32,
    /// `"scalar"` (default) or `"packet"`.
    #[serde(default)]
    pub kernel: Option<String>,
}

impl Default for IntegratorDesc {
    fn default() -> Self {
        IntegratorDesc {
            max_depth: default_max_depth(),
            rr_depth: default_rr_depth(),
            kernel: None,
        }
    }
}

/// A colour: a number (grey) or `[r, g, b]`.
#[derive(Deserialize, Debug, Clone, Copy)]
#[serde(untagged)]
pub enum ColorDesc {
    Grey(f64),
    Rgb([f64; 3]),
}

impl ColorDesc {
    pub fn spectrum(&self) -> facette_bsdf::Spectrum {
        match *self {
            ColorDesc::Grey(g) => facette_bsdf::Spectrum::splat(g),
            ColorDesc::Rgb([r, g, b]) => facette_bsdf::Spectrum::rgb(r, g, b),
        }
    }
}

/// A material: the name of an entry of `[materials]`, or an inline table.
#[derive(Deserialize, Debug)]
#[serde(untagged)]
pub enum MaterialRef {
    Name(String),
    Inline(toml::Table),
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct ObjectDesc {
    /// `sphere`, `rectangle`, `disk`, `cube`, `obj`, `ply`, `torus-knot`.
    pub shape: String,
    #[serde(default)]
    pub center: Option<[f64; 3]>,
    #[serde(default)]
    pub radius: Option<f64>,
    /// Mesh file (`obj`, `ply`), relative to the scene file.
    #[serde(default)]
    pub file: Option<String>,
    /// Triangle count of a generated mesh (`torus-knot`).
    #[serde(default)]
    pub triangles: Option<usize>,
    #[serde(default)]
    pub transform: Vec<toml::Table>,
    pub material: Option<Spanned<MaterialRef>>,
    /// Emitted radiance (makes the object an area light).
    #[serde(default)]
    pub emission: Option<ColorDesc>,
    #[serde(default)]
    pub two_sided: bool,
    #[serde(default)]
    pub flip_normals: bool,
    /// Mesh files: which shading normals (Mitsuba XML computes missing ones).
    #[serde(skip)]
    pub mesh_normals: MeshNormals,
    /// OBJ files: whether `v ↦ 1 − v` (Mitsuba XML's `flip_tex_coords`); `None` is the
    /// default (flipped).
    #[serde(skip)]
    pub flip_tex_coords: Option<bool>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct LightDesc {
    /// `point`, `spot`, `directional`, `environment`, `constant`.
    #[serde(rename = "type")]
    pub kind: String,
    #[serde(default)]
    pub position: Option<[f64; 3]>,
    #[serde(default)]
    pub target: Option<[f64; 3]>,
    #[serde(default)]
    pub direction: Option<[f64; 3]>,
    #[serde(default)]
    pub intensity: Option<ColorDesc>,
    #[serde(default)]
    pub irradiance: Option<ColorDesc>,
    #[serde(default)]
    pub radiance: Option<ColorDesc>,
    /// Spot: full-falloff angle and full-intensity angle, degrees.
    #[serde(default)]
    pub cutoff_angle: Option<f64>,
    #[serde(default)]
    pub beam_width: Option<f64>,
    /// Environment image (EXR, HDR, PNG), relative to the scene file.
    #[serde(default)]
    pub file: Option<String>,
    /// Procedural sky parameters (instead of `file`).
    #[serde(default)]
    pub sky: Option<toml::Table>,
    #[serde(default)]
    pub scale: Option<f64>,
    /// Rotation of the environment (transform steps; only rotations are allowed).
    #[serde(default)]
    pub transform: Vec<toml::Table>,
}

/// Shading normals of a mesh file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MeshNormals {
    /// The file's normals, or the flat triangle normals where it has none (TOML scenes).
    #[default]
    AsStored,
    /// Flat triangle normals, ignoring the file's (Mitsuba's `face_normals`).
    Face,
    /// The file's normals, or angle-weighted vertex normals where it has none (Mitsuba's
    /// default).
    ComputedIfMissing,
}
