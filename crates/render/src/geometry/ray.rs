//! Rays, ray differentials, and spawning rays off a surface without self-intersection.
//!
//! # Spawning rule
//! A ray leaving a surface point `p` must not hit the surface it starts on. The computed
//! hit point carries a rounding error proportional to the magnitude of its coordinates
//! (barycentric interpolation, sphere re-projection: a few ulps of `max |pᵢ|`), so the
//! origin is pushed off along the **geometric** normal, on the side the new ray travels to,
//! by
//!
//! ```text
//! offset = (1 + max(|p.x|, |p.y|, |p.z|)) · RAY_EPSILON,   RAY_EPSILON = 2⁻³⁰ ≈ 9.3e-10
//! ```
//!
//! This is Mitsuba 3's rule (`Interaction::offset_p`: `(1 + max|p|) · RayEpsilon` along
//! `n`, sign of `n·d`); the `1 +` keeps a floor near the origin. Mitsuba's double-precision
//! epsilon is 1500 ulps; we take a much larger 2⁻³⁰ (≈ 8·10⁶ ulps of a unit coordinate):
//! that leaves a wide margin over every error bound of our f64 intersection routines, and
//! is still far below any distance a render can show (a nanometre on a one-metre scene).
//! Intersection routines accept only `t > 0`, so the offset is the only guard — there is
//! no `t_min` to tune.

use super::Vec3;
use facette_bsdf::lanes::{LVec3, Real};

/// Relative offset of spawned ray origins; see the module documentation.
pub const RAY_EPSILON: f64 = 1.0 / (1u64 << 30) as f64;

/// A ray `origin + t·dir`, `0 < t ≤ t_max`. `dir` is a unit vector, so `t` is a distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
    pub t_max: f64,
}

impl Ray {
    /// A ray with `dir` normalized. A zero or non-finite direction gives a zero direction,
    /// which every intersection routine reports as a miss.
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3, t_max: f64) -> Ray {
        Ray {
            origin,
            dir: dir.normalize_or_zero(),
            t_max,
        }
    }

    /// An unbounded ray.
    #[inline]
    pub fn infinite(origin: Vec3, dir: Vec3) -> Ray {
        Ray::new(origin, dir, f64::INFINITY)
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f64) -> Vec3 {
        self.origin + t * self.dir
    }

    /// An unbounded ray leaving the surface point `p` (unit geometric normal `ng`) in
    /// direction `dir`, its origin offset by the spawning rule.
    #[inline]
    pub fn spawn(p: Vec3, ng: Vec3, dir: Vec3) -> Ray {
        Ray::new(offset_origin(p, ng, dir), dir, f64::INFINITY)
    }

    /// A ray from the surface point `p` (geometric normal `ng`) towards the point `target`
    /// (a point light, say), with `t_max` the distance to `target`.
    pub fn spawn_to(p: Vec3, ng: Vec3, target: Vec3) -> Ray {
        let origin = offset_origin(p, ng, target - p);
        segment(origin, target)
    }

    /// A ray between two surface points — a shadow ray to a point sampled on an area
    /// light — with both ends offset (each along its own geometric normal, towards the
    /// other end), so that neither surface occludes the segment (pbrt-v4's `SpawnRayTo`
    /// between two interactions).
    pub fn spawn_between(p: Vec3, ng: Vec3, q: Vec3, nq: Vec3) -> Ray {
        let origin = offset_origin(p, ng, q - p);
        let target = offset_origin(q, nq, p - q);
        segment(origin, target)
    }
}

/// Ray from `origin` to `target` with `t_max` = distance; a zero-length segment gives a
/// zero direction and `t_max = 0` (hits nothing).
fn segment(origin: Vec3, target: Vec3) -> Ray {
    let d = target - origin;
    let len = d.length();
    if len > 0.0 && len.is_finite() {
        Ray {
            origin,
            dir: d / len,
            t_max: len,
        }
    } else {
        Ray {
            origin,
            dir: Vec3::ZERO,
            t_max: 0.0,
        }
    }
}

/// The origin of a ray leaving `p` in direction `dir`: `p` moved along the geometric
/// normal `ng` to the side `dir` points to, by `(1 + max|pᵢ|) · RAY_EPSILON`.
#[inline]
pub fn offset_origin(p: Vec3, ng: Vec3, dir: Vec3) -> Vec3 {
    offset_origin_lanes::<f64>(p.into(), ng.into(), dir.into()).into()
}

/// [`offset_origin`] over lanes, its one source.
#[inline(always)]
pub fn offset_origin_lanes<R: Real>(p: LVec3<R>, ng: LVec3<R>, dir: LVec3<R>) -> LVec3<R> {
    let largest = p.x.abs().max(p.y.abs().max(p.z.abs()));
    let mag = (R::one() + largest) * R::splat(RAY_EPSILON);
    let signed = R::select(ng.dot(dir).ge(R::zero()), mag, -mag);
    p + ng.scale(signed)
}

/// The two auxiliary rays of a camera ray, offset by one pixel in x and in y (pbrt's
/// `RayDifferential`). They are used only to estimate the footprint of a pixel on the
/// surface ([`SurfaceHit::uv_derivatives`](super::SurfaceHit::uv_derivatives)); directions
/// need not be unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayDifferential {
    pub rx_origin: Vec3,
    pub rx_dir: Vec3,
    pub ry_origin: Vec3,
    pub ry_dir: Vec3,
}

impl RayDifferential {
    /// The differentials scaled about the main `ray` by `s` — pbrt's
    /// `ScaleDifferentials`: with `n` samples per pixel, `s = 1/√n` shrinks the footprint
    /// to the area each sample stands for.
    pub fn scaled(&self, ray: &Ray, s: f64) -> RayDifferential {
        RayDifferential {
            rx_origin: ray.origin + (self.rx_origin - ray.origin) * s,
            rx_dir: ray.dir + (self.rx_dir - ray.dir) * s,
            ry_origin: ray.origin + (self.ry_origin - ray.origin) * s,
            ry_dir: ray.dir + (self.ry_dir - ray.dir) * s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn new_normalizes_and_handles_zero() {
        let r = Ray::new(Vec3::ZERO, Vec3::new(0.0, 3.0, 4.0), 10.0);
        assert!((r.dir.length() - 1.0).abs() < 1e-15);
        assert!((r.at(5.0) - Vec3::new(0.0, 3.0, 4.0)).length() < 1e-14);
        let z = Ray::new(Vec3::ZERO, Vec3::ZERO, 1.0);
        assert_eq!(z.dir, Vec3::ZERO);
        let n = Ray::new(Vec3::ZERO, Vec3::new(f64::NAN, 0.0, 1.0), 1.0);
        assert_eq!(n.dir, Vec3::ZERO);
    }

    #[test]
    fn spawn_offsets_to_the_side_of_travel() {
        let p = Vec3::new(100.0, -3.0, 2.0);
        let n = Vec3::Z;
        let up = Ray::spawn(p, n, Vec3::new(1.0, 0.0, 1.0));
        let expected = 101.0 * RAY_EPSILON;
        assert!((up.origin.z - (2.0 + expected)).abs() < 1e-15);
        let down = Ray::spawn(p, n, Vec3::new(1.0, 0.0, -1.0));
        assert!((down.origin.z - (2.0 - expected)).abs() < 1e-15);
        assert_eq!(up.origin.x, 100.0);
    }

    #[test]
    fn spawn_between_stops_before_target() {
        let p = Vec3::ZERO;
        let q = Vec3::new(0.0, 0.0, 2.0);
        let r = Ray::spawn_between(p, Vec3::Z, q, -Vec3::Z);
        assert!(r.origin.z > 0.0);
        assert!(r.at(r.t_max).z < 2.0);
        assert!((r.dir - Vec3::Z).length() < 1e-15);
        let degenerate = Ray::spawn_to(p, Vec3::Z, p + Vec3::Z * RAY_EPSILON);
        assert!(degenerate.t_max >= 0.0);
    }

    #[test]
    fn differentials_scale_about_the_main_ray() {
        let ray = Ray::new(Vec3::ZERO, Vec3::Z, f64::INFINITY);
        let rd = RayDifferential {
            rx_origin: Vec3::X,
            rx_dir: Vec3::new(0.1, 0.0, 1.0),
            ry_origin: Vec3::Y,
            ry_dir: Vec3::new(0.0, 0.1, 1.0),
        };
        let s = rd.scaled(&ray, 0.5);
        assert_eq!(s.rx_origin, Vec3::new(0.5, 0.0, 0.0));
        assert_eq!(s.ry_dir, Vec3::new(0.0, 0.05, 1.0));
    }
}
