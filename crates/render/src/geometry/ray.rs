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
//!
//! The render kernel's f32 lanes (their rays, hit points and normals are f32) take
//! [`RAY_EPSILON_F32`] = 2⁻¹⁷ ≈ 7.6e-6 in place of 2⁻³⁰: 128 ulps of a unit coordinate,
//! about Mitsuba 3's single-precision `RayEpsilon` (89 ulps). The errors it must cover are
//! a few ulps of `max |pᵢ|`: the sphere record's re-projection, a triangle hit computed in
//! f64 and rounded to f32, and the next ray test's rounding of `|o − c|² − r²` (whose true
//! value is `2rδ` for an origin `δ` off a sphere of radius `r`). The tests spawn rays off
//! spheres far from the origin and off large meshes in f32 lanes and find no
//! self-intersection.

use super::Vec3;
use facette_bsdf::lanes::{LVec3, Real};

/// Relative offset of spawned ray origins; see the module documentation.
pub const RAY_EPSILON: f64 = 1.0 / (1u64 << 30) as f64;

/// Relative offset of spawned ray origins in f32 lanes; see the module documentation.
pub const RAY_EPSILON_F32: f64 = 1.0 / (1u64 << 17) as f64;

/// The relative offset for rays in lanes of `R`: [`RAY_EPSILON`] at f64 precision,
/// [`RAY_EPSILON_F32`] below it.
#[inline(always)]
pub fn ray_epsilon<R: Real>() -> f64 {
    if R::DIGITS >= f64::MANTISSA_DIGITS {
        RAY_EPSILON
    } else {
        RAY_EPSILON_F32
    }
}

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
        ShadowEnd::Away(dir).ray::<f64>(p, ng)
    }

    /// A ray from the surface point `p` (geometric normal `ng`) towards the point `target`
    /// (a point light, say), with `t_max` the distance to `target`.
    pub fn spawn_to(p: Vec3, ng: Vec3, target: Vec3) -> Ray {
        ShadowEnd::Point(target).ray::<f64>(p, ng)
    }

    /// A ray between two surface points — a shadow ray to a point sampled on an area
    /// light — with both ends offset (each along its own geometric normal, towards the
    /// other end), so that neither surface occludes the segment (pbrt-v4's `SpawnRayTo`
    /// between two interactions).
    pub fn spawn_between(p: Vec3, ng: Vec3, q: Vec3, nq: Vec3) -> Ray {
        ShadowEnd::Surface { q, nq }.ray::<f64>(p, ng)
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
    offset_origin_by::<f64>(p.into(), ng.into(), dir.into(), RAY_EPSILON).into()
}

/// [`offset_origin`] over lanes, with the offset of the lanes' precision
/// ([`ray_epsilon`]).
#[inline(always)]
pub fn offset_origin_lanes<R: Real>(p: LVec3<R>, ng: LVec3<R>, dir: LVec3<R>) -> LVec3<R> {
    offset_origin_by(p, ng, dir, ray_epsilon::<R>())
}

/// The one source of the spawning rule: `p` moved along `ng` to the side `dir` points to,
/// by `(1 + max|pᵢ|) · epsilon`.
#[inline(always)]
fn offset_origin_by<R: Real>(p: LVec3<R>, ng: LVec3<R>, dir: LVec3<R>, epsilon: f64) -> LVec3<R> {
    let largest = p.x.abs().max(p.y.abs().max(p.z.abs()));
    let mag = (R::one() + largest) * R::splat(epsilon);
    let signed = R::select(ng.dot(dir).ge(R::zero()), mag, -mag);
    p + ng.scale(signed)
}

/// Where a light sample's shadow ray ends; the ray itself is made by
/// [`ray`](Self::ray) with the offset of the precision it is traced at (the scalar
/// integrator's f64, the render kernel's f32 lanes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowEnd {
    /// Nowhere: the ray is unbounded along a unit direction (a distant light, the
    /// environment).
    Away(Vec3),
    /// At a point (a point or spot light).
    Point(Vec3),
    /// At the point `q` of a surface of geometric normal `nq` (an area light), which is
    /// offset towards the shading point too ([`Ray::spawn_between`]).
    Surface { q: Vec3, nq: Vec3 },
}

impl ShadowEnd {
    /// The shadow ray from the surface point `p` (geometric normal `ng`), offset by the
    /// spawning rule of lanes `R` ([`ray_epsilon`]): `ray::<f64>` is what [`Ray::spawn`],
    /// [`Ray::spawn_to`] and [`Ray::spawn_between`] give.
    #[inline]
    pub fn ray<R: Real>(&self, p: Vec3, ng: Vec3) -> Ray {
        let eps = ray_epsilon::<R>();
        let offset = |p: Vec3, n: Vec3, d: Vec3| -> Vec3 {
            offset_origin_by::<f64>(p.into(), n.into(), d.into(), eps).into()
        };
        match *self {
            ShadowEnd::Away(dir) => Ray::new(offset(p, ng, dir), dir, f64::INFINITY),
            ShadowEnd::Point(target) => segment(offset(p, ng, target - p), target),
            ShadowEnd::Surface { q, nq } => segment(offset(p, ng, q - p), offset(q, nq, p - q)),
        }
    }
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
