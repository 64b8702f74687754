//! Triangle meshes, with Mitsuba 3's conventions (`src/render/mesh.cpp`).
//!
//! | parameter      | meaning                                                          |
//! |----------------|------------------------------------------------------------------|
//! | `positions`    | vertex positions (object space)                                  |
//! | `normals`      | optional per-vertex shading normals                              |
//! | `uvs`          | optional per-vertex texture coordinates                          |
//! | `indices`      | three `u32` per triangle; counter-clockwise seen from the front  |
//! | `to_world`     | transform applied once, when the mesh is built                   |
//! | `flip_normals` | invert geometric and shading normals                             |
//!
//! # Conventions
//! For a hit with barycentrics `(b1, b2)` (weights of the triangle's second and third
//! vertices):
//! - `ng = normalize((p1 − p0) × (p2 − p0))` — the counter-clockwise side is the front;
//! - `ns` = normalized interpolation of the vertex normals when present (falling back to
//!   `ng` where they interpolate to zero), else `ng`; `flip_normals` negates both;
//! - `uv` = interpolated vertex uvs when present, else the barycentrics `(b1, b2)`;
//! - `dpdu`, `dpdv` solve `p1 − p0 = dpdu Δu₁ + dpdv Δv₁`, `p2 − p0 = dpdu Δu₂ + dpdv
//!   Δv₂` from the vertex uvs. Without uvs, or when the uv triangle is degenerate, they
//!   are an arbitrary orthonormal frame around the (unflipped) face normal — Duff et al.'s
//!   construction, which is Mitsuba's `coordinate_system`, so anisotropic materials on
//!   uv-less meshes are oriented as in Mitsuba. (Then the uv derivatives of a ray
//!   differential measure world-space lengths along that frame.)
//!
//! A mirroring `to_world` (negative determinant) reverses the winding of every triangle
//! when the mesh is built, so that the front side stays the side the (transformed)
//! vertex normals point to — pbrt-v4's "transform swaps handedness" rule.
//!
//! Intersection uses the watertight test of [`triangle`](super::triangle); area
//! sampling picks a triangle in proportion to its area (binary search in the cumulative
//! areas) and a uniform point in it.

use super::bounds::Bounds3;
use super::error::{GeometryError, GeometryResult};
use super::interaction::{PrimHit, SurfaceHit};
use super::ray::Ray;
use super::solid_angle_sampling::{
    area_sample_from, area_to_solid_angle, use_spherical_sampling, ShapeSample,
};
use super::spherical_triangle;
use super::transform::Transform;
use super::triangle::TriangleRay;
use super::{Vec2, Vec3};
use facette_bsdf::math::Frame;

#[derive(Clone, Debug, PartialEq)]
pub struct TriangleMesh {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
    triangles: Vec<[u32; 3]>,
    flip_normals: bool,
    /// Cumulative triangle areas; the last entry is the total area.
    area_cdf: Vec<f64>,
}

impl TriangleMesh {
    /// Validates and builds a mesh: attribute counts must match the positions, every
    /// index must name a vertex, every value must be finite, and there must be at least
    /// one triangle. Positions and normals are transformed by `to_world`.
    pub fn new(
        positions: Vec<Vec3>,
        normals: Option<Vec<Vec3>>,
        uvs: Option<Vec<Vec2>>,
        indices: Vec<u32>,
        to_world: &Transform,
        flip_normals: bool,
    ) -> GeometryResult<TriangleMesh> {
        let n = positions.len();
        if n > u32::MAX as usize {
            return Err(GeometryError::TooLarge {
                what: "vertices",
                count: n,
                max: u32::MAX as usize,
            });
        }
        if let Some(ns) = &normals {
            check_count("normal", n, ns.len())?;
        }
        if let Some(uv) = &uvs {
            check_count("uv", n, uv.len())?;
        }
        if indices.len() % 3 != 0 {
            return Err(GeometryError::IndexCountNotTriangles {
                count: indices.len(),
            });
        }
        if indices.is_empty() {
            return Err(GeometryError::NoTriangles);
        }
        if indices.len() / 3 > u32::MAX as usize {
            return Err(GeometryError::TooLarge {
                what: "triangles",
                count: indices.len() / 3,
                max: u32::MAX as usize,
            });
        }
        if let Some(k) = indices.iter().position(|&i| i as usize >= n) {
            return Err(GeometryError::IndexOutOfRange {
                index: indices[k] as i64,
                face: k / 3,
                vertex_count: n,
            });
        }
        check_finite("position", positions.iter().map(|p| p.is_finite()), |i| {
            format!("{}", positions[i])
        })?;
        if let Some(ns) = &normals {
            check_finite("normal", ns.iter().map(|v| v.is_finite()), |i| {
                format!("{}", ns[i])
            })?;
        }
        if let Some(uv) = &uvs {
            check_finite("uv", uv.iter().map(|v| v.is_finite()), |i| {
                format!("{}", uv[i])
            })?;
        }

        let is_identity = *to_world == Transform::IDENTITY;
        let positions: Vec<Vec3> = if is_identity {
            positions
        } else {
            positions.into_iter().map(|p| to_world.point(p)).collect()
        };
        check_finite(
            "transformed position",
            positions.iter().map(|p| p.is_finite()),
            |i| format!("{}", positions[i]),
        )?;
        let normals = normals.map(|ns| {
            ns.into_iter()
                .map(|v| {
                    let t = if is_identity { v } else { to_world.normal(v) };
                    t.normalize_or_zero()
                })
                .collect::<Vec<_>>()
        });
        let swap = to_world.linear_determinant() < 0.0;
        let triangles: Vec<[u32; 3]> = indices
            .chunks_exact(3)
            .map(|c| {
                if swap {
                    [c[0], c[2], c[1]]
                } else {
                    [c[0], c[1], c[2]]
                }
            })
            .collect();

        let mut area_cdf = Vec::with_capacity(triangles.len());
        let mut total = 0.0;
        for t in &triangles {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            total += 0.5 * (b - a).cross(c - a).length();
            area_cdf.push(total);
        }
        Ok(TriangleMesh {
            positions,
            normals,
            uvs,
            triangles,
            flip_normals,
            area_cdf,
        })
    }

    #[inline]
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    #[inline]
    pub fn normals(&self) -> Option<&[Vec3]> {
        self.normals.as_deref()
    }

    #[inline]
    pub fn uvs(&self) -> Option<&[Vec2]> {
        self.uvs.as_deref()
    }

    /// Vertex indices of each triangle (winding as stored, after a mirror swap).
    #[inline]
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    #[inline]
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    #[inline]
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    #[inline]
    pub fn flip_normals(&self) -> bool {
        self.flip_normals
    }

    /// The three vertex positions of triangle `i` (`i < triangle_count()`).
    #[inline]
    pub fn triangle_vertices(&self, i: usize) -> [Vec3; 3] {
        self.triangles[i].map(|k| self.positions[k as usize])
    }

    pub fn triangle_bounds(&self, i: usize) -> Bounds3 {
        let [a, b, c] = self.triangle_vertices(i);
        Bounds3::new(a.min(b).min(c), a.max(b).max(c))
    }

    pub fn bounds(&self) -> Bounds3 {
        Bounds3::from_points(self.positions.iter().copied())
    }

    /// Total surface area.
    #[inline]
    pub fn area(&self) -> f64 {
        self.area_cdf.last().copied().unwrap_or(0.0)
    }

    pub fn triangle_area(&self, i: usize) -> f64 {
        let prev = if i == 0 { 0.0 } else { self.area_cdf[i - 1] };
        self.area_cdf[i] - prev
    }

    /// Hit of triangle `i` in `(0, t_max]` for a ray prepared by [`TriangleRay::new`].
    #[inline]
    pub fn intersect_triangle(&self, i: usize, ray: &TriangleRay, t_max: f64) -> Option<PrimHit> {
        let [a, b, c] = self.triangle_vertices(i);
        ray.intersect(a, b, c, t_max)
    }

    /// The surface details of a hit on triangle `i`.
    pub fn surface_hit(&self, ray: &Ray, i: usize, hit: PrimHit, shape: u32) -> SurfaceHit {
        let idx = self.triangles[i];
        let [p0, p1, p2] = idx.map(|k| self.positions[k as usize]);
        let (b1, b2) = (hit.local.x, hit.local.y);
        let b0 = 1.0 - b1 - b2;
        // Interpolating the vertices (rather than o + t d) bounds the error of p by the
        // vertex magnitudes (Mitsuba does the same).
        let p = b0 * p0 + b1 * p1 + b2 * p2;
        let dp0 = p1 - p0;
        let dp1 = p2 - p0;
        let mut face_n = dp0.cross(dp1).normalize_or_zero();
        if face_n == Vec3::ZERO {
            face_n = -ray.dir;
        }
        let frame = Frame::from_normal(face_n);
        let (uv, dpdu, dpdv) = match &self.uvs {
            Some(uvs) => {
                let [uv0, uv1, uv2] = idx.map(|k| uvs[k as usize]);
                let uv = b0 * uv0 + b1 * uv1 + b2 * uv2;
                let duv0 = uv1 - uv0;
                let duv1 = uv2 - uv0;
                let det = duv0.x * duv1.y - duv0.y * duv1.x;
                let inv = 1.0 / det;
                let dpdu = (duv1.y * dp0 - duv0.y * dp1) * inv;
                let dpdv = (duv0.x * dp1 - duv1.x * dp0) * inv;
                if det != 0.0 && dpdu.is_finite() && dpdv.is_finite() {
                    (uv, dpdu, dpdv)
                } else {
                    (uv, frame.s, frame.t)
                }
            }
            None => (Vec2::new(b1, b2), frame.s, frame.t),
        };
        let ns = match &self.normals {
            Some(ns) => {
                let [n0, n1, n2] = idx.map(|k| ns[k as usize]);
                let n = (b0 * n0 + b1 * n1 + b2 * n2).normalize_or_zero();
                if n == Vec3::ZERO {
                    face_n
                } else {
                    n
                }
            }
            None => face_n,
        };
        let sign = if self.flip_normals { -1.0 } else { 1.0 };
        SurfaceHit {
            t: hit.t,
            p,
            ng: sign * face_n,
            ns: sign * ns,
            uv,
            dpdu,
            dpdv,
            shape,
            prim: i as u32,
        }
    }

    /// Closest hit by testing every triangle (shape index 0): a reference for tests and
    /// tiny meshes; scenes go through the BVH.
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceHit> {
        let tr = TriangleRay::new(ray)?;
        let mut best: Option<(usize, PrimHit)> = None;
        let mut t_max = ray.t_max;
        for i in 0..self.triangles.len() {
            if let Some(h) = self.intersect_triangle(i, &tr, t_max) {
                t_max = h.t;
                best = Some((i, h));
            }
        }
        best.map(|(i, h)| self.surface_hit(ray, i, h, 0))
    }

    /// Uniform sample of the surface: `(point, geometric normal, 1/area)`. The normal is
    /// the geometric one (flipped with `flip_normals`), the same `ng` a ray hitting that
    /// point reports, so one-sided emitters agree between hits and samples. A mesh of
    /// zero area returns pdf 0.
    pub fn sample(&self, u: Vec2) -> (Vec3, Vec3, f64) {
        let total = self.area();
        let Some((i, ux)) = self.select_triangle(u.x) else {
            return (self.positions[0], Vec3::Z, 0.0);
        };
        let [p0, p1, p2] = self.triangle_vertices(i);
        let su = ux.sqrt();
        let b1 = u.y * su;
        let b0 = 1.0 - su;
        let b2 = 1.0 - b0 - b1;
        let p = b0 * p0 + b1 * p1 + b2 * p2;
        (p, self.face_normal(i), 1.0 / total)
    }

    /// A triangle chosen in proportion to its area by binary search in the cumulative
    /// areas (O(log n) per sample), and the fraction of `u` within its interval, uniform
    /// again for the sample inside the triangle. `None` for a mesh of zero area.
    fn select_triangle(&self, u: f64) -> Option<(usize, f64)> {
        let total = self.area();
        if !(total > 0.0) {
            return None;
        }
        let target = u * total;
        let i = self
            .area_cdf
            .partition_point(|&c| c <= target)
            .min(self.triangles.len() - 1);
        let prev = if i == 0 { 0.0 } else { self.area_cdf[i - 1] };
        let a = self.area_cdf[i] - prev;
        let rest = if a > 0.0 {
            ((target - prev) / a).clamp(0.0, 1.0)
        } else {
            0.5
        };
        Some((i, rest))
    }

    /// The geometric normal of triangle `i` as a hit reports it (`flip_normals` applied).
    fn face_normal(&self, i: usize) -> Vec3 {
        let [p0, p1, p2] = self.triangle_vertices(i);
        let n = (p1 - p0).cross(p2 - p0).normalize_or_zero();
        if self.flip_normals {
            -n
        } else {
            n
        }
    }

    /// The solid angle triangle `i` subtends from `p` when spherical-triangle sampling
    /// applies to it, else `None` (area sampling).
    fn spherical_solid_angle(&self, i: usize, p: Vec3) -> Option<f64> {
        let omega = spherical_triangle::solid_angle(p, self.triangle_vertices(i));
        use_spherical_sampling(omega).then_some(omega)
    }

    /// A point seen from `p`: a triangle chosen in proportion to its area, then a
    /// direction uniform in the solid angle it subtends (Arvo 1995), or its area sample
    /// converted to solid angle where spherical sampling does not apply (see
    /// [`solid_angle_sampling`](super::solid_angle_sampling)).
    pub fn sample_from(&self, p: Vec3, u: Vec2) -> Option<ShapeSample> {
        let (i, ux) = self.select_triangle(u.x)?;
        let select = self.triangle_area(i) / self.area();
        let Some(omega) = self.spherical_solid_angle(i, p) else {
            return area_sample_from(p, self.sample(u));
        };
        let s = spherical_triangle::sample(p, self.triangle_vertices(i), Vec2::new(ux, u.y))?;
        Some(ShapeSample {
            point: s.point,
            normal: self.face_normal(i),
            pdf: select / omega,
        })
    }

    /// Density per unit solid angle with which [`sample_from`](Self::sample_from) at `p`
    /// produces the direction towards the point `q` of triangle `i` (normal `nq`).
    pub fn pdf_from(&self, i: usize, p: Vec3, q: Vec3, nq: Vec3) -> f64 {
        let total = self.area();
        if i >= self.triangles.len() || !(total > 0.0) {
            return 0.0;
        }
        match self.spherical_solid_angle(i, p) {
            Some(omega) => self.triangle_area(i) / total / omega,
            None => area_to_solid_angle(1.0 / total, p, q, nq),
        }
    }
}

fn check_count(attribute: &'static str, expected: usize, got: usize) -> GeometryResult<()> {
    if expected == got {
        Ok(())
    } else {
        Err(GeometryError::AttributeCountMismatch {
            attribute,
            expected,
            got,
        })
    }
}

fn check_finite(
    attribute: &'static str,
    mut finite: impl Iterator<Item = bool>,
    value: impl Fn(usize) -> String,
) -> GeometryResult<()> {
    match finite.position(|ok| !ok) {
        None => Ok(()),
        Some(index) => Err(GeometryError::NonFiniteVertex {
            attribute,
            index,
            value: value(index),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use facette_bsdf::math::rng::{Pcg32, RandomSource};

    fn close(a: Vec3, b: Vec3, tol: f64) -> bool {
        (a - b).abs().max_element() <= tol
    }

    /// Two triangles forming the square [0, 2]² in z = 0, uv = (x/2, y/2).
    fn square(normals: bool, uvs: bool, t: &Transform, flip: bool) -> TriangleMesh {
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 2.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        let n = normals.then(|| {
            vec![
                Vec3::new(0.0, 0.0, 1.0),
                Vec3::new(0.0, 0.0, 1.0),
                Vec3::new(0.6, 0.0, 0.8),
                Vec3::new(0.6, 0.0, 0.8),
            ]
        });
        let uv = uvs.then(|| {
            positions
                .iter()
                .map(|p| Vec2::new(p.x / 2.0, p.y / 2.0))
                .collect()
        });
        TriangleMesh::new(positions, n, uv, vec![0, 1, 2, 0, 2, 3], t, flip).unwrap()
    }

    #[test]
    fn hit_with_uvs_and_normals() {
        let m = square(true, true, &Transform::IDENTITY, false);
        assert!((m.area() - 4.0).abs() < 1e-15);
        let h = m
            .intersect(&Ray::infinite(Vec3::new(1.5, 0.5, 1.0), -Vec3::Z))
            .unwrap();
        assert_eq!(h.prim, 0);
        assert!((h.t - 1.0).abs() < 1e-15);
        assert!(close(h.p, Vec3::new(1.5, 0.5, 0.0), 1e-15));
        assert!((h.uv - Vec2::new(0.75, 0.25)).abs().max_element() < 1e-15);
        assert!(close(h.ng, Vec3::Z, 0.0));
        assert!(close(h.dpdu, Vec3::new(2.0, 0.0, 0.0), 1e-15));
        assert!(close(h.dpdv, Vec3::new(0.0, 2.0, 0.0), 1e-15));
        // Shading normal interpolated: b0 = 0.25 (n0), b1 = 0.5 (n1), b2 = 0.25 (n2).
        let expect = (0.75 * Vec3::Z + 0.25 * Vec3::new(0.6, 0.0, 0.8)).normalize();
        assert!(close(h.ns, expect, 1e-15));
        let h2 = m
            .intersect(&Ray::infinite(Vec3::new(0.5, 1.5, 1.0), -Vec3::Z))
            .unwrap();
        assert_eq!(h2.prim, 1);
    }

    #[test]
    fn without_uvs_barycentric_uv_and_mitsuba_frame() {
        let m = square(false, false, &Transform::IDENTITY, false);
        let h = m
            .intersect(&Ray::infinite(Vec3::new(1.5, 0.5, 1.0), -Vec3::Z))
            .unwrap();
        // Triangle (0, 1, 2): p = b1 (2, 0) + b2 (2, 2) → b2 = 0.25, b1 = 0.5.
        assert!((h.uv - Vec2::new(0.5, 0.25)).abs().max_element() < 1e-15);
        let f = Frame::from_normal(Vec3::Z);
        assert_eq!((h.dpdu, h.dpdv), (f.s, f.t));
        assert_eq!(h.ns, h.ng);
    }

    #[test]
    fn degenerate_uvs_fall_back_to_a_frame() {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let uvs = vec![Vec2::ZERO, Vec2::ONE, Vec2::ONE * 2.0];
        let m = TriangleMesh::new(
            positions,
            None,
            Some(uvs),
            vec![0, 1, 2],
            &Transform::IDENTITY,
            false,
        )
        .unwrap();
        let h = m
            .intersect(&Ray::infinite(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z))
            .unwrap();
        assert!(h.dpdu.is_finite() && h.dpdv.is_finite());
        assert!((h.dpdu.length() - 1.0).abs() < 1e-15);
        assert!(h.dpdu.dot(h.ng).abs() < 1e-15);
    }

    #[test]
    fn flip_and_mirror() {
        let m = square(true, false, &Transform::IDENTITY, true);
        let h = m
            .intersect(&Ray::infinite(Vec3::new(1.5, 0.5, 1.0), -Vec3::Z))
            .unwrap();
        assert!(close(h.ng, -Vec3::Z, 0.0));
        assert!(h.ns.z < 0.0);
        // Mirror in z: vertex normals become -z-ish, and the swapped winding keeps ng on
        // their side.
        let mirror = Transform::scale(Vec3::new(1.0, 1.0, -1.0)).unwrap();
        let m = square(true, false, &mirror, false);
        let h = m
            .intersect(&Ray::infinite(Vec3::new(1.5, 0.5, 1.0), -Vec3::Z))
            .unwrap();
        assert!(close(h.ng, -Vec3::Z, 0.0));
        assert!(h.ns.dot(h.ng) > 0.0);
    }

    #[test]
    fn to_world_is_applied_at_load() {
        let t = Transform::translate(Vec3::new(0.0, 0.0, 5.0)).unwrap()
            * Transform::scale(Vec3::new(1.0, 3.0, 1.0)).unwrap();
        let m = square(true, true, &t, false);
        assert!((m.area() - 12.0).abs() < 1e-14);
        let b = m.bounds();
        assert!(close(b.max, Vec3::new(2.0, 6.0, 5.0), 0.0));
        let h = m
            .intersect(&Ray::infinite(Vec3::new(1.5, 1.5, 9.0), -Vec3::Z))
            .unwrap();
        assert!((h.t - 4.0).abs() < 1e-14);
        assert!(close(h.dpdv, Vec3::new(0.0, 6.0, 0.0), 1e-14));
        for n in m.normals().unwrap() {
            assert!((n.length() - 1.0).abs() < 1e-15);
        }
    }

    #[test]
    fn validation_errors() {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let id = Transform::IDENTITY;
        let e = TriangleMesh::new(p.clone(), None, None, vec![0, 1, 3], &id, false).unwrap_err();
        assert!(matches!(
            e,
            GeometryError::IndexOutOfRange {
                index: 3,
                face: 0,
                vertex_count: 3
            }
        ));
        assert!(e.to_string().contains("out of range"), "{e}");
        let e = TriangleMesh::new(p.clone(), None, None, vec![0, 1], &id, false).unwrap_err();
        assert!(matches!(
            e,
            GeometryError::IndexCountNotTriangles { count: 2 }
        ));
        let e = TriangleMesh::new(p.clone(), None, None, vec![], &id, false).unwrap_err();
        assert!(matches!(e, GeometryError::NoTriangles));
        let e = TriangleMesh::new(
            p.clone(),
            Some(vec![Vec3::Z]),
            None,
            vec![0, 1, 2],
            &id,
            false,
        )
        .unwrap_err();
        assert!(matches!(
            e,
            GeometryError::AttributeCountMismatch {
                attribute: "normal",
                ..
            }
        ));
        let mut bad = p.clone();
        bad[1].y = f64::NAN;
        let e = TriangleMesh::new(bad, None, None, vec![0, 1, 2], &id, false).unwrap_err();
        assert!(matches!(
            e,
            GeometryError::NonFiniteVertex {
                attribute: "position",
                index: 1,
                ..
            }
        ));
        let uv = vec![Vec2::ZERO, Vec2::new(f64::INFINITY, 0.0), Vec2::ONE];
        let e = TriangleMesh::new(p, None, Some(uv), vec![0, 1, 2], &id, false).unwrap_err();
        assert!(matches!(
            e,
            GeometryError::NonFiniteVertex {
                attribute: "uv",
                index: 1,
                ..
            }
        ));
    }

    #[test]
    fn samples_lie_on_the_mesh_with_pdf_one_over_area() {
        // Two triangles of different size: samples must split in proportion to area.
        let positions = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(5.0, 0.0, 1.0),
            Vec3::new(8.0, 0.0, 1.0),
            Vec3::new(5.0, 3.0, 1.0),
        ];
        let m = TriangleMesh::new(
            positions,
            None,
            None,
            vec![0, 1, 2, 3, 4, 5],
            &Transform::IDENTITY,
            false,
        )
        .unwrap();
        assert!((m.area() - 5.0).abs() < 1e-14);
        let mut rng = Pcg32::new(9, 0);
        let n = 50_000;
        let mut big = 0;
        for _ in 0..n {
            let (p, nrm, pdf) = m.sample(rng.next_2d());
            assert!((pdf * 5.0 - 1.0).abs() < 1e-14);
            assert!(close(nrm, Vec3::Z, 0.0));
            if p.z == 1.0 {
                big += 1;
                assert!(p.x >= 5.0 && p.y >= 0.0 && (p.x - 5.0) + p.y <= 3.0 + 1e-12);
            } else {
                assert_eq!(p.z, 0.0);
                assert!(p.x >= 0.0 && p.y >= 0.0 && p.x + p.y <= 1.0 + 1e-12);
            }
        }
        let frac = big as f64 / n as f64;
        assert!((frac - 0.9).abs() < 0.01, "{frac}");
    }
}
