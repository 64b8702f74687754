//! The disk, with Mitsuba 3's parameterization (`src/shapes/disk.cpp`).
//!
//! | parameter      | meaning                                                       |
//! |----------------|---------------------------------------------------------------|
//! | `to_world`     | affine object-to-world transform (default identity)           |
//! | `flip_normals` | normal along local −z instead of +z                           |
//!
//! # Conventions
//! In object space the disk is the unit disk in the plane `z = 0`, normal +z. For a hit at
//! local polar coordinates `(r, φ)` (φ from +x towards +y, in [0, 2π)):
//! - `uv = (r, φ / 2π)` — Mitsuba's choice: `u` is the radius, `v` the angle;
//! - `dpdu = to_world · (cos φ, sin φ, 0)` (Mitsuba's, the exact ∂p/∂u), and
//!   `dpdv = to_world · 2πr (−sin φ, cos φ, 0)`, the exact ∂p/∂v. Mitsuba leaves out the
//!   factor `2πr`; the direction, hence the shading frame built from `dpdu`, is the same,
//!   and the factor makes [`uv_derivatives`](super::SurfaceHit::uv_derivatives) correct.
//!   At the centre (`r = 0`) `φ = 0` is used, as Mitsuba does;
//! - `ng = ns = normalize(to_world`'s normal transform of `(0, 0, 1))`.
//!
//! `flip_normals` composes `to_world · scale(1, 1, −1)` as in Mitsuba. Any affine
//! `to_world` is accepted (an ellipse under non-uniform scale, sampled uniformly);
//! perspective is rejected.

use super::bounds::Bounds3;
use super::error::GeometryResult;
use super::interaction::{PrimHit, SurfaceHit};
use super::planar::PlaneFrame;
use super::ray::Ray;
use super::solid_angle_sampling::{
    area_to_solid_angle, area_to_solid_angle_lanes, ShapeSample, ShapeSampleLanes,
};
use super::transform::Transform;
use super::{Vec2, Vec3};
use facette_bsdf::lanes::{LVec3, Real};
use facette_bsdf::math::warp::{square_to_disk_concentric, square_to_disk_concentric_lanes};
use std::f64::consts::{PI, TAU};

#[derive(Clone, Debug, PartialEq)]
pub struct Disk {
    plane: PlaneFrame,
    area: f64,
}

impl Disk {
    pub fn new(to_world: &Transform, flip_normals: bool) -> GeometryResult<Disk> {
        let plane = PlaneFrame::new(to_world, flip_normals, "disk")?;
        let a = plane.to_world().vector(Vec3::X);
        let b = plane.to_world().vector(Vec3::Y);
        Ok(Disk {
            // The affine image of the unit disk is an ellipse of area π |a × b|.
            area: PI * a.cross(b).length(),
            plane,
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

    /// The box of the transformed square `[−1, 1]²` around the disk (conservative).
    pub fn bounds(&self) -> Bounds3 {
        self.plane.square_bounds()
    }

    #[inline]
    pub fn area(&self) -> f64 {
        self.area
    }

    /// The hit in `(0, ray.t_max]`, found in object space; `local` is the object-space
    /// `(x, y)`.
    pub fn intersect_prim(&self, ray: &Ray) -> Option<PrimHit> {
        let (t, local) = self.plane.intersect_plane(ray)?;
        (local.x * local.x + local.y * local.y <= 1.0).then_some(PrimHit { t, local })
    }

    pub fn surface_hit(&self, ray: &Ray, hit: PrimHit, shape: u32) -> SurfaceHit {
        let p = self.plane.reproject(ray.at(hit.t));
        let (x, y) = (hit.local.x, hit.local.y);
        let r = (x * x + y * y).sqrt();
        let mut v = y.atan2(x) / TAU;
        if v < 0.0 {
            v += 1.0;
        }
        let (cos_phi, sin_phi) = if r > 0.0 { (x / r, y / r) } else { (1.0, 0.0) };
        let to_world = self.plane.to_world();
        SurfaceHit {
            t: hit.t,
            p,
            ng: self.normal(),
            ns: self.normal(),
            uv: Vec2::new(r, v),
            dpdu: to_world.vector(Vec3::new(cos_phi, sin_phi, 0.0)),
            dpdv: to_world.vector(TAU * r * Vec3::new(-sin_phi, cos_phi, 0.0)),
            shape,
            prim: 0,
        }
    }

    /// Hit with shape index 0.
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceHit> {
        self.intersect_prim(ray)
            .map(|h| self.surface_hit(ray, h, 0))
    }

    /// Uniform sample (concentric map of the square to the disk, then the affine map;
    /// both preserve uniformity): `(point, normal, 1/area)`.
    pub fn sample(&self, u: Vec2) -> (Vec3, Vec3, f64) {
        let d = square_to_disk_concentric(u);
        (self.plane.point(d.x, d.y), self.normal(), 1.0 / self.area)
    }

    /// A point seen from `p`: the area sample converted to solid angle, as pbrt-v4 and
    /// Mitsuba 3 sample disks (no exact solid-angle sampler of an ellipse is known).
    pub fn sample_from(&self, p: Vec3, u: Vec2) -> Option<ShapeSample> {
        self.sample_from_lanes::<f64>(p.into(), u.x, u.y).lane(0)
    }

    /// [`sample_from`](Self::sample_from) in lanes, its one source: drawn where the
    /// density is positive (not on the disk's plane, not grazing).
    #[inline(always)]
    pub fn sample_from_lanes<R: Real>(&self, p: LVec3<R>, u0: R, u1: R) -> ShapeSampleLanes<R> {
        let (x, y) = square_to_disk_concentric_lanes(u0, u1);
        let point = self
            .plane
            .to_world()
            .point_lanes(LVec3::new(x, y, R::zero()));
        let normal = LVec3::splat(self.normal());
        let pdf = area_to_solid_angle_lanes(1.0 / self.area, p, point, normal);
        ShapeSampleLanes {
            drawn: pdf.gt(R::zero()),
            point,
            normal,
            pdf,
        }
    }

    /// Density per unit solid angle with which [`sample_from`](Self::sample_from) at `p`
    /// produces the direction towards the point `q` of the disk.
    pub fn pdf_from(&self, p: Vec3, q: Vec3) -> f64 {
        area_to_solid_angle(1.0 / self.area, p, q, self.normal())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use facette_bsdf::math::rng::{Pcg32, RandomSource};

    fn close(a: Vec3, b: Vec3, tol: f64) -> bool {
        (a - b).abs().max_element() <= tol
    }

    #[test]
    fn unit_disk_conventions() {
        let d = Disk::new(&Transform::IDENTITY, false).unwrap();
        assert!((d.area() - PI).abs() < 1e-15);
        // Point at r = 0.5, φ = 90°: uv = (0.5, 0.25).
        let h = d
            .intersect(&Ray::infinite(Vec3::new(0.0, 0.5, 3.0), -Vec3::Z))
            .unwrap();
        assert!((h.t - 3.0).abs() < 1e-15);
        assert!((h.uv - Vec2::new(0.5, 0.25)).abs().max_element() < 1e-15);
        assert!(close(h.ng, Vec3::Z, 0.0));
        assert!(close(h.dpdu, Vec3::Y, 1e-15));
        assert!(close(h.dpdv, TAU * 0.5 * -Vec3::X, 1e-15));
        // φ just below the +x axis wraps to v close to 1.
        let h = d
            .intersect(&Ray::infinite(Vec3::new(0.5, -1e-9, 1.0), -Vec3::Z))
            .unwrap();
        assert!(h.uv.y > 0.999_999);
        // Centre: defined, finite.
        let c = d.intersect(&Ray::infinite(Vec3::Z, -Vec3::Z)).unwrap();
        assert_eq!(c.uv, Vec2::ZERO);
        assert!(close(c.dpdu, Vec3::X, 0.0));
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let t = Transform::translate(Vec3::new(1.0, 2.0, 3.0)).unwrap()
            * Transform::rotate(Vec3::new(1.0, -1.0, 0.5), 40.0).unwrap()
            * Transform::scale(Vec3::new(1.5, 0.5, 1.0)).unwrap();
        let d = Disk::new(&t, false).unwrap();
        let p = |u: f64, v: f64| t.point(Vec3::new(u * (TAU * v).cos(), u * (TAU * v).sin(), 0.0));
        let target = p(0.6, 0.3);
        let h = d
            .intersect(&Ray::infinite(target + d.normal() * 2.0, -d.normal()))
            .unwrap();
        assert!(close(h.p, target, 1e-13));
        assert!((h.uv - Vec2::new(0.6, 0.3)).abs().max_element() < 1e-13);
        let e = 1e-6;
        let fd_u = (p(0.6 + e, 0.3) - p(0.6 - e, 0.3)) / (2.0 * e);
        let fd_v = (p(0.6, 0.3 + e) - p(0.6, 0.3 - e)) / (2.0 * e);
        assert!(close(h.dpdu, fd_u, 1e-7));
        assert!(close(h.dpdv, fd_v, 1e-7));
        assert!((d.area() - PI * 0.75).abs() < 1e-13);
    }

    #[test]
    fn misses_and_flip() {
        let d = Disk::new(&Transform::IDENTITY, true).unwrap();
        assert!(d
            .intersect(&Ray::infinite(Vec3::new(0.8, 0.8, 1.0), -Vec3::Z))
            .is_none());
        assert!(d
            .intersect(&Ray::new(Vec3::new(0.0, 0.0, 1.0), -Vec3::Z, 0.5))
            .is_none());
        assert!(d
            .intersect(&Ray::infinite(Vec3::new(-2.0, 0.0, 0.0), Vec3::X))
            .is_none());
        // Grazing: nearly parallel to the plane, still found inside the disk, at the rim.
        let g = Ray::infinite(Vec3::new(-5.0, 0.0, 1e-7), Vec3::new(1.0, 0.0, -2e-8));
        let hg = d.intersect(&g).unwrap();
        assert!((hg.p.x - 0.0).abs() < 1e-8 && hg.p.z == 0.0);
        let rim = Ray::infinite(Vec3::new(1.0 - 1e-12, 0.0, 1.0), -Vec3::Z);
        assert!(d.intersect(&rim).is_some());
        let out = Ray::infinite(Vec3::new(1.0 + 1e-12, 0.0, 1.0), -Vec3::Z);
        assert!(d.intersect(&out).is_none());
        let h = d
            .intersect(&Ray::infinite(Vec3::new(0.0, 0.5, 3.0), -Vec3::Z))
            .unwrap();
        assert!(close(h.ng, -Vec3::Z, 0.0));
        assert!((h.uv - Vec2::new(0.5, 0.25)).abs().max_element() < 1e-15);
    }

    #[test]
    fn samples_lie_on_the_shape_with_pdf_one_over_area() {
        let t = Transform::translate(Vec3::new(0.0, 1.0, 0.0)).unwrap()
            * Transform::scale(Vec3::new(2.0, 0.5, 1.0)).unwrap();
        let d = Disk::new(&t, false).unwrap();
        let mut rng = Pcg32::new(5, 2);
        let n = 20_000;
        let mut inner = 0;
        for _ in 0..n {
            let (p, nrm, pdf) = d.sample(rng.next_2d());
            let l = t.inverse_point(p);
            assert!(l.z.abs() < 1e-15 && l.x * l.x + l.y * l.y <= 1.0 + 1e-12);
            assert_eq!(nrm, Vec3::Z);
            assert!((pdf * d.area() - 1.0).abs() < 1e-14);
            if l.x * l.x + l.y * l.y <= 0.25 {
                inner += 1;
            }
        }
        // Uniform: a quarter of the area lies within half the radius.
        let frac = inner as f64 / n as f64;
        assert!((frac - 0.25).abs() < 0.015, "{frac}");
    }

    /// The render kernel's f32 lanes draw the f64 sampler's points and densities to f32
    /// precision, near and far, on an elliptic disk (the reference points rounded to f32
    /// for both, as the kernel's are); reference points on the disk's plane draw nothing
    /// in either.
    #[test]
    fn f32_lanes_draw_the_f64_samples() {
        use facette_bsdf::lanes::F32x8;
        let t = Transform::translate(Vec3::new(0.5, 1.0, -2.0)).unwrap()
            * Transform::rotate(Vec3::new(1.0, 1.0, 0.0), 35.0).unwrap()
            * Transform::scale(Vec3::new(0.8, 0.3, 1.0)).unwrap();
        let tilted = Disk::new(&t, false).unwrap();
        let flat = Disk::new(&Transform::IDENTITY, true).unwrap();
        let mut rng = Pcg32::new(4, 9);
        let mut worst = (0.0f64, 0.0f64);
        let cases = [
            (&tilted, Vec3::new(0.0, 2.0, 1.0)),
            (&tilted, Vec3::new(30.0, -12.0, 25.0)),
            (&flat, Vec3::new(0.3, 0.2, -0.7)),
            (&flat, Vec3::new(3.0, 2.0, 0.0)), // on the plane
        ];
        for (d, p) in cases {
            let p = Vec3::from(p.as_vec3());
            for _ in 0..64 {
                let u: [Vec2; 8] = std::array::from_fn(|_| rng.next_2d());
                let lanes = d.sample_from_lanes(
                    LVec3::<F32x8>::splat(p),
                    F32x8::from_fn(|i| u[i].x as f32 as f64),
                    F32x8::from_fn(|i| u[i].y as f32 as f64),
                );
                for (i, ui) in u.iter().enumerate() {
                    let ui = Vec2::new(ui.x as f32 as f64, ui.y as f32 as f64);
                    let scalar = d.sample_from(p, ui);
                    assert_eq!(lanes.lane(i).is_some(), scalar.is_some(), "{p}");
                    let (Some(a), Some(b)) = (lanes.lane(i), scalar) else {
                        continue;
                    };
                    let dq = (a.point - b.point).length();
                    worst.0 = worst.0.max(dq.max((a.normal - b.normal).length()));
                    worst.1 = worst.1.max((a.pdf / b.pdf - 1.0).abs());
                }
            }
            if p.z == 0.0 {
                assert!((0..8).all(|i| lanes_none(d, p, i)), "on the plane");
            }
        }
        println!(
            "f32 lanes against f64: point/normal {:.1e}, pdf {:.1e}",
            worst.0, worst.1
        );
        assert!(worst.0 < 1e-5 && worst.1 < 1e-4, "{worst:?}");
    }

    fn lanes_none(d: &Disk, p: Vec3, i: usize) -> bool {
        let u = facette_bsdf::lanes::F32x8::splat(0.3 + 0.05 * i as f64);
        d.sample_from_lanes(LVec3::splat(p), u, u).lane(i).is_none()
            && d.sample_from(p, Vec2::splat(0.3 + 0.05 * i as f64))
                .is_none()
    }
}
