//! Solid angle of a triangle and directions sampled uniformly in it, for next-event
//! estimation towards triangle area lights.
//!
//! # References
//! - A. van Oosterom and J. Strackee, "The Solid Angle of a Plane Triangle", IEEE
//!   Transactions on Biomedical Engineering BME-30(2), 1983: the closed form
//!   `tan(Ω/2) = |a·(b×c)| / (|a||b||c| + (a·b)|c| + (a·c)|b| + (b·c)|a|)`.
//! - J. Arvo, "Stratified Sampling of Spherical Triangles", SIGGRAPH 1995: the
//!   area-preserving map from `[0, 1]²` onto a spherical triangle: `u₁` picks the
//!   sub-triangle `A B C'` (`C'` on the arc `AC`) of area `u₁ Ω`, `u₂` picks a point on the
//!   arc `B C'` so that the density in solid angle is uniform.
//!
//! # Numerics (why the formulas differ from the papers' pseudo-code)
//! Everything is in `f64`, but the textbook forms still lose digits where the solid angle is
//! small (far lights: the three directions nearly coincide) or large (a point close to the
//! light's plane: directions nearly opposite):
//!
//! - Cross products of directions are taken with an edge: `a × b = a × (b − a)`, where
//!   `b − a` is the triangle edge `v₁ − v₀` computed from the vertices themselves, not as a
//!   difference of two long, nearly parallel vectors. The triple product
//!   `a·(b×c) = a·(e₁×e₂)` is then accurate to a few ulps relative, however small it is.
//! - Angles between unit vectors are `2 atan2(|u − v|, |u + v|)`, accurate over `[0, π]`
//!   (`acos` of a dot product loses half the digits near 0 and π).
//! - Arvo solves a cubic-looking expression for `cos b'` and then `sin b' = √(1 − cos²b')`,
//!   which is inaccurate for short arcs. We use the half-angle identity of the spherical
//!   excess, `tan(E/2) = tan(b/2) tan(c/2) sin α / (1 + tan(b/2) tan(c/2) cos α)`, solved
//!   for the side `b'` of the sub-triangle of area `Â`:
//!   `tan(b'/2) = sin(Â/2) / (tan(c/2) sin(α − Â/2))`, evaluated with `atan2`.
//!   `α − Â/2 ∈ (0, π)` for a proper triangle (`β + γ < π + α`); the vertex with the largest
//!   angle is used as `A`, which keeps `α − Â/2` farthest from 0.
//! - The point on the arc `B C'` is at angle `θ` with `1 − cos θ = u₂ (1 − cos φ)`, i.e.
//!   `sin(θ/2) = √u₂ sin(φ/2)`, `sin(φ/2) = |B − C'|/2`: no `1 − cos` cancellation.
//! - The sampled direction is converted to barycentric coordinates (Cramer's rule on the
//!   unnormalized vertex vectors, again with edge cross products), clamped into the
//!   triangle, and the returned point and direction are rebuilt from them: the point lies on
//!   the triangle by construction, and `dir = normalize(point − p)` exactly as returned.
//!
//! The area `Ω` used for sampling and for the pdf is van Oosterom and Strackee's (the sum of
//! the three angles minus π cancels for small triangles).

use super::{Vec2, Vec3};

/// A direction sampled uniformly in the solid angle of a shape.
#[derive(Clone, Copy, Debug)]
pub struct SphericalSample {
    /// Unit direction from the reference point, `normalize(point − p)`.
    pub dir: Vec3,
    /// Where the direction meets the shape (on the shape).
    pub point: Vec3,
    /// Density in solid angle, `1 / Ω`.
    pub pdf: f64,
}

/// The solid angle of the triangle with (unnormalized) vertex vectors `a`, `b`, `c` seen from
/// their common origin, given `det = |a·(b×c)|` computed accurately by the caller (van
/// Oosterom and Strackee 1983). Zero when `det` is not positive; never NaN.
pub(crate) fn van_oosterom(a: Vec3, b: Vec3, c: Vec3, det: f64) -> f64 {
    if !(det > 0.0) || !det.is_finite() {
        return 0.0;
    }
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let denom = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    if !denom.is_finite() {
        return 0.0;
    }
    // atan2 keeps the quadrant: a negative denominator means Ω > π (p close to the plane).
    let omega = 2.0 * det.atan2(denom);
    if omega.is_finite() {
        omega
    } else {
        0.0
    }
}

/// Solid angle subtended by triangle (a, b, c) seen from p (0 for a degenerate triangle or p
/// in its plane).
///
/// Van Oosterom and Strackee's formula (1983), with the triple product taken over the edges
/// (see the module notes) and all vectors divided by the longest one first, so that the
/// cubic terms neither overflow nor underflow at extreme scales.
pub fn solid_angle(p: Vec3, v: [Vec3; 3]) -> f64 {
    let d = [v[0] - p, v[1] - p, v[2] - p];
    let scale = d[0].length().max(d[1].length()).max(d[2].length());
    if !(scale > 0.0) || !scale.is_finite() {
        return 0.0;
    }
    let inv = 1.0 / scale;
    let [a, b, c] = d.map(|x| x * inv);
    let e1 = (v[1] - v[0]) * inv;
    let e2 = (v[2] - v[0]) * inv;
    van_oosterom(a, b, c, a.dot(e1.cross(e2)).abs())
}

/// The angle between two unit vectors, accurate over [0, π].
#[inline]
pub(crate) fn angle_between(u: Vec3, v: Vec3) -> f64 {
    2.0 * (u - v).length().atan2((u + v).length())
}

/// A direction from p toward the triangle, uniform in the solid angle it subtends: (unit
/// direction, the point where it meets the triangle's plane (inside the triangle), pdf =
/// 1 / solid angle). None when the solid angle is 0 / not finite or the construction
/// degenerates.
///
/// Arvo's (1995) map, in the numerically careful form described in the module notes. `u`
/// is clamped to `[0, 1]²`; the map is continuous and area-preserving on the square, so
/// stratified `u` give stratified directions.
pub fn sample(p: Vec3, v: [Vec3; 3], u: Vec2) -> Option<SphericalSample> {
    let omega = solid_angle(p, v);
    if !(omega > 0.0) || !omega.is_finite() {
        return None;
    }
    let pdf = 1.0 / omega;
    if !pdf.is_finite() {
        return None;
    }
    if !u.is_finite() {
        return None;
    }
    let u = u.clamp(Vec2::ZERO, Vec2::ONE);

    // Vertex vectors (unnormalized, for the exact-edge cross products) and directions.
    let d = [v[0] - p, v[1] - p, v[2] - p];
    let dir = [
        d[0].try_normalize()?,
        d[1].try_normalize()?,
        d[2].try_normalize()?,
    ];
    // m[i]: unit normal of the great circle through directions i and i+1, ∝ dᵢ × dᵢ₊₁,
    // computed as dᵢ × (vᵢ₊₁ − vᵢ).
    let m = [
        d[0].cross(v[1] - v[0]).try_normalize()?,
        d[1].cross(v[2] - v[1]).try_normalize()?,
        d[2].cross(v[0] - v[2]).try_normalize()?,
    ];
    // Interior angle at vertex i: between the arcs towards i+1 (normal m[i]) and towards
    // i−1 (normal −m[i−1]); the dihedral angle of the two great-circle planes.
    let angle = [
        angle_between(m[0], -m[2]),
        angle_between(m[1], -m[0]),
        angle_between(m[2], -m[1]),
    ];
    // A = the vertex with the largest angle (see the module notes); B, C follow cyclically.
    let ia = if angle[0] >= angle[1] && angle[0] >= angle[2] {
        0
    } else if angle[1] >= angle[2] {
        1
    } else {
        2
    };
    let (ib, ic) = ((ia + 1) % 3, (ia + 2) % 3);
    let (a, b, c) = (dir[ia], dir[ib], dir[ic]);
    let alpha = angle[ia];

    // Step 1: C' on the arc AC such that the spherical triangle A B C' has area Â = u₁ Ω.
    // tan(b'/2) = sin(Â/2) cos(c/2) / (sin(c/2) sin(α − Â/2)), with sin(c/2) = |A − B|/2 and
    // cos(c/2) = |A + B|/2 (c = arc AB).
    let half_area = 0.5 * u.x * omega;
    let b_full = angle_between(a, c);
    let b_sub = 2.0
        * (half_area.sin() * (a + b).length()).atan2((a - b).length() * (alpha - half_area).sin());
    let b_sub = if b_sub.is_finite() {
        b_sub.clamp(0.0, b_full)
    } else {
        return None;
    };
    // Unit tangent at A towards C: (A × C) × A / |…| = A × m_ca, where m_ca ∝ C × A.
    let t_ac = a.cross(m[ic]).try_normalize()?;
    let (sb, cb) = b_sub.sin_cos();
    let c_sub = (a * cb + t_ac * sb).try_normalize()?;

    // Step 2: the point on the arc B C' at angle θ from B with 1 − cos θ = u₂ (1 − cos φ),
    // φ = arc B C'; in half angles sin(θ/2) = √u₂ · |B − C'|/2.
    let s_half = (u.y.sqrt() * 0.5 * (b - c_sub).length()).min(1.0);
    let theta = 2.0 * s_half.asin();
    let w = if theta > 0.0 {
        // Unit tangent at B towards C': (B × C') × B / |…|.
        let n_bc = b.cross(c_sub).try_normalize()?;
        let t_bc = n_bc.cross(b);
        let (st, ct) = theta.sin_cos();
        b * ct + t_bc * st
    } else {
        b
    };

    // Barycentric coordinates of w: w = Σ λᵢ dᵢ by Cramer's rule, λ₀ ∝ w·(d₁ × d₂) etc.,
    // each cross product again taken with an edge. All λᵢ share the sign of
    // det = d₀·(e₁ × e₂) for w inside the cone; rounding may leave one slightly negative
    // next to an edge, which is clamped. A clearly negative one means the construction
    // failed (a nearly flat configuration): no sample rather than a wrong one.
    let e1 = v[1] - v[0];
    let e2 = v[2] - v[0];
    let det = d[0].dot(e1.cross(e2));
    if !(det != 0.0) || !det.is_finite() {
        return None;
    }
    let sign = det.signum();
    let lam = [
        sign * w.dot(d[1].cross(v[2] - v[1])),
        sign * w.dot(d[2].cross(v[0] - v[2])),
        sign * w.dot(d[0].cross(v[1] - v[0])),
    ];
    let positive: f64 = lam.iter().map(|&l| l.max(0.0)).sum();
    let negative: f64 = lam.iter().map(|&l| (-l).max(0.0)).sum();
    if !(positive > 0.0) || !positive.is_finite() || negative > 1e-6 * positive {
        return None;
    }
    let b1 = lam[1].max(0.0) / positive;
    let b2 = lam[2].max(0.0) / positive;
    let point = v[0] + e1 * b1 + e2 * b2;
    let dir = (point - p).try_normalize()?;
    Some(SphericalSample { dir, point, pdf })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::super::ray::Ray;
    use super::super::triangle::TriangleRay;
    use super::*;
    use facette_bsdf::math::quadrature::GaussLegendre;
    use facette_bsdf::math::rng::{Pcg32, RandomSource};
    use facette_bsdf::validation::{chi2_test, Chi2Config, SphereMap};
    use std::f64::consts::PI;

    /// ∫ f(ω) dω over the directions from `p` through triangle `v`, as
    /// ∫_T f(normalize(x − p)) |n·(x − p)| / |x − p|³ dA: the triangle is split into 4^levels
    /// sub-triangles, each integrated with an n×n Gauss–Legendre rule through Duffy's map
    /// x = v₀ + s (e₁ + t (e₂ − e₁)), dA = s |e₁ × e₂| ds dt.
    pub(crate) fn quad_triangle(
        p: Vec3,
        v: [Vec3; 3],
        levels: u32,
        n: usize,
        f: &impl Fn(Vec3) -> f64,
    ) -> f64 {
        let gl = GaussLegendre::new(n);
        let mut tris = vec![v];
        for _ in 0..levels {
            tris = tris
                .into_iter()
                .flat_map(|[a, b, c]| {
                    let (ab, bc, ca) = ((a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5);
                    [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
                })
                .collect();
        }
        let mut total = 0.0;
        for [a, b, c] in tris {
            let (e1, e2) = (b - a, c - a);
            let nrm = e1.cross(e2);
            let area2 = nrm.length();
            let nrm = nrm / area2;
            total += gl.integrate(0.0, 1.0, |s| {
                gl.integrate(0.0, 1.0, |t| {
                    let x = a + s * (e1 + t * (e2 - e1));
                    let r = x - p;
                    let l = r.length();
                    f(r / l) * nrm.dot(r).abs() / (l * l * l) * s * area2
                })
            });
        }
        total
    }

    /// The direction `d` from `p` hits the triangle (watertight test from `triangle.rs`).
    pub(crate) fn hits(p: Vec3, d: Vec3, v: [Vec3; 3]) -> bool {
        TriangleRay::new(&Ray::infinite(p, d))
            .and_then(|r| r.intersect(v[0], v[1], v[2], f64::INFINITY))
            .is_some()
    }

    /// Asserts `s` is a valid sample of triangle `v` from `p`, with solid angle `omega`.
    fn check_sample(p: Vec3, v: [Vec3; 3], s: &SphericalSample, omega: f64) {
        assert!(s.dir.is_finite() && s.point.is_finite(), "{s:?}");
        assert!((s.dir.length() - 1.0).abs() < 1e-12, "{s:?}");
        let to = s.point - p;
        assert!(
            (s.dir - to / to.length()).length() < 1e-12,
            "dir {:?} vs {:?}",
            s.dir,
            to.normalize()
        );
        assert!(s.pdf.is_finite() && s.pdf > 0.0);
        assert!(
            (s.pdf * omega - 1.0).abs() < 1e-12,
            "{} vs {}",
            s.pdf,
            omega
        );
        // On the triangle: in its plane and with barycentrics in [0, 1], to 1e-9 relative.
        // This measurement goes through the normal e₁ × e₂, whose direction a sliver
        // (|e₁ × e₂| ≪ scale²) only fixes to ~ε scale²/|e₁ × e₂|: the tolerance grows
        // accordingly for slivers (the sampler builds the point as v₀ + b₁e₁ + b₂e₂).
        let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
        let scale = e1.length().max(e2.length());
        let n = e1.cross(e2);
        let tol = 1e-9 * (1e-6 * scale * scale / n.length()).max(1.0);
        let q = s.point - v[0];
        let dist = q.dot(n) / n.length();
        assert!(dist.abs() <= tol * scale, "off plane by {dist}");
        let nn = n.dot(n);
        let b1 = q.cross(e2).dot(n) / nn;
        let b2 = e1.cross(q).dot(n) / nn;
        assert!(
            b1 >= -tol && b2 >= -tol && b1 + b2 <= 1.0 + tol,
            "barycentrics ({b1}, {b2})"
        );
    }

    const OCTANT: [Vec3; 3] = [Vec3::X, Vec3::Y, Vec3::Z];

    fn general_triangle() -> [Vec3; 3] {
        [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.3, 0.8, 0.0),
        ]
    }

    /// (name, p, triangle) used by the chi-square and sample-validity tests.
    fn configurations() -> Vec<(&'static str, Vec3, [Vec3; 3])> {
        let t = general_triangle();
        // A big triangle in a tilted plane, for the "near" case.
        let big = [
            Vec3::new(-1.5, -1.0, 0.2),
            Vec3::new(2.0, -0.8, -0.3),
            Vec3::new(0.1, 2.2, 0.1),
        ];
        vec![
            ("far", Vec3::new(0.4, 0.3, 6.0), t),
            ("near", Vec3::new(0.2, 0.1, 0.5), big),
            ("grazing", Vec3::new(2.5, -1.2, 0.25), t),
            ("near edge", Vec3::new(0.5, -0.03, 0.04), t),
            ("near vertex", Vec3::new(0.31, 0.82, -0.03), t),
        ]
    }

    #[test]
    fn spherical_solid_angle_known_values() {
        assert!((solid_angle(Vec3::ZERO, OCTANT) - PI / 2.0).abs() < 1e-14);
        // Regular tetrahedron: each face subtends π from the centre.
        let tet = [
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(-1.0, -1.0, 1.0),
        ];
        let mut sum = 0.0;
        for skip in 0..4 {
            let f: Vec<Vec3> = (0..4).filter(|&i| i != skip).map(|i| tet[i]).collect();
            let o = solid_angle(Vec3::ZERO, [f[0], f[1], f[2]]);
            assert!((o - PI).abs() < 1e-13, "{o}");
            sum += o;
        }
        assert!((sum - 4.0 * PI).abs() < 1e-12);
        // Independent of orientation, vertex order, and scale.
        let t = general_triangle();
        let p = Vec3::new(0.2, -0.4, 0.7);
        let o = solid_angle(p, t);
        for perm in [[0, 1, 2], [1, 2, 0], [2, 1, 0], [0, 2, 1]] {
            let q = solid_angle(p, [t[perm[0]], t[perm[1]], t[perm[2]]]);
            assert!((q / o - 1.0).abs() < 1e-14, "{q} vs {o}");
        }
        for scale in [1e-6, 1e6, 1e-150, 1e150] {
            let q = solid_angle(p * scale, t.map(|x| x * scale));
            assert!((q / o - 1.0).abs() < 1e-13, "scale {scale}: {q} vs {o}");
        }
        // A very far triangle: Ω ≈ area · cos / r², no cancellation.
        let far = solid_angle(Vec3::new(0.4, 0.3, 1e5), t);
        let approx = 0.4 / 1e10;
        assert!((far / approx - 1.0).abs() < 1e-8, "{far} vs {approx}");
    }

    #[test]
    fn spherical_solid_angle_matches_quadrature() {
        let t = general_triangle();
        for p in [
            Vec3::new(0.4, 0.3, 1.0),
            Vec3::new(0.4, 0.3, -0.3),
            Vec3::new(-1.0, 2.0, 0.5),
            Vec3::new(2.5, -1.2, 0.25),
            Vec3::new(0.4, 0.3, 6.0),
        ] {
            let o = solid_angle(p, t);
            let q = quad_triangle(p, t, 3, 24, &|_| 1.0);
            assert!((o / q - 1.0).abs() < 1e-9, "p {p}: {o} vs quadrature {q}");
        }
        // Seen from a point close to the plane above the interior: close to 2π.
        let p = Vec3::new(0.4, 0.3, 0.02);
        let o = solid_angle(p, t);
        let q = quad_triangle(p, t, 6, 16, &|_| 1.0);
        assert!(o > 5.0 && (o / q - 1.0).abs() < 1e-6, "{o} vs {q}");
    }

    #[test]
    fn spherical_triangle_samples_lie_on_the_triangle() {
        let mut rng = Pcg32::new(11, 3);
        for (name, p, v) in configurations() {
            let omega = solid_angle(p, v);
            for _ in 0..20_000 {
                let s = sample(p, v, rng.next_2d())
                    .unwrap_or_else(|| panic!("{name}: no sample (Ω = {omega})"));
                check_sample(p, v, &s, omega);
            }
        }
    }

    /// A random point: direction uniform on the sphere, distance log-uniform in
    /// [1e-4, 1e4] (both scaled by `scale`).
    pub(crate) fn random_point(rng: &mut Pcg32, scale: f64) -> Vec3 {
        let u = rng.next_2d();
        let z = 1.0 - 2.0 * u.x;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let dist = 10f64.powf(8.0 * rng.next_f64() - 4.0);
        Vec3::new(r * phi.cos(), r * phi.sin(), z) * dist * scale
    }

    #[test]
    fn spherical_triangle_random_configurations() {
        // Random triangles (vertices within a unit ball, some of them thin slivers) seen
        // from points at 1e-4 to 1e4: wherever Ω is in the range the caller uses
        // ([3e-4, 6.22] sr) every u gives a valid sample; elsewhere a valid one or None.
        let mut rng = Pcg32::new(2024, 1);
        let (mut in_range, mut none_outside) = (0, 0);
        for i in 0..40_000 {
            let v = [
                random_point(&mut rng, 1e-4).normalize_or_zero() * rng.next_f64(),
                random_point(&mut rng, 1e-4).normalize_or_zero() * rng.next_f64(),
                random_point(&mut rng, 1e-4).normalize_or_zero() * rng.next_f64(),
            ];
            let mut v = v;
            if i % 4 == 0 {
                // A sliver: the third vertex 1e-3..1e-9 off the line of the other two.
                let t = rng.next_f64();
                let off = 10f64.powf(-3.0 - 6.0 * rng.next_f64());
                v[2] = v[0] + t * (v[1] - v[0]) + random_point(&mut rng, 1e-4).normalize() * off;
            }
            let c = (v[0] + v[1] + v[2]) / 3.0;
            let p = if i % 4 == 1 {
                // Close to the plane, above the triangle or near it: Ω up to ~2π.
                let (b1, b2) = (1.2 * rng.next_f64() - 0.1, 1.2 * rng.next_f64() - 0.1);
                let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero();
                let h = 10f64.powf(-1.0 - 8.0 * rng.next_f64());
                v[0] + b1 * (v[1] - v[0]) + b2 * (v[2] - v[0]) + n * h
            } else {
                c + random_point(&mut rng, 1.0)
            };
            let omega = solid_angle(p, v);
            assert!(omega.is_finite() && (0.0..=2.0 * PI).contains(&omega));
            let usable = (3e-4..=6.22).contains(&omega);
            in_range += usable as usize;
            for _ in 0..4 {
                match sample(p, v, rng.next_2d()) {
                    Some(s) => check_sample(p, v, &s, omega),
                    None => {
                        assert!(!usable, "no sample: p {p}, {v:?}, Ω = {omega}");
                        none_outside += 1;
                    }
                }
            }
        }
        eprintln!(
            "triangle random: {in_range} configurations in range, {none_outside} None outside"
        );
        assert!(in_range > 3000, "{in_range}");
    }

    #[test]
    fn spherical_triangle_chi2() {
        let configs = configurations();
        let significance = 0.01 / configs.len() as f64;
        let mut failures = Vec::new();
        for (name, p, v) in configs {
            let omega = solid_angle(p, v);
            let centroid = (v[0] + v[1] + v[2]) / 3.0;
            let axis = (centroid - p).normalize();
            let radius = v
                .iter()
                .map(|&x| angle_between(axis, (x - p).normalize()))
                .fold(0.0, f64::max);
            let map = SphereMap::new(axis, radius / 3.0);
            let cfg = Chi2Config {
                samples: 500_000,
                seed: 17,
                // The pdf steps from 1/Ω to 0 along the shape's edges, inside many bins.
                // The harness refines a bin where its Simpson rule and the 3-point rule on
                // the same points disagree; with the default 6 intervals a step can slip
                // between the points unseen (near edge: ∫pdf = 0.99993, p = 2e-4 at 500k
                // samples; 10 intervals are worse, 1.0014, as both rules then agree for a
                // step in the second column). 8 intervals give ∫pdf within 3e-6.
                subdivisions: 8,
                ..Default::default()
            };
            let out = chi2_test(
                &map,
                &cfg,
                |rng| sample(p, v, rng.next_2d()).map(|s| s.dir),
                |d| if hits(p, d, v) { 1.0 / omega } else { 0.0 },
            );
            eprintln!(
                "triangle chi2 {name}: Ω = {omega:.4e} sr, {}",
                out.summary()
            );
            if !out.passes(significance) {
                failures.push(format!("{name}: {}", out.summary()));
            }
            assert!(
                (out.pdf_integral - 1.0).abs() < 1e-3,
                "{name}: {}",
                out.summary()
            );
        }
        assert!(failures.is_empty(), "{failures:?}");
    }

    #[test]
    fn spherical_triangle_is_area_preserving() {
        // Ω · mean of f over a 64×64 grid of u ≈ ∫ f dω over the triangle's cone.
        for (name, p, v) in configurations() {
            let omega = solid_angle(p, v);
            let k = Vec3::new(0.3, -0.5, 0.8).normalize();
            let f = |w: Vec3| w.dot(k).exp() + w.x * w.y;
            let reference = quad_triangle(p, v, 6, 16, &f);
            let n = 64;
            let mut sum = 0.0;
            for i in 0..n {
                for j in 0..n {
                    let u = Vec2::new((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                    sum += f(sample(p, v, u).unwrap().dir);
                }
            }
            let estimate = omega * sum / (n * n) as f64;
            let err = (estimate / reference - 1.0).abs();
            eprintln!("triangle grid {name}: relative error {err:.2e}");
            assert!(err < 1e-3, "{name}: {estimate} vs {reference}");
        }
    }

    #[test]
    fn spherical_triangle_degenerate_inputs() {
        let t = general_triangle();
        let u = Vec2::new(0.3, 0.6);
        // Zero-area triangles.
        for v in [
            [Vec3::ZERO, Vec3::X, 2.0 * Vec3::X],
            [Vec3::ZERO, Vec3::X, Vec3::X],
            [Vec3::Y, Vec3::Y, Vec3::Y],
        ] {
            assert_eq!(solid_angle(Vec3::new(0.1, 0.2, 0.3), v), 0.0);
            assert!(sample(Vec3::new(0.1, 0.2, 0.3), v, u).is_none());
        }
        // p in the plane (inside, outside, on an edge) or at a vertex.
        for p in [
            Vec3::new(0.4, 0.3, 0.0),
            Vec3::new(3.0, 3.0, 0.0),
            Vec3::new(0.5, 0.0, 0.0),
            t[0],
            t[1],
            t[2],
        ] {
            assert_eq!(solid_angle(p, t), 0.0, "{p}");
            assert!(sample(p, t, u).is_none(), "{p}");
        }
        // Non-finite input.
        for p in [Vec3::splat(f64::NAN), Vec3::new(f64::INFINITY, 0.0, 1.0)] {
            assert_eq!(solid_angle(p, t), 0.0);
            assert!(sample(p, t, u).is_none());
        }
        assert!(sample(Vec3::Z, t, Vec2::splat(f64::NAN)).is_none());
        // Corners of u, extreme scales, near-plane and very far points: a valid sample or
        // None, never NaN; where a sample exists its direction is scale-invariant.
        let one = 1.0 - f64::EPSILON;
        let corners = [
            Vec2::new(0.0, 0.0),
            Vec2::new(0.0, one),
            Vec2::new(one, 0.0),
            Vec2::new(one, one),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.5, 0.0),
            Vec2::new(0.0, 0.5),
            Vec2::new(-0.5, 2.0),
        ];
        let mut points = configurations()
            .into_iter()
            .map(|(_, p, v)| (p, v))
            .collect::<Vec<_>>();
        points.extend([
            (Vec3::new(0.4, 0.3, 1e-9), t),
            (Vec3::new(0.4, 0.3, 1e-13), t),
            (Vec3::new(0.5, 1e-12, 1e-12), t),
            (Vec3::new(0.4, 0.3, 1e7), t),
            (Vec3::new(1e7, 3e6, 1.0), t),
            (Vec3::new(0.0, 1e-9, 1e-9), t),
        ]);
        let mut some = 0;
        for (p, v) in points {
            let omega = solid_angle(p, v);
            assert!(omega.is_finite() && (0.0..=2.0 * PI).contains(&omega));
            for &uc in &corners {
                let base = sample(p, v, uc);
                if let Some(s) = &base {
                    check_sample(p, v, s, omega);
                    some += 1;
                }
                // Powers of two scale exactly, so the directions must not change; 1e±6 round
                // the inputs, which moves an ill-conditioned configuration (p 1e-9 from a
                // vertex or the plane) by more than the tolerance: validity only.
                for scale in [1e-6, 1e6, 2f64.powi(-20), 2f64.powi(20)] {
                    let vs = v.map(|x| x * scale);
                    let ps = p * scale;
                    if let Some(s) = sample(ps, vs, uc) {
                        check_sample(ps, vs, &s, solid_angle(ps, vs));
                        match &base {
                            Some(b) if scale.log2().fract() == 0.0 => {
                                assert!((s.dir - b.dir).length() < 1e-12, "{p} {uc}")
                            }
                            _ => {}
                        }
                    }
                }
            }
        }
        assert!(some > 60, "{some}");
        // The corners of u map to the vertices A (u₁ = 0) and B (u₂ = 0) of the octant.
        let s = sample(Vec3::ZERO, OCTANT, Vec2::new(0.3, 0.0)).unwrap();
        assert!(OCTANT.iter().any(|&x| (s.point - x).length() < 1e-12));
    }
}
