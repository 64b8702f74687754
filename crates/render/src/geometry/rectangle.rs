//! The rectangle, with Mitsuba 3's parameterization (`src/shapes/rectangle.cpp`).
//!
//! | parameter      | meaning                                                       |
//! |----------------|---------------------------------------------------------------|
//! | `to_world`     | affine object-to-world transform (default identity)           |
//! | `flip_normals` | normal along local −z instead of +z                           |
//!
//! # Conventions
//! In object space the rectangle is the square `[−1, 1]²` in the plane `z = 0` with normal
//! +z. For a hit at local `(x, y)`:
//! - `uv = ((x + 1)/2, (y + 1)/2)`: `(0, 0)` at the local corner `(−1, −1)`;
//! - `dpdu = to_world · (2, 0, 0)`, `dpdv = to_world · (0, 2, 0)` (exact derivatives);
//! - `ng = ns = normalize(to_world`'s normal transform of `(0, 0, 1))`.
//!
//! `flip_normals` is applied as Mitsuba does, by composing `to_world · scale(1, 1, −1)`:
//! it inverts the normal and keeps `uv` and the tangents. Any affine `to_world` is
//! accepted (a shear makes a parallelogram, still sampled uniformly); perspective is
//! rejected.

use super::bounds::Bounds3;
use super::error::GeometryResult;
use super::interaction::{PrimHit, SurfaceHit};
use super::planar::PlaneFrame;
use super::ray::Ray;
use super::solid_angle_sampling::{
    area_sample_from, area_to_solid_angle, use_spherical_sampling, ShapeSample,
};
use super::spherical_rectangle::SphericalRectangle;
use super::transform::Transform;
use super::{Vec2, Vec3};
use facette_bsdf::lanes::{LVec3, Real};

#[derive(Clone, Debug, PartialEq)]
pub struct Rectangle {
    plane: PlaneFrame,
    dpdu: Vec3,
    dpdv: Vec3,
    area: f64,
}

impl Rectangle {
    pub fn new(to_world: &Transform, flip_normals: bool) -> GeometryResult<Rectangle> {
        let plane = PlaneFrame::new(to_world, flip_normals, "rectangle")?;
        let dpdu = plane.to_world().vector(Vec3::new(2.0, 0.0, 0.0));
        let dpdv = plane.to_world().vector(Vec3::new(0.0, 2.0, 0.0));
        Ok(Rectangle {
            area: dpdu.cross(dpdv).length(),
            plane,
            dpdu,
            dpdv,
        })
    }

    /// The object-to-world transform (with the `flip_normals` mirror, if any).
    #[inline]
    pub fn to_world(&self) -> &Transform {
        self.plane.to_world()
    }

    /// The unit normal.
    #[inline]
    pub fn normal(&self) -> Vec3 {
        self.plane.normal()
    }

    pub fn bounds(&self) -> Bounds3 {
        self.plane.square_bounds()
    }

    #[inline]
    pub fn area(&self) -> f64 {
        self.area
    }

    /// The hit in `(0, ray.t_max]`, found in object space (where the plane is z = 0);
    /// `local` is the object-space `(x, y)`.
    pub fn intersect_prim(&self, ray: &Ray) -> Option<PrimHit> {
        let (hit, t, x, y) =
            self.intersect_lanes::<f64>(ray.origin.into(), ray.dir.into(), ray.t_max);
        hit.then(|| PrimHit {
            t,
            local: Vec2::new(x, y),
        })
    }

    /// [`intersect_prim`](Self::intersect_prim) over lanes, its one source: the lanes that
    /// hit in `(0, t_max]`, `t` and the object-space `(x, y)`.
    #[inline(always)]
    pub fn intersect_lanes<R: Real>(
        &self,
        o: LVec3<R>,
        d: LVec3<R>,
        t_max: R,
    ) -> (R::Mask, R, R, R) {
        let (hit, t, x, y) = self.plane.intersect_plane_lanes(o, d, t_max);
        (hit & x.abs().le(R::one()) & y.abs().le(R::one()), t, x, y)
    }

    /// The hit points of rays `o + t d` (the lanes' [`surface_hit`](Self::surface_hit)
    /// points): moved onto the plane.
    #[inline(always)]
    pub fn hit_points_lanes<R: Real>(&self, o: LVec3<R>, d: LVec3<R>, t: R) -> LVec3<R> {
        self.plane.reproject_lanes(o + d.scale(t))
    }

    /// The tangents along u and v (constant over the rectangle).
    pub fn tangents(&self) -> (Vec3, Vec3) {
        (self.dpdu, self.dpdv)
    }

    pub fn surface_hit(&self, ray: &Ray, hit: PrimHit, shape: u32) -> SurfaceHit {
        SurfaceHit {
            t: hit.t,
            p: self.plane.reproject(ray.at(hit.t)),
            ng: self.normal(),
            ns: self.normal(),
            uv: hit.local * 0.5 + Vec2::splat(0.5),
            dpdu: self.dpdu,
            dpdv: self.dpdv,
            shape,
            prim: 0,
        }
    }

    /// Hit with shape index 0.
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceHit> {
        self.intersect_prim(ray)
            .map(|h| self.surface_hit(ray, h, 0))
    }

    /// Uniform sample: the affine image of a uniform point of the square, so the density
    /// is the constant `1/area`.
    pub fn sample(&self, u: Vec2) -> (Vec3, Vec3, f64) {
        let p = self.plane.point(2.0 * u.x - 1.0, 2.0 * u.y - 1.0);
        (p, self.normal(), 1.0 / self.area)
    }

    /// The spherical rectangle seen from `p`, where spherical sampling applies: the shape
    /// is a true rectangle (a shear makes a parallelogram, which the construction does not
    /// cover) and its solid angle is in the usable range.
    fn spherical_from(&self, p: Vec3) -> Option<SphericalRectangle> {
        let corner = self.plane.point(-1.0, -1.0);
        let sr = SphericalRectangle::new(p, corner, self.dpdu, self.dpdv)?;
        use_spherical_sampling(sr.solid_angle()).then_some(sr)
    }

    /// A point seen from `p`, uniform in the solid angle the rectangle subtends
    /// (spherical-rectangle sampling, Ureña et al. 2013); area sampling converted to solid
    /// angle where that does not apply (see [`solid_angle_sampling`](super::solid_angle_sampling)).
    pub fn sample_from(&self, p: Vec3, u: Vec2) -> Option<ShapeSample> {
        match self.spherical_from(p) {
            Some(sr) => sr.sample(u).map(|s| ShapeSample {
                point: s.point,
                normal: self.normal(),
                pdf: s.pdf,
            }),
            None => area_sample_from(p, self.sample(u)),
        }
    }

    /// Density per unit solid angle with which [`sample_from`](Self::sample_from) at `p`
    /// produces the direction towards the point `q` of the rectangle.
    pub fn pdf_from(&self, p: Vec3, q: Vec3) -> f64 {
        match self.spherical_from(p) {
            Some(sr) => 1.0 / sr.solid_angle(),
            None => area_to_solid_angle(1.0 / self.area, p, q, self.normal()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use facette_bsdf::math::rng::{Pcg32, RandomSource};

    fn close(a: Vec3, b: Vec3, tol: f64) -> bool {
        (a - b).abs().max_element() <= tol
    }

    fn placed() -> Rectangle {
        let t = Transform::translate(Vec3::new(0.0, 0.0, 1.0)).unwrap()
            * Transform::rotate(Vec3::X, 90.0).unwrap()
            * Transform::scale(Vec3::new(2.0, 3.0, 1.0)).unwrap();
        Rectangle::new(&t, false).unwrap()
    }

    #[test]
    fn unit_square_conventions() {
        let r = Rectangle::new(&Transform::IDENTITY, false).unwrap();
        assert_eq!(r.area(), 4.0);
        let h = r
            .intersect(&Ray::infinite(Vec3::new(0.5, -0.5, 2.0), -Vec3::Z))
            .unwrap();
        assert!((h.t - 2.0).abs() < 1e-15);
        assert!(close(h.ng, Vec3::Z, 0.0));
        assert!((h.uv - Vec2::new(0.75, 0.25)).abs().max_element() < 1e-15);
        assert_eq!(h.dpdu, Vec3::new(2.0, 0.0, 0.0));
        assert_eq!(h.dpdv, Vec3::new(0.0, 2.0, 0.0));
        // Corner (-1, -1) is uv (0, 0); hits from below too (two-sided geometry).
        let c = r
            .intersect(&Ray::infinite(Vec3::new(-1.0, -1.0, -1.0), Vec3::Z))
            .unwrap();
        assert!(c.uv.abs().max_element() < 1e-15);
        assert!(close(c.ng, Vec3::Z, 0.0));
    }

    #[test]
    fn misses_parallel_and_t_max() {
        let r = Rectangle::new(&Transform::IDENTITY, false).unwrap();
        assert!(r
            .intersect(&Ray::infinite(Vec3::new(1.5, 0.0, 1.0), -Vec3::Z))
            .is_none());
        assert!(r
            .intersect(&Ray::infinite(Vec3::new(-2.0, 0.0, 0.0), Vec3::X))
            .is_none());
        assert!(r
            .intersect(&Ray::new(Vec3::new(0.0, 0.0, 1.0), -Vec3::Z, 0.999))
            .is_none());
        assert!(r
            .intersect(&Ray::infinite(Vec3::new(0.0, 0.0, 1.0), Vec3::Z))
            .is_none());
        // Grazing but not parallel: still hits inside the square.
        let g = Ray::infinite(Vec3::new(-0.9, 0.0, 1e-6), Vec3::new(1.0, 0.0, -1e-6));
        let h = r.intersect(&g).unwrap();
        assert!((h.p.x + 0.9 - 1.0).abs() < 1e-9 && h.p.z == 0.0);
    }

    #[test]
    fn transformed_rectangle() {
        let r = placed();
        // Local z → world -y... rotate +90° about X maps +z to -y.
        assert!(close(r.normal(), -Vec3::Y, 1e-15));
        assert!((r.area() - 24.0).abs() < 1e-13);
        let h = r
            .intersect(&Ray::infinite(Vec3::new(1.0, -5.0, 1.0 + 1.5), Vec3::Y))
            .unwrap();
        // World (1, 0, 2.5) is local (0.5, 0.5): uv (0.75, 0.75).
        assert!((h.uv - Vec2::new(0.75, 0.75)).abs().max_element() < 1e-14);
        assert!(close(h.dpdu, Vec3::new(4.0, 0.0, 0.0), 1e-14));
        assert!(close(h.dpdv, Vec3::new(0.0, 0.0, 6.0), 1e-14));
        let b = r.bounds();
        assert!(close(b.min, Vec3::new(-2.0, 0.0, -2.0), 1e-14));
        assert!(close(b.max, Vec3::new(2.0, 0.0, 4.0), 1e-14));
    }

    #[test]
    fn flip_normals_keeps_uv() {
        let r = Rectangle::new(&Transform::IDENTITY, true).unwrap();
        let h = r
            .intersect(&Ray::infinite(Vec3::new(0.5, -0.5, 2.0), -Vec3::Z))
            .unwrap();
        assert!(close(h.ng, -Vec3::Z, 0.0));
        assert!((h.uv - Vec2::new(0.75, 0.25)).abs().max_element() < 1e-15);
    }

    #[test]
    fn rejects_perspective() {
        let m = glam::DMat4::perspective_rh(1.0, 1.0, 0.1, 10.0);
        let t = Transform::try_new(m).unwrap();
        assert!(Rectangle::new(&t, false).is_err());
    }

    #[test]
    fn samples_lie_on_the_shape_with_pdf_one_over_area() {
        let r = placed();
        let mut rng = Pcg32::new(3, 1);
        let mut mean = Vec3::ZERO;
        let n = 20_000;
        for _ in 0..n {
            let (p, nrm, pdf) = r.sample(rng.next_2d());
            let local = r.to_world().inverse_point(p);
            assert!(local.z.abs() < 1e-14);
            assert!(local.x.abs() <= 1.0 + 1e-14 && local.y.abs() <= 1.0 + 1e-14);
            assert_eq!(nrm, r.normal());
            assert!((pdf * r.area() - 1.0).abs() < 1e-14);
            mean += p;
        }
        assert!(close(mean / n as f64, Vec3::new(0.0, 0.0, 1.0), 0.05));
    }
}
