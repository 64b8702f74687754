//! The shapes a scene is made of.

use super::bounds::Bounds3;
use super::disk::Disk;
use super::interaction::SurfaceHit;
use super::ray::Ray;
use super::rectangle::Rectangle;
use super::solid_angle_sampling::{ShapeSample, ShapeSampleLanes};
use super::sphere::Sphere;
use super::triangle_mesh::TriangleMesh;
use super::{Vec2, Vec3};
use facette_bsdf::lanes::{LVec3, Real};
use std::sync::Arc;

/// A shape of the scene. Meshes are shared (`Arc`) so that one loaded file can be
/// referenced by the scene description and the geometry without a copy.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Sphere(Sphere),
    Rectangle(Rectangle),
    Disk(Disk),
    Mesh(Arc<TriangleMesh>),
}

impl Shape {
    /// Number of BVH primitives: one per triangle, one for an analytic shape.
    #[inline]
    pub fn primitive_count(&self) -> usize {
        match self {
            Shape::Mesh(m) => m.triangle_count(),
            _ => 1,
        }
    }

    /// Box of primitive `prim` (`prim < primitive_count()`).
    pub fn primitive_bounds(&self, prim: usize) -> Bounds3 {
        match self {
            Shape::Sphere(s) => s.bounds(),
            Shape::Rectangle(r) => r.bounds(),
            Shape::Disk(d) => d.bounds(),
            Shape::Mesh(m) => m.triangle_bounds(prim),
        }
    }

    pub fn bounds(&self) -> Bounds3 {
        match self {
            Shape::Sphere(s) => s.bounds(),
            Shape::Rectangle(r) => r.bounds(),
            Shape::Disk(d) => d.bounds(),
            Shape::Mesh(m) => m.bounds(),
        }
    }

    /// Surface area.
    pub fn area(&self) -> f64 {
        match self {
            Shape::Sphere(s) => s.area(),
            Shape::Rectangle(r) => r.area(),
            Shape::Disk(d) => d.area(),
            Shape::Mesh(m) => m.area(),
        }
    }

    /// Uniform area sample: `(point, normal, pdf per unit area)`; the normal is the
    /// geometric normal a ray hitting that point would report.
    pub fn sample(&self, u: Vec2) -> (Vec3, Vec3, f64) {
        match self {
            Shape::Sphere(s) => s.sample(u),
            Shape::Rectangle(r) => r.sample(u),
            Shape::Disk(d) => d.sample(u),
            Shape::Mesh(m) => m.sample(u),
        }
    }

    /// A point of the shape sampled from the reference point `p`, with the density of its
    /// direction per unit solid angle: each shape's best sampler (see
    /// [`solid_angle_sampling`](super::solid_angle_sampling)).
    pub fn sample_from(&self, p: Vec3, u: Vec2) -> Option<ShapeSample> {
        match self {
            Shape::Sphere(s) => s.sample_from(p, u),
            Shape::Rectangle(r) => r.sample_from(p, u),
            Shape::Disk(d) => d.sample_from(p, u),
            Shape::Mesh(m) => m.sample_from(p, u),
        }
    }

    /// [`sample_from`](Self::sample_from) in lanes, for the shapes whose sampler has a lane
    /// form (spheres, disks); the others draw no lane (their lanes are sampled one by
    /// one, in f64).
    #[inline(always)]
    pub fn sample_from_lanes<R: Real>(&self, p: LVec3<R>, u0: R, u1: R) -> ShapeSampleLanes<R> {
        match self {
            Shape::Sphere(s) => s.sample_from_lanes(p, u0, u1),
            Shape::Disk(d) => d.sample_from_lanes(p, u0, u1),
            Shape::Rectangle(_) | Shape::Mesh(_) => ShapeSampleLanes::none(),
        }
    }

    /// Density per unit solid angle with which [`sample_from`](Self::sample_from) at `p`
    /// produces the direction towards `q` (normal `nq`) on primitive `prim` (the triangle
    /// of a mesh).
    pub fn pdf_from(&self, p: Vec3, q: Vec3, nq: Vec3, prim: u32) -> f64 {
        match self {
            Shape::Sphere(s) => s.pdf_from(p, q, nq),
            Shape::Rectangle(r) => r.pdf_from(p, q),
            Shape::Disk(d) => d.pdf_from(p, q),
            Shape::Mesh(m) => m.pdf_from(prim as usize, p, q, nq),
        }
    }

    /// Closest hit without acceleration (shape index 0); the scene uses its BVH instead.
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceHit> {
        match self {
            Shape::Sphere(s) => s.intersect(ray),
            Shape::Rectangle(r) => r.intersect(ray),
            Shape::Disk(d) => d.intersect(ray),
            Shape::Mesh(m) => m.intersect(ray),
        }
    }
}

impl From<Sphere> for Shape {
    fn from(s: Sphere) -> Shape {
        Shape::Sphere(s)
    }
}

impl From<Rectangle> for Shape {
    fn from(r: Rectangle) -> Shape {
        Shape::Rectangle(r)
    }
}

impl From<Disk> for Shape {
    fn from(d: Disk) -> Shape {
        Shape::Disk(d)
    }
}

impl From<TriangleMesh> for Shape {
    fn from(m: TriangleMesh) -> Shape {
        Shape::Mesh(Arc::new(m))
    }
}

impl From<Arc<TriangleMesh>> for Shape {
    fn from(m: Arc<TriangleMesh>) -> Shape {
        Shape::Mesh(m)
    }
}
