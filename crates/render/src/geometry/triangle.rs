//! Watertight ray–triangle intersection (Woop, Benthin and Wald, "Watertight Ray/Triangle
//! Intersection", JCGT 2013; the form pbrt-v4 uses in `IntersectTriangle`).
//!
//! # Why this test
//! Möller–Trumbore computes each triangle's edge tests from that triangle's own edge
//! vectors, so a ray through a shared edge can be rejected by both neighbours and slip
//! through a closed mesh. Woop et al. first translate the vertices to the ray origin and
//! shear them so the ray becomes the +z axis; the edge functions are then 2-D cross
//! products of the transformed vertices. A shared edge's function is computed from the
//! same two (bit-identical) transformed vertices in both triangles, only in opposite
//! order, so the two values are exact negatives: a ray is never lost between two
//! triangles (it may be reported by both when it passes exactly through the edge).
//! pbrt re-evaluates zero edge functions in double precision; we already compute in f64
//! and have no wider type, and exactness of the negation is what watertightness needs.
//!
//! The shear depends only on the ray: [`TriangleRay`] precomputes it once per ray, and
//! the BVH passes it to every triangle test.

use super::interaction::PrimHit;
use super::ray::Ray;
use super::{Vec2, Vec3};

/// Per-ray data of the watertight test: the axis permutation that makes the ray's
/// largest direction component z, and the shear coefficients.
#[derive(Clone, Copy, Debug)]
pub struct TriangleRay {
    origin: Vec3,
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f64,
    sy: f64,
    sz: f64,
}

impl TriangleRay {
    /// `None` for a zero or non-finite direction (no triangle can be hit).
    pub fn new(ray: &Ray) -> Option<TriangleRay> {
        let d = ray.dir;
        if !d.is_finite() || d == Vec3::ZERO || !ray.origin.is_finite() {
            return None;
        }
        let a = d.abs();
        let kz = if a.x > a.y && a.x > a.z {
            0
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Keep the winding: a negative major component mirrors the sheared frame.
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        Some(TriangleRay {
            origin: ray.origin,
            kx,
            ky,
            kz,
            sx: d[kx] / d[kz],
            sy: d[ky] / d[kz],
            sz: 1.0 / d[kz],
        })
    }

    /// The hit of triangle `(p0, p1, p2)` in `(0, t_max]`; `local` holds the barycentric
    /// weights `(b1, b2)` of `p1` and `p2` (`p = (1 − b1 − b2) p0 + b1 p1 + b2 p2`,
    /// Mitsuba's `prim_uv`). Degenerate triangles (zero projected area) are never hit.
    #[inline]
    pub fn intersect(&self, p0: Vec3, p1: Vec3, p2: Vec3, t_max: f64) -> Option<PrimHit> {
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        // Arrays: indexing by the permutation is a plain load.
        let a = (p0 - self.origin).to_array();
        let b = (p1 - self.origin).to_array();
        let c = (p2 - self.origin).to_array();
        let ax = a[kx] - self.sx * a[kz];
        let ay = a[ky] - self.sy * a[kz];
        let bx = b[kx] - self.sx * b[kz];
        let by = b[ky] - self.sy * b[kz];
        let cx = c[kx] - self.sx * c[kz];
        let cy = c[ky] - self.sy * c[kz];
        // Edge functions: e0 weighs p0 (edge p1p2), e1 weighs p1, e2 weighs p2.
        let e0 = cx * by - cy * bx;
        let e1 = ax * cy - ay * cx;
        let e2 = bx * ay - by * ax;
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
            return None;
        }
        let det = e0 + e1 + e2;
        if det == 0.0 {
            return None;
        }
        let az = self.sz * a[kz];
        let bz = self.sz * b[kz];
        let cz = self.sz * c[kz];
        let t_scaled = e0 * az + e1 * bz + e2 * cz;
        // t = t_scaled / det must lie in (0, t_max]; compare before dividing.
        if det > 0.0 {
            if !(t_scaled > 0.0 && t_scaled <= t_max * det) {
                return None;
            }
        } else if !(t_scaled < 0.0 && t_scaled >= t_max * det) {
            return None;
        }
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        if !(t > 0.0 && t <= t_max) {
            return None;
        }
        Some(PrimHit {
            t,
            local: Vec2::new(e1 * inv_det, e2 * inv_det),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use facette_bsdf::math::rng::{Pcg32, RandomSource};

    const TRI: [Vec3; 3] = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];

    fn hit(o: Vec3, d: Vec3, t_max: f64) -> Option<PrimHit> {
        let ray = Ray::new(o, d, t_max);
        TriangleRay::new(&ray)?.intersect(TRI[0], TRI[1], TRI[2], ray.t_max)
    }

    #[test]
    fn hit_barycentrics_and_both_sides() {
        let h = hit(Vec3::new(0.25, 0.5, 2.0), -Vec3::Z, f64::INFINITY).unwrap();
        assert!((h.t - 2.0).abs() < 1e-15);
        assert!((h.local - Vec2::new(0.25, 0.5)).abs().max_element() < 1e-15);
        let h = hit(Vec3::new(0.25, 0.5, -2.0), Vec3::Z, f64::INFINITY).unwrap();
        assert!((h.local - Vec2::new(0.25, 0.5)).abs().max_element() < 1e-15);
        // Oblique rays along every major axis.
        let target = Vec3::new(0.2, 0.3, 0.0);
        for d in [
            Vec3::new(3.0, 1.0, -0.5),
            Vec3::new(-1.0, 2.5, 0.7),
            Vec3::new(0.3, -0.2, 1.0),
        ] {
            let h = hit(target - d, d, f64::INFINITY).unwrap();
            assert!((h.t - d.length()).abs() < 1e-14);
            assert!((h.local - Vec2::new(0.2, 0.3)).abs().max_element() < 1e-14);
        }
    }

    #[test]
    fn misses() {
        assert!(hit(Vec3::new(0.6, 0.6, 1.0), -Vec3::Z, f64::INFINITY).is_none());
        assert!(hit(Vec3::new(0.2, 0.2, 1.0), Vec3::Z, f64::INFINITY).is_none());
        assert!(hit(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, 0.99).is_none());
        assert!(hit(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, 1.0).is_some());
        // Grazing at 1e-9 rad: still hit, at the right place.
        let g = hit(
            Vec3::new(-1.0, 0.25, 1e-9),
            Vec3::new(1.0, 0.0, -1e-9),
            f64::INFINITY,
        )
        .unwrap();
        assert!((g.local - Vec2::new(0.0, 0.25)).abs().max_element() < 1e-8);
        // Just outside each edge.
        assert!(hit(Vec3::new(0.5, -1e-12, 1.0), -Vec3::Z, f64::INFINITY).is_none());
        assert!(hit(Vec3::new(-1e-12, 0.5, 1.0), -Vec3::Z, f64::INFINITY).is_none());
        assert!(hit(Vec3::new(0.5 + 1e-12, 0.5, 1.0), -Vec3::Z, f64::INFINITY).is_none());
        assert!(hit(Vec3::new(0.5 - 1e-12, 0.5, 1.0), -Vec3::Z, f64::INFINITY).is_some());
        // In the plane of the triangle.
        assert!(hit(Vec3::new(-1.0, 0.2, 0.0), Vec3::X, f64::INFINITY).is_none());
        // Degenerate triangle.
        let ray = Ray::infinite(Vec3::new(0.5, 0.0, 1.0), -Vec3::Z);
        let tr = TriangleRay::new(&ray).unwrap();
        assert!(tr.intersect(TRI[0], TRI[1], TRI[1] * 2.0, 10.0).is_none());
        assert!(TriangleRay::new(&Ray::infinite(Vec3::ZERO, Vec3::ZERO)).is_none());
    }

    #[test]
    fn shared_edges_are_watertight() {
        // A (planar) parallelogram with awkward coordinates split along its diagonal;
        // rays aimed at points of the shared diagonal must hit at least one of the two
        // triangles. (A folded quad would be a silhouette for some rays: missing both
        // is then correct.)
        let (a, b, c) = (
            Vec3::new(0.1, 0.7, 0.3),
            Vec3::new(1.3, 0.1, -0.2),
            Vec3::new(1.7, 1.9, 0.4),
        );
        let p = [a, b, c, a + (c - b)];
        let mut rng = Pcg32::new(11, 0);
        let mut both = 0;
        for _ in 0..100_000 {
            let s = rng.next_f64();
            let on_edge = p[0] + s * (p[2] - p[0]);
            let o = Vec3::new(
                rng.next_f64() * 4.0 - 2.0,
                rng.next_f64() * 4.0 - 2.0,
                3.0 + rng.next_f64(),
            );
            let ray = Ray::infinite(o, on_edge - o);
            let tr = TriangleRay::new(&ray).unwrap();
            let h1 = tr.intersect(p[0], p[1], p[2], f64::INFINITY);
            let h2 = tr.intersect(p[0], p[2], p[3], f64::INFINITY);
            assert!(h1.is_some() || h2.is_some(), "ray through the edge lost");
            if h1.is_some() && h2.is_some() {
                both += 1;
            }
        }
        assert!(both < 100_000);
    }
}
