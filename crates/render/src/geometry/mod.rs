//! Geometry: rays, transforms, shapes, meshes and the BVH.
//!
//! - [`ray`]: [`Ray`], [`RayDifferential`], and the rule for spawning rays off a surface.
//! - [`transform`]: [`Transform`] (matrix + inverse), Mitsuba's `look_at`.
//! - Shapes with Mitsuba 3's parameterizations: [`Sphere`], [`Rectangle`], [`Disk`],
//!   [`TriangleMesh`] (watertight ray–triangle test in [`triangle`]); [`Shape`] holds any
//!   of them. The planar ones (rectangle, disk) share their frame and plane intersection
//!   (`planar`).
//! - [`mesh_io`]: OBJ and PLY files into [`MeshData`]; [`generate`]: procedural meshes;
//!   [`vertex_normals`]: Mitsuba's vertex normals for meshes stored without.
//! - [`interaction`]: [`SurfaceHit`] and its screen-space uv derivatives.
//! - [`solid_angle_sampling`]: sampling a shape as seen from a point (area lights), with
//!   each shape's best sampler: the sphere's cone, spherical rectangles and triangles.
//! - [`bvh`]: binned-SAH BVH; [`SceneGeometry`]: all shapes of a scene under one BVH,
//!   with closest-hit, occlusion and area sampling queries.
//! - [`spherical_triangle`], [`spherical_rectangle`]: solid angles of triangles and
//!   rectangles, and directions sampled uniformly in them (Arvo; Ureña, Fajardo and King),
//!   for next-event estimation towards area lights.
//!
//! Everything computes in `f64` (the project's convention); the BVH stores its boxes in
//! `f32`, rounded outwards.

// `!(x > 0.0)` is used on purpose, as in facette-bsdf: it is true for NaN, which must be
// rejected too.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub use glam::{DMat4 as Mat4, DVec2 as Vec2, DVec3 as Vec3};

pub mod bounds;
pub mod bvh;
pub mod disk;
pub mod error;
pub mod generate;
pub mod interaction;
pub mod mesh_data;
pub mod mesh_io;
mod planar;
pub mod ray;
pub mod rectangle;
pub mod scene_geometry;
pub mod shape;
pub mod solid_angle_sampling;
pub mod sphere;
pub mod spherical_rectangle;
pub mod spherical_triangle;
pub mod transform;
pub mod triangle;
pub mod triangle_mesh;
pub mod vertex_normals;

pub use bounds::Bounds3;
pub use bvh::Bvh;
pub use disk::Disk;
pub use error::{GeometryError, GeometryResult};
pub use interaction::{PrimHit, SurfaceHit};
pub use mesh_data::MeshData;
pub use ray::{Ray, RayDifferential};
pub use rectangle::Rectangle;
pub use scene_geometry::{HitDetail, HitLanes, LaneRays, PacketHit, SceneGeometry};
pub use shape::Shape;
pub use solid_angle_sampling::ShapeSample;
pub use sphere::Sphere;
pub use transform::Transform;
pub use triangle_mesh::TriangleMesh;
