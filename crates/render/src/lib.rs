//! # facette-render
//!
//! The path tracer that puts facette's materials on spheres, rectangles, disks and triangle
//! meshes under point, spot, area and environment lights, and writes EXR and PNG.
//!
//! - [`geometry`]: rays with differentials, transforms, shapes, mesh loading (OBJ, PLY),
//!   the BVH.
//! - [`image`]: image files (EXR, PNG, HDR) in and out, mip-mapped textures, environment maps
//!   with importance sampling, the procedural sky.

pub mod geometry;
pub mod image;
