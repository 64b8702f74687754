//! The surface interaction: what the integrator learns about a ray's closest hit.

use super::ray::{Ray, RayDifferential};
use super::{Vec2, Vec3};
use facette_bsdf::math::Frame;

/// A ray's hit on a surface.
///
/// - `ng` is the unit geometric normal in the shape's orientation: outward for spheres,
///   +z of the local frame for rectangles and disks, the counter-clockwise winding side
///   for triangles — inverted by `flip_normals`. It does **not** face the ray: the
///   integrator tests `ng · dir` to know which side it hit (one-sided emitters, entering
///   or leaving a dielectric).
/// - `ns` is the unit shading normal (interpolated vertex normals on meshes, else `ng`),
///   flipped together with `ng`.
/// - `uv`, `dpdu`, `dpdv` follow each shape's Mitsuba 3 parameterization (see the shape
///   files). `dpdu`'s direction orients anisotropic materials: see
///   [`shading_frame`](Self::shading_frame).
/// - `shape` is the index in the scene's shape list, `prim` the triangle index within a
///   mesh (0 for analytic shapes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    pub t: f64,
    pub p: Vec3,
    pub ng: Vec3,
    pub ns: Vec3,
    pub uv: Vec2,
    pub dpdu: Vec3,
    pub dpdv: Vec3,
    pub shape: u32,
    pub prim: u32,
}

/// Derivatives are clamped to this magnitude, as pbrt-v4 does, so that a nearly
/// edge-on footprint gives a huge but finite filter width.
const MAX_UV_DERIVATIVE: f64 = 1e8;

impl SurfaceHit {
    /// The shading frame: normal `ns`, first tangent `dpdu` made orthogonal to it
    /// (Gram–Schmidt), second tangent `ns × s`. This is Mitsuba 3's
    /// `SurfaceInteraction::initialize_sh_frame`, so anisotropic roughness (α_u along
    /// `s`) lands as in Mitsuba. A `dpdu` parallel to `ns` falls back to an arbitrary
    /// tangent.
    pub fn shading_frame(&self) -> Frame {
        Frame::from_normal_tangent(self.ns, self.dpdu)
    }

    /// A ray leaving the hit point in direction `dir` (see [`Ray::spawn`]).
    #[inline]
    pub fn spawn_ray(&self, dir: Vec3) -> Ray {
        Ray::spawn(self.p, self.ng, dir)
    }

    /// A shadow ray from the hit point to `target` (see [`Ray::spawn_to`]).
    #[inline]
    pub fn spawn_ray_to(&self, target: Vec3) -> Ray {
        Ray::spawn_to(self.p, self.ng, target)
    }

    /// The offset rays' intersections with the tangent plane at `p`, minus `p`: the
    /// position derivatives (∂p/∂x, ∂p/∂y) across one pixel (pbrt's
    /// `SurfaceInteraction::ComputeDifferentials`). `None` when an offset ray is parallel
    /// to the plane or the result is not finite.
    pub fn position_derivatives(&self, rd: &RayDifferential) -> Option<(Vec3, Vec3)> {
        let n = self.ng;
        let plane = |o: Vec3, d: Vec3| -> Option<Vec3> {
            let denom = n.dot(d);
            if denom == 0.0 {
                return None;
            }
            let t = n.dot(self.p - o) / denom;
            let q = o + t * d;
            q.is_finite().then_some(q - self.p)
        };
        let dpdx = plane(rd.rx_origin, rd.rx_dir)?;
        let dpdy = plane(rd.ry_origin, rd.ry_dir)?;
        Some((dpdx, dpdy))
    }

    /// Screen-space uv derivatives `[du/dx, dv/dx, du/dy, dv/dy]` of a ray differential.
    ///
    /// The offset rays are intersected with the tangent plane, and `dpdx = dpdu·du/dx +
    /// dpdv·dv/dx` (same for y) is solved in the least-squares sense through the 2×2
    /// normal equations (pbrt-v4's `SurfaceInteraction::ComputeDifferentials`), which
    /// stays well-posed for any orientation of the plane. All zeros when the geometry is
    /// degenerate (offset ray parallel to the plane, `dpdu ∥ dpdv`); each value is
    /// clamped to ±1e8.
    pub fn uv_derivatives(&self, rd: &RayDifferential) -> [f64; 4] {
        let Some((dpdx, dpdy)) = self.position_derivatives(rd) else {
            return [0.0; 4];
        };
        let (a, b) = (self.dpdu, self.dpdv);
        let ata00 = a.dot(a);
        let ata01 = a.dot(b);
        let ata11 = b.dot(b);
        let det = ata00 * ata11 - ata01 * ata01;
        // Relative test: dpdu and dpdv nearly parallel (or zero) give no solution.
        if !(det > 1e-24 * ata00 * ata11) || !det.is_finite() {
            return [0.0; 4];
        }
        let inv_det = 1.0 / det;
        let solve = |d: Vec3| -> (f64, f64) {
            let atb0 = a.dot(d);
            let atb1 = b.dot(d);
            let du = (ata11 * atb0 - ata01 * atb1) * inv_det;
            let dv = (ata00 * atb1 - ata01 * atb0) * inv_det;
            (clamp_derivative(du), clamp_derivative(dv))
        };
        let (dudx, dvdx) = solve(dpdx);
        let (dudy, dvdy) = solve(dpdy);
        [dudx, dvdx, dudy, dvdy]
    }
}

#[inline]
fn clamp_derivative(x: f64) -> f64 {
    if x.is_finite() {
        x.clamp(-MAX_UV_DERIVATIVE, MAX_UV_DERIVATIVE)
    } else {
        0.0
    }
}

/// A primitive's hit before the surface details are computed: the distance and the
/// primitive's own coordinates (barycentrics `(b1, b2)` of a triangle, object-space `(x,
/// y)` of a rectangle or disk; unused for spheres). The BVH finds the closest of these,
/// and only that one is turned into a [`SurfaceHit`] (Mitsuba 3's
/// `PreliminaryIntersection`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PrimHit {
    pub t: f64,
    pub local: Vec2,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane_hit(dpdu: Vec3, dpdv: Vec3) -> SurfaceHit {
        SurfaceHit {
            t: 2.0,
            p: Vec3::ZERO,
            ng: Vec3::Z,
            ns: Vec3::Z,
            uv: Vec2::ZERO,
            dpdu,
            dpdv,
            shape: 0,
            prim: 0,
        }
    }

    #[test]
    fn derivatives_of_a_pinhole_footprint_on_a_facing_plane() {
        // Camera at distance 2 above the plane z = 0 looking down; offset rays tilted by
        // 0.01 in x and y hit at 0.02 from the centre. With p = (2u, 3v, 0): du/dx = 0.01.
        let hit = plane_hit(Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 3.0, 0.0));
        let o = Vec3::new(0.0, 0.0, 2.0);
        let rd = RayDifferential {
            rx_origin: o,
            rx_dir: Vec3::new(0.01, 0.0, -1.0),
            ry_origin: o,
            ry_dir: Vec3::new(0.0, 0.01, -1.0),
        };
        let d = hit.uv_derivatives(&rd);
        let expected = [0.02 / 2.0, 0.0, 0.0, 0.02 / 3.0];
        for k in 0..4 {
            assert!((d[k] - expected[k]).abs() < 1e-15, "{d:?}");
        }
    }

    #[test]
    fn degenerate_configurations_give_zeros() {
        let hit = plane_hit(Vec3::X, Vec3::X * 2.0);
        let rd = RayDifferential {
            rx_origin: Vec3::Z,
            rx_dir: -Vec3::Z,
            ry_origin: Vec3::Z,
            ry_dir: -Vec3::Z,
        };
        assert_eq!(hit.uv_derivatives(&rd), [0.0; 4]);
        let hit = plane_hit(Vec3::X, Vec3::Y);
        let parallel = RayDifferential {
            rx_origin: Vec3::Z,
            rx_dir: Vec3::X,
            ry_origin: Vec3::Z,
            ry_dir: -Vec3::Z,
        };
        assert_eq!(hit.uv_derivatives(&parallel), [0.0; 4]);
    }

    #[test]
    fn shading_frame_follows_dpdu() {
        let hit = plane_hit(Vec3::new(1.0, 1.0, 0.5), Vec3::Y);
        let f = hit.shading_frame();
        assert!((f.s - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-15);
        assert!((f.n - Vec3::Z).length() < 1e-15);
    }
}
