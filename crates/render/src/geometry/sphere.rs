//! The analytic sphere, with Mitsuba 3's parameterization (`src/shapes/sphere.cpp`).
//!
//! | parameter      | meaning                                                           |
//! |----------------|-------------------------------------------------------------------|
//! | `center`       | centre (default origin)                                           |
//! | `radius`       | radius > 0 (default 1)                                            |
//! | `to_world`     | similarity transform (rotation, uniform scale, translation); the  |
//! |                | effective object-to-world map is `to_world · translate(center) ·  |
//! |                | scale(radius)`, as in Mitsuba                                     |
//! | `flip_normals` | normals point inward                                              |
//!
//! # Conventions
//! With `l` the hit point on the unit sphere of object space (`θ` polar angle from local
//! +z, `φ` azimuth from local +x towards +y, in [0, 2π)):
//! - `uv = (φ / 2π, θ / π)`: `v = 0` at the local north pole (+z), `u = 0` on the local
//!   +x half-plane;
//! - `dpdu = to_world · 2π (−l.y, l.x, 0)`, `dpdv = to_world · π (l.z cos φ, l.z sin φ,
//!   −sin θ)` — the true partial derivatives of the point with respect to `uv` (at the
//!   poles Mitsuba's choice `dpdv ∝ (1, 0, 0)` is kept);
//! - `ng = ns` = outward unit normal, inverted by `flip_normals`. As in Mitsuba, a
//!   mirroring `to_world` (negative determinant) also inverts the normals.
//!
//! Non-uniform scale and shear are rejected (Mitsuba only warns; the result would not be a
//! sphere).

use super::bounds::Bounds3;
use super::error::{GeometryError, GeometryResult};
use super::interaction::{PrimHit, SurfaceHit};
use super::ray::Ray;
use super::solid_angle_sampling::{
    area_sample_from, area_to_solid_angle, ShapeSample, ShapeSampleLanes,
};
use super::transform::Transform;
use super::{Vec2, Vec3};
use facette_bsdf::lanes::{LFrame, LVec3, Mask, Real};
use facette_bsdf::math::warp::square_to_uniform_sphere;
use std::f64::consts::{PI, TAU};

#[derive(Clone, Debug, PartialEq)]
pub struct Sphere {
    /// Object (unit sphere) to world.
    to_world: Transform,
    center: Vec3,
    radius: f64,
    flip_normals: bool,
}

impl Sphere {
    /// A sphere of `radius` at `center`, outward normals.
    pub fn new(center: Vec3, radius: f64) -> GeometryResult<Sphere> {
        Self::with_transform(center, radius, &Transform::IDENTITY, false)
    }

    /// The full Mitsuba parameter set: the unit sphere placed by `to_world ·
    /// translate(center) · scale(radius)`.
    pub fn with_transform(
        center: Vec3,
        radius: f64,
        to_world: &Transform,
        flip_normals: bool,
    ) -> GeometryResult<Sphere> {
        if !center.is_finite() {
            return Err(param("center", format!("{center}"), "finite coordinates"));
        }
        if !(radius > 0.0 && radius <= facette_bsdf::limits::MAX_COORDINATE) {
            return Err(param(
                "radius",
                format!("{radius}"),
                "a number > 0 and at most 1e30 (the scene coordinate limit)",
            ));
        }
        let placed =
            *to_world * Transform::translate(center)? * Transform::scale(Vec3::splat(radius))?;
        let Some(world_radius) = placed.similarity_scale() else {
            return Err(GeometryError::UnsupportedTransform {
                shape: "sphere",
                reason: "it must be a rotation, uniform scale and translation (no shear, \
                         non-uniform scale or perspective)",
            });
        };
        let mirrored = placed.linear_determinant() < 0.0;
        Ok(Sphere {
            center: placed.point(Vec3::ZERO),
            radius: world_radius,
            to_world: placed,
            flip_normals: flip_normals != mirrored,
        })
    }

    #[inline]
    pub fn center(&self) -> Vec3 {
        self.center
    }

    #[inline]
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Whether normals point inward.
    #[inline]
    pub fn flip_normals(&self) -> bool {
        self.flip_normals
    }

    /// The object-to-world transform of the unit sphere (centre and radius included).
    #[inline]
    pub fn to_world(&self) -> &Transform {
        &self.to_world
    }

    pub fn bounds(&self) -> Bounds3 {
        Bounds3::new(
            self.center - Vec3::splat(self.radius),
            self.center + Vec3::splat(self.radius),
        )
    }

    #[inline]
    pub fn area(&self) -> f64 {
        4.0 * PI * self.radius * self.radius
    }

    /// The nearest hit in `(0, ray.t_max]`. From inside the sphere this is the far
    /// root. The quadratic is solved as in pbrt-v4 (`Sphere::BasicIntersect`): the
    /// discriminant from the distance between the centre and the ray's closest point
    /// (no cancellation for distant origins) and the stable root pair `q`, `c/q`.
    pub fn intersect_prim(&self, ray: &Ray) -> Option<PrimHit> {
        let (hit, t) = self.intersect_lanes::<f64>(ray.origin.into(), ray.dir.into(), ray.t_max);
        hit.then_some(PrimHit {
            t,
            local: Vec2::ZERO,
        })
    }

    /// [`intersect_prim`](Self::intersect_prim) for a lane of rays (origins `o`,
    /// directions `d`, limits `t_max`): whether each lane hits in `(0, t_max]`, and where.
    /// The one source of the sphere test: `f64` for one ray, `F64x4` for the packet
    /// kernel's rays four at a time, bit for bit the same. It is pbrt-v4's robust
    /// quadratic: the discriminant from the distance of the ray's closest approach
    /// (Haines et al., *Ray Tracing Gems* ch. 7), both roots without cancellation.
    #[inline(always)]
    pub fn intersect_lanes<R: Real>(&self, o: LVec3<R>, d: LVec3<R>, t_max: R) -> (R::Mask, R) {
        let zero = R::zero();
        let o = o - LVec3::splat(self.center);
        let a = d.length_squared();
        let half_b = o.dot(d);
        let r = R::splat(self.radius);
        let c = o.length_squared() - r * r;
        let closest = (o - d.scale(half_b / a)).length_squared().sqrt();
        let disc = a * (r + closest) * (r - closest);
        // Every lane misses (one ray: this ray misses): skip the roots.
        let real = a.gt(zero) & disc.ge(zero);
        if real.none() {
            return (real, zero);
        }
        let root = disc.sqrt();
        let q = R::select(half_b.gt(zero), -(half_b + root), -(half_b - root));
        let (r0, r1) = (q / a, c / q);
        let (t0, t1) = (r0.min(r1), R::select(r0.gt(r1), r0, r1));
        let t = R::select(t0.gt(zero), t0, t1);
        // `q == 0`: origin on the sphere, ray tangent (both roots 0). The comparisons are
        // false for NaN lanes (a zero direction, a negative discriminant's root); a NaN
        // root is refused before `min` could drop it.
        let ordered = r0.eq(r0) & r1.eq(r1);
        let hit = real & !q.eq(zero) & ordered & t0.le(t_max) & t1.gt(zero);
        (hit & t.le(t_max), t)
    }

    /// The surface details of a hit found by [`intersect_prim`](Self::intersect_prim).
    pub fn surface_hit(&self, ray: &Ray, hit: PrimHit, shape: u32) -> SurfaceHit {
        let mut h = self.shading_hit(ray, hit, shape);
        self.complete_hit(&mut h);
        h
    }

    /// A hit with `uv` left at zero and `dpdu`, `dpdv` at their directions (not their
    /// lengths): the frame of an untextured material, without the `acos`/`atan2`/`sqrt` of
    /// the uv parameterization. [`complete_hit`](Self::complete_hit) fills the rest.
    pub fn shading_hit(&self, ray: &Ray, hit: PrimHit, shape: u32) -> SurfaceHit {
        let (p, n, dpdu, l) =
            self.shading_hit_lanes::<f64>(ray.origin.into(), ray.dir.into(), hit.t);
        let l: Vec3 = l.into();
        let dpdv = self
            .to_world
            .vector(Vec3::new(l.z * l.x, l.z * l.y, -(l.x * l.x + l.y * l.y)));
        SurfaceHit {
            t: hit.t,
            p: p.into(),
            ng: n.into(),
            ns: n.into(),
            uv: Vec2::ZERO,
            dpdu: dpdu.into(),
            dpdv,
            shape,
            prim: 0,
        }
    }

    /// The point, normal and dp/du direction of [`shading_hit`](Self::shading_hit) over
    /// lanes of rays (origins `o`, directions `d`) hitting at `t` — its one source — and the
    /// outward direction in object space (dp/dv's direction follows from it).
    #[inline(always)]
    pub fn shading_hit_lanes<R: Real>(
        &self,
        o: LVec3<R>,
        d: LVec3<R>,
        t: R,
    ) -> (LVec3<R>, LVec3<R>, LVec3<R>, LVec3<R>) {
        let v = (o + d.scale(t)) - LVec3::splat(self.center);
        // glam's normalize_or_zero, then −d for a zero vector.
        let rcp = R::one() / v.length_squared().sqrt();
        let ok = rcp.is_finite() & rcp.gt(R::zero());
        let outward = LVec3::select(ok, v.scale(rcp), -d);
        // Re-project onto the surface (Mitsuba does the same) to bound the error of `p`.
        let p = LVec3::splat(self.center) + outward.scale(R::splat(self.radius));
        let l = self.to_world.inverse_vector_lanes(outward);
        // The direction of the parameterization's dp/du (see `parameterization`).
        let dpdu = self.to_world.vector_lanes(LVec3::new(-l.y, l.x, R::zero()));
        let n = if self.flip_normals { -outward } else { outward };
        (p, n, dpdu, l)
    }

    /// Replaces the tangent directions of a [`shading_hit`](Self::shading_hit) by the
    /// parameterization's uv, dp/du and dp/dv.
    pub fn complete_hit(&self, hit: &mut SurfaceHit) {
        // The geometric normal is the outward direction, up to the flip.
        let outward = if self.flip_normals { -hit.ng } else { hit.ng };
        (hit.uv, hit.dpdu, hit.dpdv) = self.parameterization(outward);
    }

    /// Hit with shape index 0 (for using a sphere on its own).
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceHit> {
        self.intersect_prim(ray)
            .map(|h| self.surface_hit(ray, h, 0))
    }

    /// uv and its derivatives at the point in world direction `outward` from the centre.
    fn parameterization(&self, outward: Vec3) -> (Vec2, Vec3, Vec3) {
        let l = self.to_world.inverse_vector(outward).normalize_or_zero();
        let theta = l.z.clamp(-1.0, 1.0).acos();
        let mut phi = l.y.atan2(l.x);
        if phi < 0.0 {
            phi += TAU;
        }
        let uv = Vec2::new(phi / TAU, theta / PI);
        let dpdu_local = TAU * Vec3::new(-l.y, l.x, 0.0);
        let rd = (l.x * l.x + l.y * l.y).sqrt();
        let dpdv_local = if rd > 0.0 {
            PI * Vec3::new(l.z * l.x / rd, l.z * l.y / rd, -rd)
        } else {
            PI * Vec3::X
        };
        (
            uv,
            self.to_world.vector(dpdu_local),
            self.to_world.vector(dpdv_local),
        )
    }

    /// Uniform sample of the surface: `(point, normal, pdf per unit area = 1/area)`.
    pub fn sample(&self, u: Vec2) -> (Vec3, Vec3, f64) {
        let local = square_to_uniform_sphere(u);
        let outward = self.to_world.vector(local).normalize_or_zero();
        let p = self.center + self.radius * outward;
        let n = if self.flip_normals { -outward } else { outward };
        (p, n, 1.0 / self.area())
    }

    /// The cone of directions the sphere subtends from outside points `p`, in lanes: the
    /// lanes where `p` is outside (on the surface or closer the cone would be a hemisphere
    /// or more), `sin² θ_max` and `1 − cos θ_max`. The latter as `sin² θ_max / (1 +
    /// cos θ_max)`, which has no cancellation where the sphere is small or far (`1 − cos`
    /// of a tiny angle would round to zero, in f32 lanes already at `sin² θ_max` ≈ 1e-7)
    /// and needs no series.
    #[inline(always)]
    fn cone_from_lanes<R: Real>(&self, p: LVec3<R>) -> (R::Mask, R, R) {
        let dist2 = (LVec3::splat(self.center) - p).length_squared();
        let r2 = R::splat(self.radius * self.radius);
        let outside = dist2.gt(r2 * R::splat(1.0 + 1e-9));
        let sin2_max = R::select(outside, r2 / dist2, R::zero());
        let one_minus_cos_max = sin2_max / (R::one() + (R::one() - sin2_max).sqrt());
        (outside, sin2_max, one_minus_cos_max)
    }

    /// [`cone_from_lanes`](Self::cone_from_lanes) at one point: `None` from inside or on
    /// the surface.
    fn cone_from(&self, p: Vec3) -> Option<(f64, f64)> {
        let (outside, sin2_max, one_minus_cos_max) = self.cone_from_lanes::<f64>(p.into());
        outside.then_some((sin2_max, one_minus_cos_max))
    }

    /// A point of the sphere seen from `p`, its direction uniform in the cone the sphere
    /// subtends (pdf `1 / (2π (1 − cos θ_max))` per unit solid angle); from inside, a
    /// uniform area sample converted to solid angle. The cone's direction at angle θ from
    /// the axis meets the sphere at the point whose angle α at the centre (from the axis
    /// towards `p`) satisfies `cos α = sin² θ / sin θ_max + cos θ √(1 − sin² θ / sin² θ_max)`
    /// — the law of sines in the triangle (p, centre, point), written without the
    /// cancellation a ray–sphere intersection has for far spheres (the form of pbrt-v4's
    /// `Sphere::Sample(ctx, u)`).
    pub fn sample_from(&self, p: Vec3, u: Vec2) -> Option<ShapeSample> {
        let s = self.sample_from_lanes::<f64>(p.into(), u.x, u.y);
        if !s.drawn {
            return area_sample_from(p, self.sample(u));
        }
        Some(ShapeSample {
            point: s.point.into(),
            normal: s.normal.into(),
            pdf: s.pdf,
        })
    }

    /// [`sample_from`](Self::sample_from)'s cone sample in lanes, its one source (the render
    /// kernel's next-event estimation draws eight sphere-light samples at once); the lanes
    /// where `p` is inside or on the sphere are not drawn (the caller draws those by area,
    /// lane by lane).
    #[inline(always)]
    pub fn sample_from_lanes<R: Real>(&self, p: LVec3<R>, u0: R, u1: R) -> ShapeSampleLanes<R> {
        let (outside, sin2_max, one_minus_cos_max) = self.cone_from_lanes(p);
        // θ uniform in solid angle: 1 − cos θ uniform in [0, 1 − cos θ_max].
        let one_minus_cos = u0 * one_minus_cos_max;
        let cos_theta = R::one() - one_minus_cos;
        let sin2_theta = one_minus_cos * (R::splat(2.0) - one_minus_cos);
        let cos_alpha = sin2_theta / sin2_max.sqrt()
            + cos_theta * (R::one() - sin2_theta / sin2_max).max(R::zero()).sqrt();
        let cos_alpha = cos_alpha.clamp(-1.0, 1.0);
        let sin_alpha = (R::one() - cos_alpha * cos_alpha).max(R::zero()).sqrt();
        let (sin_phi, cos_phi) = (R::splat(TAU) * u1).sin_cos();
        let center = LVec3::splat(self.center);
        let axis = (p - center).normalize();
        let frame = LFrame::from_normal(axis);
        let outward = frame.to_world(LVec3::new(
            sin_alpha * cos_phi,
            sin_alpha * sin_phi,
            cos_alpha,
        ));
        let point = center + outward.scale(R::splat(self.radius));
        let normal = if self.flip_normals { -outward } else { outward };
        ShapeSampleLanes {
            drawn: outside,
            point,
            normal,
            pdf: R::one() / (R::splat(TAU) * one_minus_cos_max),
        }
    }

    /// Density per unit solid angle with which [`sample_from`](Self::sample_from) at `p`
    /// produces the direction towards the surface point `q` (normal `nq`).
    pub fn pdf_from(&self, p: Vec3, q: Vec3, nq: Vec3) -> f64 {
        match self.cone_from(p) {
            Some((_, one_minus_cos_max)) => 1.0 / (TAU * one_minus_cos_max),
            None => area_to_solid_angle(1.0 / self.area(), p, q, nq),
        }
    }
}

fn param(name: &'static str, value: String, expected: &'static str) -> GeometryError {
    GeometryError::InvalidShapeParameter {
        shape: "sphere",
        name,
        value,
        expected,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3, tol: f64) -> bool {
        (a - b).abs().max_element() <= tol
    }

    #[test]
    fn hits_from_outside_and_inside() {
        let s = Sphere::new(Vec3::new(0.0, 0.0, 5.0), 2.0).unwrap();
        let h = s.intersect(&Ray::infinite(Vec3::ZERO, Vec3::Z)).unwrap();
        assert!((h.t - 3.0).abs() < 1e-14);
        assert!(close(h.p, Vec3::new(0.0, 0.0, 3.0), 1e-14));
        assert!(close(h.ng, -Vec3::Z, 1e-15));
        // Inside: far root, normal still outward.
        let h = s
            .intersect(&Ray::infinite(Vec3::new(0.0, 0.0, 5.0), Vec3::X))
            .unwrap();
        assert!((h.t - 2.0).abs() < 1e-14);
        assert!(close(h.ng, Vec3::X, 1e-15));
        // Miss, behind, t_max.
        assert!(s
            .intersect(&Ray::infinite(Vec3::ZERO, Vec3::new(1.0, 0.0, 1.0)))
            .is_none());
        assert!(s.intersect(&Ray::infinite(Vec3::ZERO, -Vec3::Z)).is_none());
        assert!(s.intersect(&Ray::new(Vec3::ZERO, Vec3::Z, 2.999)).is_none());
        assert!(s.intersect(&Ray::new(Vec3::ZERO, Vec3::Z, 3.001)).is_some());
        assert!(s
            .intersect(&Ray::new(Vec3::ZERO, Vec3::ZERO, 10.0))
            .is_none());
    }

    #[test]
    fn grazing_rays() {
        let s = Sphere::new(Vec3::ZERO, 1.0).unwrap();
        // Tangent at x = 1 (touches), slightly outside (misses), slightly inside (hits twice).
        let inside = Ray::infinite(Vec3::new(1.0 - 1e-9, -10.0, 0.0), Vec3::Y);
        let h = s.intersect(&inside).unwrap();
        assert!((h.p.length() - 1.0).abs() < 1e-14);
        assert!(h.t < 10.0);
        let outside = Ray::infinite(Vec3::new(1.0 + 1e-9, -10.0, 0.0), Vec3::Y);
        assert!(s.intersect(&outside).is_none());
        let tangent = Ray::infinite(Vec3::new(1.0, -10.0, 0.0), Vec3::Y);
        if let Some(h) = s.intersect(&tangent) {
            assert!((h.t - 10.0).abs() < 1e-6 && h.p.is_finite());
        }
    }

    #[test]
    fn distant_origin_stays_accurate() {
        let s = Sphere::new(Vec3::ZERO, 1.0).unwrap();
        let h = s
            .intersect(&Ray::infinite(Vec3::new(0.5, 0.0, -1e7), Vec3::Z))
            .unwrap();
        assert!((h.p.length() - 1.0).abs() < 1e-15);
        assert!((h.p.z + 0.75f64.sqrt()).abs() < 1e-8);
    }

    #[test]
    fn uv_and_derivatives_follow_mitsuba() {
        let s = Sphere::new(Vec3::new(1.0, 2.0, 3.0), 2.0).unwrap();
        // Point at θ = 60°, φ = 120°.
        let (theta, phi) = (PI / 3.0, 2.0 * PI / 3.0);
        let dir = Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        );
        let target = s.center() + 2.0 * dir;
        let h = s
            .intersect(&Ray::infinite(target + 3.0 * dir, -dir))
            .unwrap();
        assert!(close(h.p, target, 1e-13));
        assert!((h.uv.x - 1.0 / 3.0).abs() < 1e-14);
        assert!((h.uv.y - 1.0 / 3.0).abs() < 1e-14);
        // Finite differences of p(u, v) = c + r (sin πv cos 2πu, sin πv sin 2πu, cos πv).
        let p = |u: f64, v: f64| {
            s.center()
                + 2.0
                    * Vec3::new(
                        (PI * v).sin() * (TAU * u).cos(),
                        (PI * v).sin() * (TAU * u).sin(),
                        (PI * v).cos(),
                    )
        };
        let e = 1e-6;
        let fd_u = (p(h.uv.x + e, h.uv.y) - p(h.uv.x - e, h.uv.y)) / (2.0 * e);
        let fd_v = (p(h.uv.x, h.uv.y + e) - p(h.uv.x, h.uv.y - e)) / (2.0 * e);
        assert!(close(h.dpdu, fd_u, 1e-6), "{} vs {fd_u}", h.dpdu);
        assert!(close(h.dpdv, fd_v, 1e-6), "{} vs {fd_v}", h.dpdv);
        assert!(h.dpdu.dot(h.ng).abs() < 1e-12 && h.dpdv.dot(h.ng).abs() < 1e-12);
        // v = 0 at the north pole, u = 0 on +x.
        let top = s
            .intersect(&Ray::infinite(s.center() + Vec3::Z * 5.0, -Vec3::Z))
            .unwrap();
        assert!(top.uv.y.abs() < 1e-12);
        let east = s
            .intersect(&Ray::infinite(s.center() + Vec3::X * 5.0, -Vec3::X))
            .unwrap();
        assert!(east.uv.x.abs() < 1e-12 && (east.uv.y - 0.5).abs() < 1e-12);
    }

    #[test]
    fn rotation_frame_moves_the_parameterization() {
        // Local +z mapped to world +x: the pole (v = 0) is now on +x.
        let rot = Transform::rotate(Vec3::Y, 90.0).unwrap();
        let s = Sphere::with_transform(Vec3::ZERO, 1.0, &rot, false).unwrap();
        let h = s
            .intersect(&Ray::infinite(Vec3::X * 3.0, -Vec3::X))
            .unwrap();
        assert!(h.uv.y.abs() < 1e-12);
        assert!(close(h.ng, Vec3::X, 1e-15));
    }

    #[test]
    fn flip_and_mirror_invert_normals() {
        let s = Sphere::with_transform(Vec3::ZERO, 1.0, &Transform::IDENTITY, true).unwrap();
        let h = s
            .intersect(&Ray::infinite(Vec3::Z * 3.0, -Vec3::Z))
            .unwrap();
        assert!(close(h.ng, -Vec3::Z, 1e-15) && close(h.ns, -Vec3::Z, 1e-15));
        let mirror = Transform::scale(Vec3::splat(-1.0)).unwrap();
        let m = Sphere::with_transform(Vec3::ZERO, 1.0, &mirror, false).unwrap();
        assert!(m.flip_normals());
        assert!((m.radius() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(Sphere::new(Vec3::ZERO, 0.0).is_err());
        assert!(Sphere::new(Vec3::ZERO, f64::NAN).is_err());
        assert!(Sphere::new(Vec3::new(f64::INFINITY, 0.0, 0.0), 1.0).is_err());
        let squash = Transform::scale(Vec3::new(1.0, 2.0, 1.0)).unwrap();
        let e = Sphere::with_transform(Vec3::ZERO, 1.0, &squash, false).unwrap_err();
        assert!(e.to_string().contains("sphere"), "{e}");
        let msg = Sphere::new(Vec3::ZERO, -1.0).unwrap_err().to_string();
        assert!(msg.contains("radius") && msg.contains("-1"), "{msg}");
    }

    #[test]
    fn samples_lie_on_the_surface_with_pdf_one_over_area() {
        let s = Sphere::new(Vec3::new(-1.0, 0.5, 2.0), 0.7).unwrap();
        let mut rng = facette_bsdf::math::rng::Pcg32::new(7, 0);
        use facette_bsdf::math::rng::RandomSource;
        let mut mean = Vec3::ZERO;
        let n = 20_000;
        for _ in 0..n {
            let (p, nrm, pdf) = s.sample(rng.next_2d());
            assert!(((p - s.center()).length() - 0.7).abs() < 1e-14);
            assert!(close(nrm, (p - s.center()) / 0.7, 1e-13));
            assert!((pdf * s.area() - 1.0).abs() < 1e-14);
            mean += p;
        }
        // Uniform on the sphere: the mean is the centre.
        assert!(close(mean / n as f64, s.center(), 0.02));
    }

    /// The render kernel's f32 lanes draw the same cone samples as the f64 sampler, to f32
    /// precision: near spheres (wide cones), far and tiny ones (cones down to sin² θ_max
    /// ≈ 1e-10, where `1 − cos θ_max` computed directly would round to zero in f32), and
    /// points inside, which no lane samples.
    #[test]
    fn f32_lanes_draw_the_f64_cone_samples() {
        use facette_bsdf::lanes::F32x8;
        use facette_bsdf::math::rng::RandomSource;
        let mut rng = facette_bsdf::math::rng::Pcg32::new(11, 3);
        let cases = [
            (Vec3::new(0.3, -0.2, 1.0), 0.5, Vec3::new(0.0, 0.0, 4.0)),
            (Vec3::new(2.0, 1.0, -1.0), 0.25, Vec3::new(2.1, 1.0, -0.6)),
            (
                Vec3::new(-5.0, 3.0, 2.0),
                0.01,
                Vec3::new(40.0, -20.0, 15.0),
            ),
            (Vec3::new(1.0, 2.0, 3.0), 1e-3, Vec3::new(-60.0, 50.0, 30.0)),
            (Vec3::ZERO, 1.0, Vec3::new(0.2, 0.1, -0.3)), // inside
        ];
        let mut worst = (0.0f64, 0.0f64);
        for (flip, (c, r, p)) in cases.into_iter().enumerate() {
            let s = Sphere::with_transform(c, r, &Transform::IDENTITY, flip % 2 == 1).unwrap();
            for _ in 0..64 {
                let u: [Vec2; 8] = std::array::from_fn(|_| rng.next_2d());
                let lanes = s.sample_from_lanes(
                    LVec3::<F32x8>::splat(p),
                    F32x8::from_fn(|i| u[i].x),
                    F32x8::from_fn(|i| u[i].y),
                );
                for (i, &ui) in u.iter().enumerate() {
                    let scalar = s.sample_from_lanes::<f64>(p.into(), ui.x, ui.y);
                    assert_eq!(lanes.drawn.lane(i), scalar.drawn);
                    if !scalar.drawn {
                        continue;
                    }
                    let (q, n) = (lanes.point.lane(i), lanes.normal.lane(i));
                    let dq = (q - Vec3::from(scalar.point)).length() / r;
                    let dn = (n - Vec3::from(scalar.normal)).length();
                    let dp = (lanes.pdf.lane(i) / scalar.pdf - 1.0).abs();
                    worst = (worst.0.max(dq.max(dn)), worst.1.max(dp));
                }
            }
        }
        println!(
            "f32 lanes against f64: point/normal {:.1e}, pdf {:.1e}",
            worst.0, worst.1
        );
        assert!(worst.0 < 1e-3 && worst.1 < 1e-5, "{worst:?}");
    }
}
