//! What the planar shapes (rectangle, disk) share: an object space where the shape lies in
//! the plane `z = 0` with normal +z, Mitsuba's `flip_normals` as a mirror of that space,
//! the ray–plane intersection done in object space, and the re-projection of world hits
//! onto the plane. Each shape adds only its outline, parameterization and sampling.

use super::bounds::Bounds3;
use super::error::{GeometryError, GeometryResult};
use super::ray::Ray;
use super::transform::Transform;
use super::{Vec2, Vec3};
use facette_bsdf::lanes::{LVec3, Real};

/// The placement of a planar shape: its object-to-world transform and what follows from
/// it (world normal and centre).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct PlaneFrame {
    to_world: Transform,
    normal: Vec3,
    center: Vec3,
}

impl PlaneFrame {
    /// The frame of the shape named `shape` (for errors). Only affine transforms keep a
    /// plane a plane with a constant normal, so perspective is rejected; `flip_normals`
    /// composes `to_world · scale(1, 1, −1)` as Mitsuba does, which inverts the normal and
    /// keeps `uv` and the tangents.
    pub fn new(
        to_world: &Transform,
        flip_normals: bool,
        shape: &'static str,
    ) -> GeometryResult<PlaneFrame> {
        if !to_world.is_affine() {
            return Err(GeometryError::UnsupportedTransform {
                shape,
                reason: "perspective transforms are not supported",
            });
        }
        let to_world = if flip_normals {
            *to_world * Transform::scale(Vec3::new(1.0, 1.0, -1.0))?
        } else {
            *to_world
        };
        Ok(PlaneFrame {
            normal: to_world.normal(Vec3::Z).normalize(),
            center: to_world.point(Vec3::ZERO),
            to_world,
        })
    }

    /// The object-to-world transform (with the `flip_normals` mirror, if any).
    #[inline]
    pub fn to_world(&self) -> &Transform {
        &self.to_world
    }

    /// The unit world normal.
    #[inline]
    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    /// The world point at object-space `(x, y, 0)`.
    #[inline]
    pub fn point(&self, x: f64, y: f64) -> Vec3 {
        self.to_world.point(Vec3::new(x, y, 0.0))
    }

    /// The box of the transformed square `[−1, 1]²` (which holds both shapes' outlines).
    pub fn square_bounds(&self) -> Bounds3 {
        Bounds3::from_points(
            [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(x, y)| self.point(x, y)),
        )
    }

    /// The ray's crossing of the plane in `(0, ray.t_max]`, found in object space (where
    /// the plane is z = 0, so the test is exact for rays nearly parallel to it): `t` and
    /// the object-space `(x, y)`. Rays parallel to the plane miss.
    pub fn intersect_plane(&self, ray: &Ray) -> Option<(f64, Vec2)> {
        let (hit, t, x, y) =
            self.intersect_plane_lanes::<f64>(ray.origin.into(), ray.dir.into(), ray.t_max);
        hit.then(|| (t, Vec2::new(x, y)))
    }

    /// [`intersect_plane`](Self::intersect_plane) over lanes, its one source: the lanes
    /// that hit in `(0, t_max]`, `t` and the object-space `(x, y)`.
    #[inline(always)]
    pub fn intersect_plane_lanes<R: Real>(
        &self,
        o: LVec3<R>,
        d: LVec3<R>,
        t_max: R,
    ) -> (R::Mask, R, R, R) {
        let o = self.to_world.inverse_point_lanes(o);
        let d = self.to_world.inverse_vector_lanes(d);
        let t = -o.z / d.z;
        // A ray parallel to the plane (d.z = 0) would get t = ±∞ or NaN: never a hit, even
        // below an infinite t_max.
        let hit = !d.z.eq(R::zero()) & t.gt(R::zero()) & t.le(t_max);
        (hit, t, o.x + t * d.x, o.y + t * d.y)
    }

    /// `p` moved onto the plane along the normal, as Mitsuba does with its hits: spawned
    /// rays then start from the surface itself.
    #[inline]
    pub fn reproject(&self, p: Vec3) -> Vec3 {
        p + self.normal * self.normal.dot(self.center - p)
    }

    /// [`reproject`](Self::reproject) over lanes.
    #[inline(always)]
    pub fn reproject_lanes<R: Real>(&self, p: LVec3<R>) -> LVec3<R> {
        let n = LVec3::splat(self.normal);
        p + n.scale(n.dot(LVec3::splat(self.center) - p))
    }
}
