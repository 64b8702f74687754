//! Directions sampled uniformly in the solid angle a rectangle subtends, for next-event
//! estimation towards rectangular area lights.
//!
//! # Reference
//! C. Ureña, M. Fajardo and A. King, "An Area-Preserving Parametrization for Spherical
//! Rectangles", Computer Graphics Forum 32(4) (EGSR), 2013.
//!
//! # The parametrization, as derived here
//! In a frame with the rectangle's edges along x and y, the reference point at the origin
//! and the rectangle in the plane z = −h (h > 0, the distance to the plane), the rectangle
//! is `[x₀, x₁] × [y₀, y₁]`. Describe a direction by the angle ψ of the plane through the
//! y axis that contains it (`x = h tan ψ` on the rectangle's plane) and its elevation φ
//! within that plane (`y = d tan φ`, `d = √(x² + h²)`): then `dω = cos φ dψ dφ =
//! dψ d(sin φ)`. So
//!
//! 1. the marginal of ψ is proportional to `sin φ₁(ψ) − sin φ₀(ψ)`, with
//!    `sin φⱼ = yⱼ / √(d² + yⱼ²)`; its integral from ψ₀ is the solid angle `Ω(x)` of the
//!    sub-rectangle `[x₀, x] × [y₀, y₁]`, in closed form
//!    `G(ψ) = asin(kⱼ sin ψ)|ⱼ₌₀¹` with `kⱼ = yⱼ / √(h² + yⱼ²)`;
//! 2. given ψ, sin φ is uniform between `sin φ₀` and `sin φ₁`.
//!
//! Step 1 picks x with `Ω(x) = u₁ Ω`, step 2 picks y: Ureña et al.'s algorithm. Inverting
//! `G(ψ) = T` gives `sin ψ = sin T / √((k₁ − k₀)² + 4 k₀ k₁ sin²(T/2))` (`G` is odd and
//! increasing, so ψ has the sign of T); this is the paper's closed form, written so the
//! denominator does not cancel for small rectangles.
//!
//! # Numerics (why not the paper's pseudo-code verbatim)
//! - The paper (and pbrt-v4) compute the solid angle as the sum of four dihedral angles
//!   minus 2π, and the target `T = u₁ Ω + G(ψ₀)` likewise: both cancel when the rectangle is
//!   small or far (Ω ≪ 1) and `x = h sin ψ / √(1 − sin²ψ)` cancels when p is close to the
//!   plane. Here Ω is van Oosterom and Strackee's formula for the two triangles of the
//!   sub-rectangle (see `spherical_triangle`), accurate to a few ulps relative at any
//!   size, and the closed-form x is only a starting guess: up to four steps of Newton's
//!   method on `Ω(x) − u₁ Ω` (derivative `h/(x² + h²) · (sin φ₁ − sin φ₀)`), kept inside a
//!   shrinking bracket `[x₀, x₁]`, make the sample consistent with the reported Ω to
//!   rounding. One step normally suffices.
//! - Step 2 needs `y = d sin φ / √(1 − sin²φ)`; `1 − sin²φ = (1 − sin φ)(1 + sin φ)`, and
//!   `1 ∓ sin φⱼ` are computed without cancellation (`1 − y/r = d²/(r (r + y))` for y > 0)
//!   and interpolated with the same weights as sin φ (the interpolation is affine).
//! - The point is rebuilt as `s + fₓ ex + f_y ey` with the fractions clamped to [0, 1]: it
//!   lies on the rectangle by construction, and the returned direction is
//!   `normalize(point − p)`.

use super::spherical_triangle::{van_oosterom, SphericalSample};
use super::{Vec2, Vec3};

/// Relative tolerance of [`SphericalRectangle::new`] on `|ex·ey|`.
const ORTHOGONALITY_TOLERANCE: f64 = 1e-6;
/// p closer to the plane than this times the configuration's size counts as in it.
const PLANE_TOLERANCE: f64 = 1e-9;

/// The spherical rectangle that a rectangle (corner `s`, orthogonal edge vectors `ex`,
/// `ey`) subtends from `p`.
#[derive(Clone, Copy, Debug)]
pub struct SphericalRectangle {
    p: Vec3,
    s: Vec3,
    ex: Vec3,
    ey: Vec3,
    /// Edge lengths.
    lx: f64,
    ly: f64,
    /// Distance from p to the plane (> 0).
    h: f64,
    /// The rectangle in the local frame: `[x0, x0 + lx] × [y0, y0 + ly]` at z = −h.
    x0: f64,
    y0: f64,
    solid_angle: f64,
}

/// Solid angle of `[x0, x1] × [y0, y1]` in the plane z = −h seen from the origin: van
/// Oosterom and Strackee for its two triangles, whose triple products are both
/// `h (x1 − x0)(y1 − y0)` exactly. Inputs are pre-scaled by the caller.
fn local_solid_angle(h: f64, x0: f64, x1: f64, y0: f64, y1: f64) -> f64 {
    let det = h * (x1 - x0) * (y1 - y0);
    let v00 = Vec3::new(x0, y0, -h);
    let v10 = Vec3::new(x1, y0, -h);
    let v11 = Vec3::new(x1, y1, -h);
    let v01 = Vec3::new(x0, y1, -h);
    van_oosterom(v00, v10, v11, det) + van_oosterom(v00, v11, v01, det)
}

/// `(sin φ, 1 − sin φ, 1 + sin φ)` for `sin φ = y / √(d² + y²)`, the last two without
/// cancellation.
#[inline]
fn sine_and_complements(y: f64, d2: f64) -> (f64, f64, f64) {
    let r = (d2 + y * y).sqrt();
    let k = y / r;
    if y > 0.0 {
        (k, d2 / (r * (r + y)), 1.0 + k)
    } else {
        (k, 1.0 - k, d2 / (r * (r - y)))
    }
}

impl SphericalRectangle {
    /// None if p lies in the rectangle's plane (within a relative tolerance), or the edges
    /// are not orthogonal (|ex·ey| > 1e-6 |ex||ey|: the caller then falls back to area
    /// sampling), or degenerate.
    pub fn new(p: Vec3, s: Vec3, ex: Vec3, ey: Vec3) -> Option<SphericalRectangle> {
        let (lx, ly) = (ex.length(), ey.length());
        if !(lx > 0.0) || !(ly > 0.0) || !lx.is_finite() || !ly.is_finite() {
            return None;
        }
        if !p.is_finite() || !s.is_finite() {
            return None;
        }
        if !(ex.dot(ey).abs() <= ORTHOGONALITY_TOLERANCE * lx * ly) {
            return None;
        }
        // Orthonormal frame: x along ex, y along ey made exactly orthogonal (it differs from
        // ey's direction by at most 1e-6 rad), z their cross product.
        let xa = ex / lx;
        let ya = (ey - xa * xa.dot(ey)).try_normalize()?;
        let za = xa.cross(ya);
        let d = s - p;
        let (x0, y0, z0) = (d.dot(xa), d.dot(ya), d.dot(za));
        // Which side of the plane p is on does not matter: only the distance h enters (the
        // configuration mirrored through the plane subtends the same directions, mirrored).
        let h = z0.abs();
        let size = d.length().max(lx).max(ly);
        if !(h > PLANE_TOLERANCE * size) || !size.is_finite() {
            return None;
        }
        let rect = SphericalRectangle {
            p,
            s,
            ex,
            ey,
            lx,
            ly,
            h,
            x0,
            y0,
            solid_angle: 0.0,
        };
        let omega = rect.partial_solid_angle(x0 + lx);
        if !(omega > 0.0) || !omega.is_finite() || !(1.0 / omega).is_finite() {
            return None;
        }
        Some(SphericalRectangle {
            solid_angle: omega,
            ..rect
        })
    }

    /// Solid angle of the sub-rectangle `[x0, x] × [y0, y1]`.
    fn partial_solid_angle(&self, x: f64) -> f64 {
        let (x0, y0, y1, h) = (self.x0, self.y0, self.y0 + self.ly, self.h);
        // Scaled by the largest coordinate so the cubic terms stay in range.
        let m = x0.abs().max(x.abs()).max(y0.abs()).max(y1.abs()).max(h);
        let inv = 1.0 / m;
        local_solid_angle(h * inv, x0 * inv, x * inv, y0 * inv, y1 * inv)
    }

    pub fn solid_angle(&self) -> f64 {
        self.solid_angle
    }

    /// Uniform in solid angle: the sampled point on the rectangle (and the unit direction,
    /// pdf = 1/solid angle). `u` is clamped to `[0, 1]²`; `u₁` moves along `ex`, `u₂` along
    /// `ey`, and `u = (0, 0)` maps to the corner `s`.
    pub fn sample(&self, u: Vec2) -> Option<SphericalSample> {
        if !u.is_finite() {
            return None;
        }
        let u = u.clamp(Vec2::ZERO, Vec2::ONE);
        let (h, x0, y0) = (self.h, self.x0, self.y0);
        let (x1, y1) = (x0 + self.lx, y0 + self.ly);
        let target = u.x * self.solid_angle;

        // Step 1: x with Ω(x) = target. Closed-form start (module notes).
        let x = if u.x <= 0.0 {
            x0
        } else if u.x >= 1.0 {
            x1
        } else {
            let k0 = y0 / (h * h + y0 * y0).sqrt();
            let k1 = y1 / (h * h + y1 * y1).sqrt();
            let g = |sin_psi: f64| (k1 * sin_psi).asin() - (k0 * sin_psi).asin();
            let t = g(x0 / (x0 * x0 + h * h).sqrt()) + target;
            let sh = (0.5 * t).sin();
            let sin_psi = t.sin() / ((k1 - k0) * (k1 - k0) + 4.0 * k0 * k1 * sh * sh).sqrt();
            let guess = if sin_psi.is_finite() {
                let sin_psi = sin_psi.clamp(-1.0, 1.0);
                h * sin_psi / ((1.0 - sin_psi) * (1.0 + sin_psi)).sqrt()
            } else {
                f64::NAN
            };
            let mut x = if guess.is_nan() {
                0.5 * (x0 + x1)
            } else {
                guess.clamp(x0, x1)
            };
            // Newton on Ω(x) − target, bracketed. A step below the resolution of x (the
            // residual is then rounding noise) ends the iteration where it is: bisecting
            // on such noise would throw a converged x away.
            let (mut lo, mut hi) = (x0, x1);
            let tol = 16.0 * f64::EPSILON * (x0.abs() + x1.abs());
            for _ in 0..4 {
                let r = self.partial_solid_angle(x) - target;
                if r == 0.0 {
                    break;
                }
                if r > 0.0 {
                    hi = x;
                } else {
                    lo = x;
                }
                let d2 = x * x + h * h;
                let (s1, _, _) = sine_and_complements(y1, d2);
                let (s0, _, _) = sine_and_complements(y0, d2);
                let step = r / (h / d2 * (s1 - s0));
                let next = x - step;
                if step.abs() <= tol {
                    if next >= x0 && next <= x1 {
                        x = next;
                    }
                    break;
                }
                x = if next.is_finite() && next > lo && next < hi {
                    next
                } else {
                    0.5 * (lo + hi)
                };
            }
            x
        };

        // Step 2: sin φ uniform between sin φ₀ and sin φ₁ at this x.
        let d2 = x * x + h * h;
        let (k0, om0, op0) = sine_and_complements(y0, d2);
        let (k1, om1, op1) = sine_and_complements(y1, d2);
        let lerp = |a: f64, b: f64| a + u.y * (b - a);
        let sin_phi = lerp(k0, k1);
        let cos2_phi = lerp(om0, om1) * lerp(op0, op1);
        let y = if u.y <= 0.0 {
            y0
        } else if u.y >= 1.0 {
            y1
        } else if cos2_phi > 0.0 {
            sin_phi * d2.sqrt() / cos2_phi.sqrt()
        } else if sin_phi > 0.0 {
            y1
        } else {
            y0
        };
        if !x.is_finite() || !y.is_finite() {
            return None;
        }

        let fx = ((x - x0) / self.lx).clamp(0.0, 1.0);
        let fy = ((y - y0) / self.ly).clamp(0.0, 1.0);
        let point = self.s + self.ex * fx + self.ey * fy;
        let dir = (point - self.p).try_normalize()?;
        Some(SphericalSample {
            dir,
            point,
            pdf: 1.0 / self.solid_angle,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::spherical_triangle::{
        self,
        tests::{hits, random_point},
    };
    use super::*;
    use facette_bsdf::math::quadrature::GaussLegendre;
    use facette_bsdf::math::rng::{Pcg32, RandomSource};
    use facette_bsdf::validation::{chi2_test, Chi2Config, SphereMap};
    use std::f64::consts::PI;

    /// A rectangle: corner and edges.
    #[derive(Clone, Copy, Debug)]
    struct Rect {
        s: Vec3,
        ex: Vec3,
        ey: Vec3,
    }

    impl Rect {
        fn triangles(&self) -> [[Vec3; 3]; 2] {
            let (a, b, c, d) = (
                self.s,
                self.s + self.ex,
                self.s + self.ex + self.ey,
                self.s + self.ey,
            );
            [[a, b, c], [a, c, d]]
        }
        fn triangle_solid_angle(&self, p: Vec3) -> f64 {
            let [t0, t1] = self.triangles();
            spherical_triangle::solid_angle(p, t0) + spherical_triangle::solid_angle(p, t1)
        }
        /// The ray hits one of the two triangles (watertight across the diagonal).
        fn hits(&self, p: Vec3, d: Vec3) -> bool {
            let [t0, t1] = self.triangles();
            hits(p, d, t0) || hits(p, d, t1)
        }
        fn spherical(&self, p: Vec3) -> Option<SphericalRectangle> {
            SphericalRectangle::new(p, self.s, self.ex, self.ey)
        }
    }

    /// ∫ f(ω) dω over the rectangle's cone from p, by n×n Gauss–Legendre on each of m×m
    /// panels of the rectangle (integrand f · |n·r| / |r|³ dA).
    fn quad_rect(r: &Rect, p: Vec3, m: usize, n: usize, f: &impl Fn(Vec3) -> f64) -> f64 {
        let gl = GaussLegendre::new(n);
        let nrm = r.ex.cross(r.ey);
        let area = nrm.length();
        let nrm = nrm / area;
        let mut total = 0.0;
        for i in 0..m {
            for j in 0..m {
                let (a0, a1) = (i as f64 / m as f64, (i + 1) as f64 / m as f64);
                let (b0, b1) = (j as f64 / m as f64, (j + 1) as f64 / m as f64);
                total += gl.integrate(a0, a1, |a| {
                    gl.integrate(b0, b1, |b| {
                        let x = r.s + a * r.ex + b * r.ey;
                        let d = x - p;
                        let l = d.length();
                        f(d / l) * nrm.dot(d).abs() / (l * l * l)
                    })
                });
            }
        }
        total * area
    }

    /// A rotation, so the rectangle's frame is not the world's.
    fn rotate(v: Vec3) -> Vec3 {
        let q = glam::DQuat::from_axis_angle(Vec3::new(1.0, 2.0, -0.5).normalize(), 0.9);
        q * v
    }

    fn unit_rect() -> Rect {
        Rect {
            s: rotate(Vec3::new(-1.0, -0.5, 0.0)) + Vec3::new(0.3, -0.2, 0.5),
            ex: rotate(Vec3::new(2.0, 0.0, 0.0)),
            ey: rotate(Vec3::new(0.0, 1.0, 0.0)),
        }
    }

    /// A point given in the rectangle's (unrotated) frame of `unit_rect`.
    fn at(local: Vec3) -> Vec3 {
        rotate(local) + Vec3::new(0.3, -0.2, 0.5)
    }

    fn configurations() -> Vec<(&'static str, Vec3, Rect)> {
        let r = unit_rect();
        vec![
            ("far", at(Vec3::new(0.2, 0.1, 12.0)), r),
            // On the side opposite to the normal ex × ey.
            ("near (below)", at(Vec3::new(0.3, -0.1, -0.25)), r),
            ("grazing", at(Vec3::new(3.0, 1.5, 0.3)), r),
            ("near edge", at(Vec3::new(0.2, -0.53, 0.03)), r),
            ("near corner", at(Vec3::new(0.98, 0.52, 0.02)), r),
        ]
    }

    fn check_sample(r: &Rect, p: Vec3, s: &SphericalSample, omega: f64) {
        assert!(s.dir.is_finite() && s.point.is_finite(), "{s:?}");
        assert!((s.dir.length() - 1.0).abs() < 1e-12);
        let to = s.point - p;
        assert!((s.dir - to / to.length()).length() < 1e-12, "{s:?}");
        assert!(s.pdf.is_finite() && s.pdf > 0.0);
        assert!((s.pdf * omega - 1.0).abs() < 1e-12);
        // Coordinates along the (possibly slightly skewed) edges: least squares through
        // the Gram matrix.
        let q = s.point - r.s;
        let (gxx, gxy, gyy) = (r.ex.dot(r.ex), r.ex.dot(r.ey), r.ey.dot(r.ey));
        let (qx, qy) = (q.dot(r.ex), q.dot(r.ey));
        let g = gxx * gyy - gxy * gxy;
        let (fx, fy) = ((qx * gyy - qy * gxy) / g, (qy * gxx - qx * gxy) / g);
        let scale = gxx.sqrt().max(gyy.sqrt());
        let off = (q - fx * r.ex - fy * r.ey).length();
        let tol = 1e-9;
        assert!(off <= tol * scale, "off plane by {off}");
        assert!(
            (-tol..=1.0 + tol).contains(&fx) && (-tol..=1.0 + tol).contains(&fy),
            "({fx}, {fy})"
        );
    }

    #[test]
    fn spherical_rectangle_solid_angle() {
        // The square [−1, 1]² seen from height 1 above its centre: a cube face, 4π/6.
        let sq = Rect {
            s: Vec3::new(-1.0, -1.0, 0.0),
            ex: Vec3::new(2.0, 0.0, 0.0),
            ey: Vec3::new(0.0, 2.0, 0.0),
        };
        let o = sq.spherical(Vec3::Z).unwrap().solid_angle();
        assert!((o - 2.0 * PI / 3.0).abs() < 1e-14, "{o}");
        let o = sq.spherical(-Vec3::Z).unwrap().solid_angle();
        assert!((o - 2.0 * PI / 3.0).abs() < 1e-14, "{o}");
        // Sum of its two triangles; quadrature; all configurations and a few more.
        let mut cases = configurations();
        cases.push(("very far", at(Vec3::new(0.2, 0.1, 1e4)), unit_rect()));
        cases.push(("far side", at(Vec3::new(300.0, -200.0, 1.0)), unit_rect()));
        cases.push(("close", at(Vec3::new(0.1, 0.1, 1e-3)), unit_rect()));
        for (name, p, r) in cases {
            let o = r.spherical(p).unwrap().solid_angle();
            let t = r.triangle_solid_angle(p);
            assert!((o / t - 1.0).abs() < 1e-12, "{name}: {o} vs {t}");
            if !name.contains("close") && !name.contains("near") {
                let q = quad_rect(&r, p, 4, 24, &|_| 1.0);
                assert!((o / q - 1.0).abs() < 1e-9, "{name}: {o} vs quadrature {q}");
            }
        }
        // Quadrature near the plane needs panels.
        let (_, p, r) = &configurations()[1];
        let o = r.spherical(*p).unwrap().solid_angle();
        let q = quad_rect(r, *p, 32, 16, &|_| 1.0);
        assert!((o / q - 1.0).abs() < 1e-6, "{o} vs {q}");
    }

    #[test]
    fn spherical_rectangle_samples_lie_on_the_rectangle() {
        let mut rng = Pcg32::new(5, 9);
        for (name, p, r) in configurations() {
            let sr = r.spherical(p).unwrap();
            for _ in 0..20_000 {
                let s = sr
                    .sample(rng.next_2d())
                    .unwrap_or_else(|| panic!("{name}: no sample"));
                check_sample(&r, p, &s, r.triangle_solid_angle(p));
            }
        }
    }

    #[test]
    fn spherical_rectangle_random_configurations() {
        // Random rectangles (any orientation, aspect ratios up to 1e4) seen from points at
        // 1e-4 to 1e4, or just above the plane: where Ω is in the range the caller uses
        // ([3e-4, 6.22] sr) every u gives a valid sample; elsewhere a valid one or None.
        let mut rng = Pcg32::new(77, 2);
        let (mut in_range, mut none) = (0, 0);
        for i in 0..40_000 {
            let ax = random_point(&mut rng, 1.0).normalize();
            let other = random_point(&mut rng, 1.0).normalize();
            let ay = (other - ax * ax.dot(other)).normalize();
            let (lx, ly) = (
                10f64.powf(-2.0 * rng.next_f64()),
                10f64.powf(-2.0 * rng.next_f64()),
            );
            let r = Rect {
                s: random_point(&mut rng, 1e-4),
                ex: ax * lx,
                ey: ay * ly,
            };
            let p = if i % 4 == 1 {
                let (fx, fy) = (1.2 * rng.next_f64() - 0.1, 1.2 * rng.next_f64() - 0.1);
                let h = 10f64.powf(-1.0 - 7.0 * rng.next_f64());
                r.s + fx * r.ex + fy * r.ey + ax.cross(ay) * h * (rng.next_f64() - 0.5).signum()
            } else {
                r.s + 0.5 * (r.ex + r.ey) + random_point(&mut rng, 1.0)
            };
            let Some(sr) = r.spherical(p) else {
                none += 1;
                continue;
            };
            let omega = sr.solid_angle();
            assert!(omega.is_finite() && omega > 0.0 && omega <= 2.0 * PI);
            // Both are ill-conditioned near the plane and far away (relative error
            // ~ ε·distance/height and ε·distance/size; the two world triangles are not even
            // coplanar once their corners are rounded).
            let tri = r.triangle_solid_angle(p);
            let height = (p - r.s).dot(ax.cross(ay)).abs();
            let dist = (p - r.s).length();
            let tol = 1e-12 * (1.0 + dist / height + dist / lx.min(ly));
            assert!(
                (omega / tri - 1.0).abs() < tol,
                "{omega} vs {tri}, {p} {r:?}"
            );
            let usable = (3e-4..=6.22).contains(&omega);
            in_range += usable as usize;
            for _ in 0..4 {
                match sr.sample(rng.next_2d()) {
                    Some(s) => check_sample(&r, p, &s, omega),
                    None => {
                        assert!(!usable, "no sample: p {p}, {r:?}, Ω = {omega}");
                        none += 1;
                    }
                }
            }
        }
        eprintln!("rectangle random: {in_range} configurations in range, {none} None");
        assert!(in_range > 5000, "{in_range}");
    }

    #[test]
    fn spherical_rectangle_chi2() {
        let configs = configurations();
        let significance = 0.01 / configs.len() as f64;
        let mut failures = Vec::new();
        for (name, p, r) in configs {
            let sr = r.spherical(p).unwrap();
            let omega = sr.solid_angle();
            let centre = r.s + 0.5 * (r.ex + r.ey);
            let axis = (centre - p).normalize();
            let radius = [r.s, r.s + r.ex, r.s + r.ey, r.s + r.ex + r.ey]
                .iter()
                .map(|&x| spherical_triangle::angle_between(axis, (x - p).normalize()))
                .fold(0.0, f64::max);
            let cfg = Chi2Config {
                samples: 500_000,
                seed: 23,
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
                &SphereMap::new(axis, radius / 3.0),
                &cfg,
                |rng| sr.sample(rng.next_2d()).map(|s| s.dir),
                |d| if r.hits(p, d) { 1.0 / omega } else { 0.0 },
            );
            eprintln!(
                "rectangle chi2 {name}: Ω = {omega:.4e} sr, {}",
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
    fn spherical_rectangle_is_area_preserving() {
        for (name, p, r) in configurations() {
            let sr = r.spherical(p).unwrap();
            let k = Vec3::new(-0.4, 0.2, 0.9).normalize();
            let f = |w: Vec3| w.dot(k).exp() + w.x * w.y;
            let reference = quad_rect(&r, p, 32, 16, &f);
            let n = 64;
            let mut sum = 0.0;
            for i in 0..n {
                for j in 0..n {
                    let u = Vec2::new((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                    sum += f(sr.sample(u).unwrap().dir);
                }
            }
            let estimate = sr.solid_angle() * sum / (n * n) as f64;
            let err = (estimate / reference - 1.0).abs();
            eprintln!("rectangle grid {name}: relative error {err:.2e}");
            assert!(err < 1e-3, "{name}: {estimate} vs {reference}");
        }
    }

    #[test]
    fn spherical_rectangle_degenerate_inputs() {
        let r = unit_rect();
        // p in the plane (inside, outside, on an edge, at a corner).
        for local in [
            Vec3::new(0.1, 0.1, 0.0),
            Vec3::new(5.0, 0.1, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(-1.0, -0.5, 0.0),
        ] {
            assert!(r.spherical(at(local)).is_none(), "{local}");
        }
        // Non-orthogonal, zero or non-finite edges, non-finite p.
        let p = at(Vec3::new(0.0, 0.0, 1.0));
        let skew = Rect {
            ey: r.ey + 1e-3 * r.ex,
            ..r
        };
        assert!(skew.spherical(p).is_none());
        let slight = Rect {
            ey: r.ey + 1e-8 * r.ex,
            ..r
        };
        let sr = slight.spherical(p).unwrap();
        let s = sr.sample(Vec2::new(0.3, 0.7)).unwrap();
        check_sample(&slight, p, &s, sr.solid_angle());
        for bad in [
            Rect {
                ex: Vec3::ZERO,
                ..r
            },
            Rect {
                ey: Vec3::ZERO,
                ..r
            },
            Rect {
                ex: Vec3::splat(f64::NAN),
                ..r
            },
            Rect {
                s: Vec3::splat(f64::INFINITY),
                ..r
            },
        ] {
            assert!(bad.spherical(p).is_none());
        }
        assert!(r.spherical(Vec3::splat(f64::NAN)).is_none());
        assert!(r
            .spherical(p)
            .unwrap()
            .sample(Vec2::splat(f64::NAN))
            .is_none());

        // Corners of u, extreme scales, points near the plane and very far: valid samples
        // (or None), directions independent of the scale.
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
        let mut points: Vec<(Vec3, Rect)> = configurations()
            .into_iter()
            .map(|(_, p, r)| (p, r))
            .collect();
        points.extend(
            [
                Vec3::new(0.1, 0.1, 1e-8),
                Vec3::new(0.1, 0.1, -1e-8),
                Vec3::new(1.0, 0.0, 1e-8),
                Vec3::new(-1.0, -0.5, 1e-7),
                Vec3::new(0.0, 0.0, 1e7),
                Vec3::new(1e7, 3e6, 1.0),
                Vec3::new(3.0, 0.0, 1e-6),
            ]
            .map(|l| (at(l), r)),
        );
        let mut some = 0;
        for (p, r) in points {
            let Some(sr) = r.spherical(p) else { continue };
            let omega = sr.solid_angle();
            assert!(omega.is_finite() && omega > 0.0 && omega <= 2.0 * PI);
            for &uc in &corners {
                let base = sr.sample(uc);
                if let Some(s) = &base {
                    check_sample(&r, p, s, omega);
                    some += 1;
                }
                // Powers of two scale exactly, so the directions must not change; 1e±6 round
                // the inputs, which moves an ill-conditioned configuration (p 1e-9 from a
                // vertex or the plane) by more than the tolerance: validity only.
                for scale in [1e-6, 1e6, 2f64.powi(-20), 2f64.powi(20)] {
                    let rs = Rect {
                        s: r.s * scale,
                        ex: r.ex * scale,
                        ey: r.ey * scale,
                    };
                    let ps = p * scale;
                    let Some(srs) = rs.spherical(ps) else {
                        continue;
                    };
                    if let Some(s) = srs.sample(uc) {
                        check_sample(&rs, ps, &s, srs.solid_angle());
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
        assert!(some > 80, "{some}");
        // u = (0, 0) is the corner s; u = (1, 1) the opposite one.
        let sr = r.spherical(p).unwrap();
        assert!((sr.sample(Vec2::ZERO).unwrap().point - r.s).length() < 1e-12);
        let far = r.s + r.ex + r.ey;
        assert!((sr.sample(Vec2::ONE).unwrap().point - far).length() < 1e-12);
    }
}
