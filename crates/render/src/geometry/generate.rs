//! Deterministic procedural meshes for tests, benchmarks and the benchmark scene.
//!
//! [`TorusKnot`]: a bumpy tube swept along a (p, q) torus knot — long, self-winding,
//! with detail at every scale, so the BVH faces both large empty regions and dense
//! clusters. Resolution is free: [`TorusKnot::with_triangles`] picks the grid for a
//! target count, and `2 · segments · sides` triangles reach 10k, 100k, 1M or more.
//! Vertex normals (area-weighted face normals) and uvs (`u` along the knot, `v` around
//! the tube) are included; seam vertices are duplicated for continuous uvs but share
//! bit-identical positions, so the surface is closed (watertight under the
//! [`triangle`](super::triangle) test).
//!
//! Everything is computed from the parameters alone, in a fixed order: the same
//! parameters give the same mesh, bit for bit, on every run.

use super::error::GeometryResult;
use super::mesh_data::MeshData;
use super::transform::Transform;
use super::triangle_mesh::TriangleMesh;
use super::{Vec2, Vec3};
use std::f64::consts::TAU;

/// A tube around the torus knot curve
/// `c(t) = ((R + r cos qt) cos pt, (R + r cos qt) sin pt, r sin qt)`, `t ∈ [0, 2π)`,
/// of radius `tube_radius · (1 + bump_amplitude · sin(bump_frequency · t) · sin 5θ)` at
/// angle θ around the tube ([`TorusKnot::radius_at`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorusKnot {
    /// Windings around the torus axis.
    pub p: u32,
    /// Windings through the torus hole.
    pub q: u32,
    /// R: distance from the torus centre to the tube the knot lies on.
    pub major_radius: f64,
    /// r: radius of that torus.
    pub minor_radius: f64,
    /// Radius of the swept tube.
    pub tube_radius: f64,
    /// Relative amplitude of the bumps (0 = smooth tube).
    pub bump_amplitude: f64,
    /// Bumps along the curve.
    pub bump_frequency: u32,
    /// Grid steps along the curve.
    pub segments: u32,
    /// Grid steps around the tube.
    pub sides: u32,
}

impl Default for TorusKnot {
    fn default() -> Self {
        TorusKnot {
            p: 2,
            q: 3,
            major_radius: 1.0,
            minor_radius: 0.4,
            tube_radius: 0.15,
            bump_amplitude: 0.15,
            bump_frequency: 40,
            segments: 200,
            sides: 25,
        }
    }
}

impl TorusKnot {
    /// The default knot at a resolution of at least `triangles` triangles
    /// (`segments = 8 · sides`, which keeps the grid cells near square). 10_000, and
    /// 1_000_000 are reached exactly (25 × 200 and 250 × 2000); 100_000 gives 102_400.
    pub fn with_triangles(triangles: usize) -> TorusKnot {
        let sides = ((triangles as f64 / 16.0).sqrt().ceil() as u32).max(3);
        let mut k = TorusKnot {
            sides,
            segments: 8 * sides,
            ..TorusKnot::default()
        };
        while k.triangle_count() < triangles {
            k.segments += 1;
        }
        k
    }

    #[inline]
    pub fn triangle_count(&self) -> usize {
        2 * self.segments as usize * self.sides as usize
    }

    /// Point of the knot curve at `t`.
    fn curve(&self, t: f64) -> Vec3 {
        let (p, q) = (self.p as f64, self.q as f64);
        let ring = self.major_radius + self.minor_radius * (q * t).cos();
        Vec3::new(
            ring * (p * t).cos(),
            ring * (p * t).sin(),
            self.minor_radius * (q * t).sin(),
        )
    }

    /// Unit tangent of the curve at `t` (analytic derivative).
    fn tangent(&self, t: f64) -> Vec3 {
        let (p, q) = (self.p as f64, self.q as f64);
        let (r_maj, r_min) = (self.major_radius, self.minor_radius);
        let ring = r_maj + r_min * (q * t).cos();
        let dring = -r_min * q * (q * t).sin();
        Vec3::new(
            dring * (p * t).cos() - ring * p * (p * t).sin(),
            dring * (p * t).sin() + ring * p * (p * t).cos(),
            r_min * q * (q * t).cos(),
        )
        .normalize()
    }

    /// Tube radius at curve parameter `t` and angle `theta` around the tube.
    pub fn radius_at(&self, t: f64, theta: f64) -> f64 {
        let f = self.bump_frequency as f64;
        self.tube_radius * (1.0 + self.bump_amplitude * (f * t).sin() * (5.0 * theta).sin())
    }

    /// The mesh arrays (object space).
    pub fn mesh_data(&self) -> MeshData {
        let segs = self.segments.max(3) as usize;
        let sides = self.sides.max(3) as usize;
        // Canonical grid (no seam duplicates): positions and the tube frame.
        let mut grid = Vec::with_capacity(segs * sides);
        for i in 0..segs {
            let t = TAU * i as f64 / segs as f64;
            let c = self.curve(t);
            let tan = self.tangent(t);
            // The frame's normal: the position vector made orthogonal to the tangent.
            // It never vanishes for R > r (the curve stays away from the z axis and
            // winds around it), and it is periodic in t, so the tube closes smoothly.
            let n = (c - tan * c.dot(tan)).normalize();
            let b = tan.cross(n);
            for j in 0..sides {
                let theta = TAU * j as f64 / sides as f64;
                let rho = self.radius_at(t, theta);
                grid.push(c + rho * (theta.cos() * n + theta.sin() * b));
            }
        }
        let g = |i: usize, j: usize| (i % segs) * sides + (j % sides);

        // Area-weighted vertex normals on the canonical grid; winding (a, d, c), (a, c, b)
        // faces outwards for this (tangent, θ) orientation.
        let mut normals = vec![Vec3::ZERO; segs * sides];
        for i in 0..segs {
            for j in 0..sides {
                let (a, b, c, d) = (g(i, j), g(i + 1, j), g(i + 1, j + 1), g(i, j + 1));
                for [x, y, z] in [[a, d, c], [a, c, b]] {
                    let n = (grid[y] - grid[x]).cross(grid[z] - grid[x]);
                    normals[x] += n;
                    normals[y] += n;
                    normals[z] += n;
                }
            }
        }

        // Output vertices: (segs + 1) × (sides + 1), seams copied from the canonical grid.
        let w = sides + 1;
        let mut positions = Vec::with_capacity((segs + 1) * w);
        let mut out_normals = Vec::with_capacity((segs + 1) * w);
        let mut uvs = Vec::with_capacity((segs + 1) * w);
        for i in 0..=segs {
            for j in 0..=sides {
                positions.push(grid[g(i, j)]);
                out_normals.push(normals[g(i, j)].normalize_or_zero());
                uvs.push(Vec2::new(i as f64 / segs as f64, j as f64 / sides as f64));
            }
        }
        let v = |i: usize, j: usize| (i * w + j) as u32;
        let mut indices = Vec::with_capacity(6 * segs * sides);
        for i in 0..segs {
            for j in 0..sides {
                let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
                indices.extend_from_slice(&[a, d, c, a, c, b]);
            }
        }
        MeshData {
            positions,
            normals: Some(out_normals),
            uvs: Some(uvs),
            indices,
        }
    }

    /// The mesh, placed by `to_world`.
    pub fn mesh(&self, to_world: &Transform) -> GeometryResult<TriangleMesh> {
        self.mesh_data().into_mesh(to_world, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::ray::Ray;
    use facette_bsdf::math::rng::{Pcg32, RandomSource};

    #[test]
    fn triangle_counts() {
        assert_eq!(TorusKnot::with_triangles(10_000).triangle_count(), 10_000);
        assert_eq!(
            TorusKnot::with_triangles(1_000_000).triangle_count(),
            1_000_000
        );
        let k = TorusKnot::with_triangles(100_000);
        assert!(k.triangle_count() >= 100_000 && k.triangle_count() < 105_000);
        assert_eq!(
            TorusKnot::with_triangles(10_000)
                .mesh_data()
                .triangle_count(),
            10_000
        );
    }

    #[test]
    fn deterministic_and_outward() {
        let k = TorusKnot::with_triangles(5_000);
        let a = k.mesh_data();
        assert_eq!(a, k.mesh_data());
        let m = k.mesh(&Transform::IDENTITY).unwrap();
        // Face normals agree with vertex normals (outward winding).
        let ns = m.normals().unwrap();
        for (t, tri) in m.triangles().iter().enumerate() {
            let [p0, p1, p2] = m.triangle_vertices(t);
            let ng = (p1 - p0).cross(p2 - p0);
            assert!(
                ng.dot(ns[tri[0] as usize]) > 0.0,
                "triangle {t} faces inwards"
            );
        }
    }

    #[test]
    fn closed_surface_rays_cross_an_even_number_of_times() {
        // From outside the bounds, a ray crosses a closed surface an even number of
        // times: count hits by re-spawning past each one.
        let m = TorusKnot::with_triangles(20_000)
            .mesh(&Transform::IDENTITY)
            .unwrap();
        let mut rng = Pcg32::new(21, 0);
        for _ in 0..200 {
            let target = Vec3::new(
                rng.next_f64() - 0.5,
                rng.next_f64() - 0.5,
                rng.next_f64() * 0.4 - 0.2,
            ) * 2.0;
            let o = Vec3::new(0.3, -0.2, 5.0);
            let mut ray = Ray::infinite(o, target - o);
            let mut crossings = 0;
            while let Some(h) = m.intersect(&ray) {
                crossings += 1;
                ray = h.spawn_ray(ray.dir);
                assert!(crossings < 100);
            }
            assert_eq!(crossings % 2, 0);
        }
    }
}

/// The cube [−1, 1]³ with flat faces (24 vertices with face normals and uvs, 12 triangles,
/// counter-clockwise seen from outside), as Mitsuba 3's `cube` shape.
pub fn cube_mesh_data() -> MeshData {
    let mut data = MeshData {
        normals: Some(Vec::new()),
        uvs: Some(Vec::new()),
        ..Default::default()
    };
    // For each face: its normal and two tangents with t1 × t2 = n.
    let faces = [
        (Vec3::X, Vec3::Y, Vec3::Z),
        (-Vec3::X, Vec3::Z, Vec3::Y),
        (Vec3::Y, Vec3::Z, Vec3::X),
        (-Vec3::Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (-Vec3::Z, Vec3::Y, Vec3::X),
    ];
    for (n, t1, t2) in faces {
        debug_assert!((t1.cross(t2) - n).length() < 1e-12);
        let base = data.positions.len() as u32;
        for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            data.positions.push(n + t1 * a + t2 * b);
            data.normals.as_mut().expect("set").push(n);
            data.uvs
                .as_mut()
                .expect("set")
                .push(Vec2::new(0.5 * (a + 1.0), 0.5 * (b + 1.0)));
        }
        data.indices
            .extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    data
}

#[cfg(test)]
mod cube_tests {
    use super::*;

    #[test]
    fn cube_faces_wind_outward_and_enclose_volume_eight() {
        let d = cube_mesh_data();
        assert_eq!(d.triangle_count(), 12);
        let mut volume = 0.0;
        for t in d.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|k| d.positions[t[k] as usize]);
            let n = (b - a).cross(c - a);
            // Outward: the face normal agrees with the stored vertex normal.
            assert!(n.dot(d.normals.as_ref().unwrap()[t[0] as usize]) > 0.0);
            volume += a.dot(b.cross(c)) / 6.0;
        }
        assert!((volume - 8.0).abs() < 1e-12);
    }
}
