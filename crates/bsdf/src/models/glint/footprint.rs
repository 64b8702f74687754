//! The ray footprint k_P: a normalized 2-D Gaussian over the map  [CCM19 §4.1], and what a
//! query precomputes from it.
//!
//! **Weights.** W_i = ∫ k_i k_P du  [CCM19 eq. 9] is the integral of a product of Gaussians:
//! with k_P = N(c, Σ_P) and k_i = N(u_i, σ_k² I) (integrating to h² = 1),
//! W_i = N(u_i; c, S) with S = Σ_P + σ_k² I. The paper states Σ W_i = 1; on a lattice the sum
//! ripples by up to ±12 % around 1 for footprints below a texel, so the patch NDF divides by
//! Z = Σ_i W_i, evaluated by Poisson summation: Z = Σ_{m ∈ ℤ²} e^{−2π² mᵀSm} cos(2π m·(c − ½))
//! (λ_min(S) ≥ σ_k² makes the terms with |m|² > 9 smaller than 1e-14).
//!
//! **Truncation.** Seeds with (u_i − c)ᵀS⁻¹(u_i − c) > R² (R² = [`CUTOFF_R2`]) are dropped
//! (the paper's ±3σ boxes, §5, made stricter): the set T of the others is what the patch
//! NDF sums and what the sampler draws from. Z counts every seed, so the patch NDF
//! integrates to Σ_T W_i / Z ≥ 1 − e^{−R²/2} = 0.99966 (measured by the tests).
//!
//! **Tiling.** The map repeats; a footprint may straddle tiles, and its seeds are taken in
//! every tile copy it reaches (the list of tile offsets is computed once per query).
//!
//! **Large footprints.** When S is at least one map period along both axes
//! (λ_min(S) ≥ max(W, H)²) the periodized weights are uniform to 3e-9 (their Fourier terms
//! are e^{−2π² λ_min/period²}): the query switches to the exact uniform average over the map
//! (W_i = 1/N), which is the map's global distribution. Otherwise the major axis of S is
//! clamped to one period (λ_max ≤ max(W, H)²) to bound the number of tile copies; that
//! changes the weights only where a footprint is longer than the map along one direction
//! and thin along the other.

use super::lobe::{cholesky2, CUTOFF_R2};
use super::microsurface::SEED_SIGMA;
use crate::math::{Vec2, PI};

/// A footprint in texel units: centre (texel centres at half-integers) and covariance
/// (xx, xy, yy) in texels².
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    pub center: Vec2,
    pub cov: [f64; 3],
}

impl Footprint {
    /// An isotropic footprint of standard deviation `sigma` texels.
    pub fn isotropic(center: Vec2, sigma: f64) -> Footprint {
        Footprint {
            center,
            cov: [sigma * sigma, 0.0, sigma * sigma],
        }
    }

    /// The footprint of standard deviations (σ_x, σ_y) with correlation ρ.
    pub fn from_sigmas(center: Vec2, sx: f64, sy: f64, rho: f64) -> Footprint {
        Footprint {
            center,
            cov: [sx * sx, rho * sx * sy, sy * sy],
        }
    }

    /// The Gaussian with covariance s² (d_x d_xᵀ + d_y d_yᵀ) spanned by the two
    /// screen-space derivative vectors d_x, d_y (already in texels per pixel).
    pub fn from_derivatives(center: Vec2, dx: Vec2, dy: Vec2, s: f64) -> Footprint {
        let s2 = s * s;
        Footprint {
            center,
            cov: [
                s2 * (dx.x * dx.x + dy.x * dy.x),
                s2 * (dx.x * dx.y + dy.x * dy.y),
                s2 * (dx.y * dx.y + dy.y * dy.y),
            ],
        }
    }

    /// Finite, positive semi-definite covariance.
    pub fn sanitized(self) -> Footprint {
        let center = if self.center.is_finite() {
            self.center
        } else {
            Vec2::ZERO
        };
        if !self.cov.iter().all(|v| v.is_finite()) {
            return Footprint::isotropic(center, 0.0);
        }
        let xx = self.cov[0].max(0.0);
        let yy = self.cov[2].max(0.0);
        let lim = (xx * yy).sqrt();
        Footprint {
            center,
            cov: [xx, self.cov[1].clamp(-lim, lim), yy],
        }
    }
}

/// Eigen-decomposition of a symmetric 2×2 matrix: (λ_max, λ_min, unit eigenvector of
/// λ_max).
pub fn eigen2(m: [f64; 3]) -> (f64, f64, Vec2) {
    let [a, b, c] = m;
    let tr = 0.5 * (a + c);
    let d = (0.25 * (a - c) * (a - c) + b * b).sqrt();
    let (l1, l2) = (tr + d, tr - d);
    let v = if b.abs() > 1e-300 {
        Vec2::new(l1 - c, b).normalize()
    } else if a >= c {
        Vec2::X
    } else {
        Vec2::Y
    };
    (l1, l2, v)
}

/// How a query weights the seeds.
#[derive(Clone, Debug, PartialEq)]
pub enum Weighting {
    /// W_i = 1/N over the whole map.
    Uniform,
    /// W_i = N(u_i; c, S) / Z over the seeds of T.
    Gaussian,
}

/// Everything a query derives from a footprint once.
#[derive(Clone, Debug)]
pub struct FootprintQuery {
    pub weighting: Weighting,
    /// Centre, reduced into the base tile.
    pub center: Vec2,
    /// S = Σ_P + σ_k² I (clamped) and its inverse (a, b, c).
    pub s: [f64; 3],
    pub s_inv: [f64; 3],
    /// 1/(2π √|S|) / Z: multiplies e^{−q/2} to give W_i/Z.
    pub weight_scale: f64,
    /// Z = Σ_i W_i over the infinite lattice.
    pub z: f64,
    /// Cholesky factor of Σ_P (clamped) for sampling positions.
    pub footprint_chol: [f64; 3],
    /// Tile offsets (in tiles) whose seeds the footprint reaches.
    pub tiles: Vec<(i64, i64)>,
    pub map_size: (usize, usize),
}

impl FootprintQuery {
    pub fn new(fp: Footprint, width: usize, height: usize) -> FootprintQuery {
        let fp = fp.sanitized();
        let (wf, hf) = (width as f64, height as f64);
        let center = Vec2::new(fp.center.x.rem_euclid(wf), fp.center.y.rem_euclid(hf));
        let k2 = SEED_SIGMA * SEED_SIGMA;
        let mut s = [fp.cov[0] + k2, fp.cov[1], fp.cov[2] + k2];
        let period2 = wf.max(hf).powi(2);
        let (l1, l2, v) = eigen2(s);
        if l2 >= period2 {
            return FootprintQuery {
                weighting: Weighting::Uniform,
                center,
                s,
                s_inv: [0.0; 3],
                weight_scale: 1.0 / (width * height) as f64,
                z: 1.0,
                footprint_chol: [0.0; 3],
                tiles: vec![(0, 0)],
                map_size: (width, height),
            };
        }
        if l1 > period2 {
            // Clamp the major axis to one period: S = λ1' v vᵀ + λ2 (I − v vᵀ).
            let l1 = period2;
            s = [
                l1 * v.x * v.x + l2 * v.y * v.y,
                (l1 - l2) * v.x * v.y,
                l1 * v.y * v.y + l2 * v.x * v.x,
            ];
        }
        let det = (s[0] * s[2] - s[1] * s[1]).max(1e-300);
        let s_inv = [s[2] / det, -s[1] / det, s[0] / det];
        let z = lattice_gaussian_sum(s, center);
        let footprint_chol = cholesky2([s[0] - k2, s[1], s[2] - k2]);
        let mut q = FootprintQuery {
            weighting: Weighting::Gaussian,
            center,
            s,
            s_inv,
            weight_scale: 1.0 / (2.0 * PI * det.sqrt() * z),
            z,
            footprint_chol,
            tiles: Vec::new(),
            map_size: (width, height),
        };
        q.tiles = q.tiles_reached(q.s, q.s_inv);
        q
    }

    /// Half-extents of the bounding box of the truncation ellipse of covariance `s`.
    pub fn ellipse_half_extent(s: [f64; 3]) -> Vec2 {
        let r = CUTOFF_R2.sqrt();
        Vec2::new(r * s[0].sqrt(), r * s[2].sqrt())
    }

    /// Tile offsets whose seed-centre box [½, W − ½] × [½, H − ½] meets the ellipse of `s`.
    pub fn tiles_reached(&self, s: [f64; 3], s_inv: [f64; 3]) -> Vec<(i64, i64)> {
        let (wf, hf) = (self.map_size.0 as f64, self.map_size.1 as f64);
        let e = Self::ellipse_half_extent(s);
        let c = self.center;
        let tx0 = ((c.x - e.x - 0.5) / wf).floor() as i64;
        let tx1 = ((c.x + e.x - 0.5) / wf).floor() as i64;
        let ty0 = ((c.y - e.y - 0.5) / hf).floor() as i64;
        let ty1 = ((c.y + e.y - 0.5) / hf).floor() as i64;
        let mut out = Vec::new();
        for ty in ty0..=ty1 {
            for tx in tx0..=tx1 {
                let (ox, oy) = (tx as f64 * wf, ty as f64 * hf);
                let q = min_quadratic_over_box(
                    s_inv,
                    c,
                    [ox + 0.5, ox + wf - 0.5],
                    [oy + 0.5, oy + hf - 0.5],
                );
                if q <= CUTOFF_R2 {
                    out.push((tx, ty));
                }
            }
        }
        out
    }

    /// (u − c)ᵀ S⁻¹ (u − c).
    #[inline]
    pub fn mahalanobis2(&self, u: Vec2) -> f64 {
        let d = u - self.center;
        let [a, b, c] = self.s_inv;
        a * d.x * d.x + 2.0 * b * d.x * d.y + c * d.y * d.y
    }

    /// Number of seeds the truncation ellipse holds (its area).
    pub fn seeds_estimate(&self) -> f64 {
        match self.weighting {
            Weighting::Uniform => (self.map_size.0 * self.map_size.1) as f64,
            Weighting::Gaussian => {
                PI * CUTOFF_R2
                    * (self.s[0] * self.s[2] - self.s[1] * self.s[1])
                        .max(0.0)
                        .sqrt()
            }
        }
    }
}

/// Σ over the lattice u = n + ½ (n ∈ ℤ²) of N(u; c, S), by Poisson summation (module notes).
///
/// Runs at every shading point. The terms of m and −m are equal (the exponent and the cosine
/// are even), so the half plane {m_y > 0} ∪ {m_y = 0, m_x > 0} is summed twice, plus m = 0;
/// the phases cos 2π(m_x p_x + m_y p_y) are the real parts of products of powers of
/// e^{2πi p_x} and e^{2πi p_y} — two `sin_cos` in place of 48 cosines (perf had the cosines
/// at 8 % of a brushed-plate render) and half the exponentials.
pub fn lattice_gaussian_sum(s: [f64; 3], c: Vec2) -> f64 {
    /// (cos 2πkp, sin 2πkp) for k = 0..=3.
    fn phase_powers(p: f64) -> [(f64, f64); 4] {
        let (sin, cos) = (2.0 * PI * p).sin_cos();
        let mut z = [(1.0, 0.0); 4];
        for k in 1..4 {
            let (a, b) = z[k - 1];
            z[k] = (a * cos - b * sin, a * sin + b * cos);
        }
        z
    }
    let zx = phase_powers(c.x - 0.5);
    let zy = phase_powers(c.y - 0.5);
    let mut z = 1.0;
    for my in 0i32..=3 {
        let (ay, by) = zy[my as usize];
        for mx in if my == 0 { 1 } else { -3 }..=3i32 {
            let (fx, fy) = (mx as f64, my as f64);
            let e = 2.0 * PI * PI * (s[0] * fx * fx + 2.0 * s[1] * fx * fy + s[2] * fy * fy);
            if e > 40.0 {
                continue;
            }
            // e^{−2πi k p} is the conjugate of e^{2πi k p}.
            let (ax, bx) = zx[mx.unsigned_abs() as usize];
            let bx = if mx < 0 { -bx } else { bx };
            z += 2.0 * (-e).exp() * (ax * ay - bx * by);
        }
    }
    z
}

/// min over the box [x0, x1] × [y0, y1] of (u − c)ᵀ B (u − c) for positive semi-definite B:
/// 0 when c is inside, else the smallest of the four edge minima (each a clamped 1-D
/// quadratic).
#[inline]
pub fn min_quadratic_over_box(b: [f64; 3], c: Vec2, xr: [f64; 2], yr: [f64; 2]) -> f64 {
    if c.x >= xr[0] && c.x <= xr[1] && c.y >= yr[0] && c.y <= yr[1] {
        return 0.0;
    }
    let [a, bb, cc] = b;
    let q = |dx: f64, dy: f64| a * dx * dx + 2.0 * bb * dx * dy + cc * dy * dy;
    let mut best = f64::INFINITY;
    // Edges x = const: minimize over dy given dx: dy* = −b dx / c.
    for x in xr {
        let dx = x - c.x;
        let dy = if cc > 0.0 { -bb * dx / cc } else { 0.0 };
        let y = (c.y + dy).clamp(yr[0], yr[1]);
        best = best.min(q(dx, y - c.y));
    }
    for y in yr {
        let dy = y - c.y;
        let dx = if a > 0.0 { -bb * dy / a } else { 0.0 };
        let x = (c.x + dx).clamp(xr[0], xr[1]);
        best = best.min(q(x - c.x, dy));
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn poisson_sum_matches_the_direct_lattice_sum() {
        for (s, c) in [
            (
                [SEED_SIGMA * SEED_SIGMA, 0.0, SEED_SIGMA * SEED_SIGMA],
                Vec2::new(3.5, 2.5),
            ),
            ([0.4, 0.1, 0.25], Vec2::new(1.1, 7.9)),
            ([4.0, -1.5, 2.0], Vec2::new(0.0, 0.3)),
            // Sub-texel (near λ_min(S) = σ_k², where the most terms count) and correlated.
            ([0.2, 0.01, 0.19], Vec2::new(0.37, 0.81)),
            ([0.25, -0.05, 0.3], Vec2::new(-2.9, 5.13)),
        ] {
            let det = s[0] * s[2] - s[1] * s[1];
            let inv = [s[2] / det, -s[1] / det, s[0] / det];
            let mut direct = 0.0;
            for y in -60..60 {
                for x in -60..60 {
                    let dx = x as f64 + 0.5 - c.x;
                    let dy = y as f64 + 0.5 - c.y;
                    let q = inv[0] * dx * dx + 2.0 * inv[1] * dx * dy + inv[2] * dy * dy;
                    direct += (-0.5 * q).exp() / (2.0 * PI * det.sqrt());
                }
            }
            let z = lattice_gaussian_sum(s, c);
            assert!((z - direct).abs() < 1e-13, "{z} vs {direct}");
        }
    }

    #[test]
    fn box_minimum_is_exact() {
        let b = [2.0, 0.7, 1.0];
        let c = Vec2::new(-1.0, 3.0);
        let (xr, yr) = ([0.0, 2.0], [0.0, 1.0]);
        let mut brute = f64::INFINITY;
        for i in 0..=400 {
            for j in 0..=200 {
                let u = Vec2::new(i as f64 * 0.005, j as f64 * 0.005);
                let d = u - c;
                brute = brute.min(b[0] * d.x * d.x + 2.0 * b[1] * d.x * d.y + b[2] * d.y * d.y);
            }
        }
        let m = min_quadratic_over_box(b, c, xr, yr);
        assert!(m <= brute + 1e-12 && brute - m < 1e-3, "{m} {brute}");
    }

    #[test]
    fn huge_footprints_become_uniform_and_long_ones_are_clamped() {
        let q = FootprintQuery::new(Footprint::isotropic(Vec2::new(3.0, 3.0), 100.0), 64, 64);
        assert_eq!(q.weighting, Weighting::Uniform);
        let q = FootprintQuery::new(
            Footprint::from_sigmas(Vec2::new(3.0, 3.0), 1000.0, 1.0, 0.0),
            64,
            64,
        );
        assert_eq!(q.weighting, Weighting::Gaussian);
        assert!((q.s[0] - 64.0 * 64.0).abs() < 1e-6, "{:?}", q.s);
        assert!(q.tiles.len() <= 18, "{}", q.tiles.len());
        let q = FootprintQuery::new(Footprint::isotropic(Vec2::new(0.2, 0.3), 1.0), 64, 64);
        assert!(q.tiles.contains(&(-1, -1)) && q.tiles.contains(&(0, 0)));
    }
}
