//! The microsurface: one Gaussian seed per texel (h = 1) and its Beckmann lobe
//! [CCM19 §3, eqs. 1–6].
//!
//! **Seeds.** Seed i sits at the centre u_i of texel i. Its weight k_i is an isotropic 2-D
//! Gaussian whose half maximum lies halfway to the neighbouring seeds (full width at half
//! maximum h = 1 texel: σ_k = 1/(2√(2 ln 2)) ≈ 0.4247 texel) and which integrates to h² = 1
//! [CCM19 §3.1]. It does not depend on any footprint.
//!
//! **Lobe moments.** E_i[f] = ∫ f(u) k_i(u) du  [CCM19 eq. 6] over the interpolated normal
//! map, for f = x̃, ỹ, x̃², ỹ², x̃ỹ; then σ_x² = E[x̃²] − E[x̃]², σ_y² likewise, and the
//! covariance c_xy = E[x̃ỹ] − E[x̃]E[ỹ]  [CCM19 eq. 5, ERRATA 14: c_xy, not c_xy²]. The paper
//! estimates these by Monte Carlo; here they are exact: inside each cell between four texel
//! centres the slope is bilinear, and k_i is separable, so each expectation is a sum of
//! products of 1-D integrals of the Gaussian against 1, t, t² over unit intervals — the
//! same numbers for every seed. The Gaussian is truncated to the 4×4 cells around the seed
//! (±2 texels: the dropped mass is 5e-6) and renormalized.
//!
//! **Roughness floor.** Where the map is locally flat σ = 0 and the lobe is singular; the
//! paper sets σ to σ_ε = 0.01 there. We add σ_ε² to both variances everywhere: the result is
//! the slope distribution of the interpolated map seen through the near-specular
//! microsurface of roughness σ_ε that the paper's reference renders use (§5.2.2), it equals
//! the paper's rule on flat texels, and it is continuous where the map is almost flat (the
//! paper's rule jumps from σ_ε to 0⁺ there).

use super::lobe::SlopeLobe;
use super::normal_map::NormalMap;
use crate::checks::{check_range, Bounds};
use crate::error::ParamResult;
use crate::math::quadrature::GaussLegendre;
use rayon::prelude::*;
use std::sync::OnceLock;

/// σ_k = h / (2√(2 ln 2)) with h = 1 texel: the seed weight's standard deviation.
pub const SEED_SIGMA: f64 = 0.424_660_900_144_009_5;

/// The default roughness floor σ_ε  [CCM19 §3.2].
pub const DEFAULT_ROUGHNESS_FLOOR: f64 = 0.01;

/// Half-width (texels) of the window of cells each seed's moments integrate over.
const WINDOW: i64 = 2;

/// The 1-D moment weights shared by every seed: with B_0(t) = 1 − t and B_1(t) = t on a cell
/// [n, n + 1] (n = −2…1, offsets from the seed), `lin[a]` is the weight of the texel at
/// offset a ∈ −2…2 in E[f] for a linear interpolant, and `quad[a][a']` the weight of the
/// pair (a, a') in E[f g] (a tridiagonal 5×5 matrix); both normalized by the truncated mass.
struct SeedWeights {
    lin: [f64; 5],
    quad: [[f64; 5]; 5],
}

fn seed_weights() -> &'static SeedWeights {
    static W: OnceLock<SeedWeights> = OnceLock::new();
    W.get_or_init(|| {
        let gl = GaussLegendre::new(48);
        let g = |x: f64| {
            (-0.5 * x * x / (SEED_SIGMA * SEED_SIGMA)).exp()
                / (SEED_SIGMA * (2.0 * std::f64::consts::PI).sqrt())
        };
        let mut lin = [0.0; 5];
        let mut quad = [[0.0; 5]; 5];
        let mut mass = 0.0;
        for n in -WINDOW..WINDOW {
            let (a, b) = (n as f64, n as f64 + 1.0);
            let basis = |k: usize, x: f64| if k == 0 { b - x } else { x - a };
            mass += gl.integrate(a, b, g);
            for k in 0..2 {
                let ia = (n + WINDOW) as usize + k;
                lin[ia] += gl.integrate(a, b, |x| basis(k, x) * g(x));
                for k2 in 0..2 {
                    let ib = (n + WINDOW) as usize + k2;
                    quad[ia][ib] += gl.integrate(a, b, |x| basis(k, x) * basis(k2, x) * g(x));
                }
            }
        }
        for v in lin.iter_mut() {
            *v /= mass;
        }
        for row in quad.iter_mut() {
            for v in row.iter_mut() {
                *v /= mass;
            }
        }
        SeedWeights { lin, quad }
    })
}

/// Slope mean and covariance (xx, xy, yy) of seed (x, y) over the interpolated map, without
/// the roughness floor  [CCM19 eqs. 5–6].
pub fn seed_moments(map: &NormalMap, x: i64, y: i64) -> ([f64; 2], [f64; 3]) {
    let w = seed_weights();
    let mut s = [[[0.0f64; 2]; 5]; 5];
    for (b, row) in s.iter_mut().enumerate() {
        for (a, v) in row.iter_mut().enumerate() {
            *v = map.slope(x + a as i64 - WINDOW, y + b as i64 - WINDOW);
        }
    }
    let mut mean = [0.0; 2];
    for (b, row) in s.iter().enumerate() {
        for (a, v) in row.iter().enumerate() {
            let wt = w.lin[a] * w.lin[b];
            mean[0] += wt * v[0];
            mean[1] += wt * v[1];
        }
    }
    // E[f g] = Σ_{b,b'} K[b][b'] Σ_{a,a'} f(a,b) K[a][a'] g(a',b').
    let mut exx = 0.0;
    let mut exy = 0.0;
    let mut eyy = 0.0;
    for b in 0usize..5 {
        for b2 in b.saturating_sub(1)..(b + 2).min(5) {
            let kb = w.quad[b][b2];
            if kb == 0.0 {
                continue;
            }
            let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
            for a in 0usize..5 {
                let p = s[b][a];
                // a2 indexes the banded weight matrix and the row of slopes together.
                #[allow(clippy::needless_range_loop)]
                for a2 in a.saturating_sub(1)..(a + 2).min(5) {
                    let ka = w.quad[a][a2];
                    let q = s[b2][a2];
                    xx += ka * p[0] * q[0];
                    xy += ka * p[0] * q[1];
                    yy += ka * p[1] * q[1];
                }
            }
            exx += kb * xx;
            exy += kb * xy;
            eyy += kb * yy;
        }
    }
    let cov = [
        (exx - mean[0] * mean[0]).max(0.0),
        exy - mean[0] * mean[1],
        (eyy - mean[1] * mean[1]).max(0.0),
    ];
    (mean, cov)
}

/// The covariance with the roughness floor σ_ε² added to both variances and the
/// correlation kept within ±0.999 (rounding may push a near-degenerate one past 1).
pub fn floored_covariance(cov: [f64; 3], floor: f64) -> [f64; 3] {
    let xx = cov[0] + floor * floor;
    let yy = cov[2] + floor * floor;
    let lim = 0.999 * (xx * yy).sqrt();
    [xx, cov[1].clamp(-lim, lim), yy]
}

/// Checks a roughness floor σ_ε.
pub fn check_roughness_floor(floor: f64) -> ParamResult<f64> {
    check_range("roughness_floor", floor, 0.0, 1.0, Bounds::OpenClosed)
}

/// One lobe per texel, row-major.
pub fn build_lobes(map: &NormalMap, roughness_floor: f64) -> Vec<SlopeLobe> {
    let w = map.width();
    (0..map.texels())
        .into_par_iter()
        .with_min_len(1024)
        .map(|k| {
            let (mean, cov) = seed_moments(map, (k % w) as i64, (k / w) as i64);
            SlopeLobe::from_moments(mean, floored_covariance(cov, roughness_floor))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec2;

    #[test]
    fn seed_width_puts_half_maximum_halfway_between_seeds() {
        let g = |x: f64| (-0.5 * x * x / (SEED_SIGMA * SEED_SIGMA)).exp();
        assert!((g(0.5) - 0.5).abs() < 1e-15);
        let w = seed_weights();
        assert!((w.lin.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        let total: f64 = w.quad.iter().flatten().sum();
        assert!((total - 1.0).abs() < 1e-14);
    }

    #[test]
    fn moments_are_exact_against_brute_force_integration() {
        // A map with structure at the texel scale.
        let (wd, ht) = (7usize, 5usize);
        let slopes: Vec<[f32; 2]> = (0..wd * ht)
            .map(|k| {
                let (x, y) = ((k % wd) as f32, (k / wd) as f32);
                [(x * 1.7).sin() * 0.4 + 0.1 * y, (y * 2.3 + x).cos() * 0.3]
            })
            .collect();
        let map = NormalMap::from_slopes(wd, ht, slopes).unwrap();
        let (sx, sy) = (3i64, 2i64);
        let (mean, cov) = seed_moments(&map, sx, sy);
        // Midpoint rule on a fine grid over the same ±2-texel window.
        let n = 800;
        let c = Vec2::new(sx as f64 + 0.5, sy as f64 + 0.5);
        let (mut m0, mut m1, mut m2, mut mxx, mut mxy, mut myy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for i in 0..n {
            for j in 0..n {
                let dx = -2.0 + 4.0 * (i as f64 + 0.5) / n as f64;
                let dy = -2.0 + 4.0 * (j as f64 + 0.5) / n as f64;
                let g = (-0.5 * (dx * dx + dy * dy) / (SEED_SIGMA * SEED_SIGMA)).exp();
                let s = map.interpolated_slope(c + Vec2::new(dx, dy));
                m0 += g;
                m1 += g * s[0];
                m2 += g * s[1];
                mxx += g * s[0] * s[0];
                mxy += g * s[0] * s[1];
                myy += g * s[1] * s[1];
            }
        }
        let (e1, e2) = (m1 / m0, m2 / m0);
        let ref_cov = [mxx / m0 - e1 * e1, mxy / m0 - e1 * e2, myy / m0 - e2 * e2];
        assert!((mean[0] - e1).abs() < 2e-5 && (mean[1] - e2).abs() < 2e-5);
        for k in 0..3 {
            assert!(
                (cov[k] - ref_cov[k]).abs() < 2e-5,
                "{k}: {} vs {}",
                cov[k],
                ref_cov[k]
            );
        }
    }

    #[test]
    fn a_flat_map_gives_lobes_of_the_roughness_floor() {
        let map = NormalMap::from_slopes(4, 4, vec![[0.25, -0.1]; 16]).unwrap();
        for l in build_lobes(&map, 0.01) {
            let f = l.to_f64();
            assert!((f.mean[0] - 0.25).abs() < 1e-7 && (f.mean[1] + 0.1).abs() < 1e-7);
            assert!((f.cov[0] - 1e-4).abs() < 1e-9 && f.cov[1].abs() < 1e-10);
            assert!((f.cov[2] - 1e-4).abs() < 1e-9);
        }
    }
}
