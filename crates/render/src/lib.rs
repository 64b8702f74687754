//! # facette-render
//!
//! The path tracer that puts facette's materials on spheres, rectangles, disks and triangle
//! meshes under point, spot, area and environment lights, and writes EXR and PNG.
//!
//! - [`geometry`]: rays with differentials, transforms, shapes, mesh loading (OBJ, PLY),
//!   the BVH.
//! - [`image`]: image files (EXR, PNG, HDR) in and out, mip-mapped textures, environment maps
//!   with importance sampling, the procedural sky.
//! - [`scene`]: the TOML scene format and its loading (errors with file:line).
//! - [`camera`], [`film`], [`lights`], [`materials`]: what a scene is made of.
//! - [`integrator`]: the path tracer (NEE + MIS, Russian roulette).
//! - [`sampler`]: the pixel samplers (Owen-scrambled Sobol in Morton order, stratified,
//!   independent) that give each camera sample its random numbers.
//! - [`pixel_footprint`]: the whole pixel's footprint at a camera ray's hit (glints).
//! - [`render`]: tiles in parallel, passes, interruption, determinism.
//! - [`partial_film`]: parts of a render for distributed runs, saved exactly and merged.

// `!(x > 0.0)` is the NaN-rejecting test used throughout (a NaN must fail every check).
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod camera;
pub mod film;
pub mod geometry;
pub mod image;
pub mod integrator;
pub mod kernel;
pub mod lights;
pub mod materials;
pub mod partial_film;
pub mod pixel_footprint;
pub mod render;
pub mod sampler;
pub mod scene;
