//! The microsurface: Gaussian seeds on a lattice of spacing h = 1/n texels (one per texel at
//! n = 1, the paper's choice; n² per texel with `seed_subdivision` n) and their Beckmann lobes
//! [CCM19 §3, eqs. 1–6; §5.1.1 for h].
//!
//! **Seeds.** With n = 1/h seeds per texel side, seed (i, j) sits at
//! ((i + ½)/n, (j + ½)/n) in texels: at the texel centres for h = 1, on a finer lattice
//! otherwise. Its weight k_i is an isotropic 2-D Gaussian whose half maximum lies halfway to
//! the neighbouring seeds (full width at half maximum h: σ_k = h/(2√(2 ln 2)) ≈ 0.4247 h)
//! and which integrates to h² [CCM19 §3.1]. It does not depend on any footprint. Everything
//! downstream (footprints, weights, the hierarchy, the mip levels) works in *lattice* units,
//! where a seed step is 1 and σ_k = [`SEED_SIGMA`]; [`super::surface::GlintSurface::query`]
//! converts a footprint from texels.
//!
//! **Why h < 1.** A lobe is one Gaussian standing for the slopes under its seed weight. Where
//! a scratch crosses a texel, the flat and the tilted slopes of the seed's neighbourhood
//! become one smeared lobe at every footprint, however small; a finer lattice narrows each
//! seed's neighbourhood, so the P-NDF approaches the interpolated map's slope distribution
//! pointwise, at 1/h² the lobes (memory and a query's work at a given footprint in texels).
//! docs/glints.md measures the images against the brute-force reference for h = 1, ½, ¼.
//!
//! **Lobe moments.** E_i[f] = ∫ f(u) k_i(u) du  [CCM19 eq. 6] over the interpolated normal
//! map, for f = x̃, ỹ, x̃², ỹ², x̃ỹ; then σ_x² = E[x̃²] − E[x̃]², σ_y² likewise, and the
//! covariance c_xy = E[x̃ỹ] − E[x̃]E[ỹ]  [CCM19 eq. 5, ERRATA 14: c_xy, not c_xy²]. The paper
//! estimates these by Monte Carlo; here they are exact: inside each cell between four texel
//! centres the slope is bilinear, and k_i is separable, so each expectation is a sum of
//! products of 1-D integrals of the Gaussian against 1, t, t² over unit intervals — the
//! same numbers for every seed of the same phase (its offset from the texel centre below
//! it: n phases per axis). The Gaussian is truncated to the 4×4 cells around that texel
//! centre (the dropped mass is below 5e-6 at h = 1, and negligible at finer h) and
//! renormalized.
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
use crate::error::{ParamError, ParamResult};
use crate::math::quadrature::GaussLegendre;
use rayon::prelude::*;

/// σ_k = h / (2√(2 ln 2)) in lattice units (h = 1): the seed weight's standard deviation.
pub const SEED_SIGMA: f64 = 0.424_660_900_144_009_5;

/// The default roughness floor σ_ε  [CCM19 §3.2].
pub const DEFAULT_ROUGHNESS_FLOOR: f64 = 0.01;

/// Half-width (texels) of the window of cells each seed's moments integrate over.
const WINDOW: i64 = 2;

/// The most seeds per texel side (`seed_subdivision`): h = ¼, 16 lobes a texel.
pub const MAX_SEED_SUBDIVISION: usize = 4;

/// Checks a seed subdivision n (seeds per texel side, h = 1/n texels): 1 … 4.
pub fn check_seed_subdivision(n: usize) -> ParamResult<usize> {
    if (1..=MAX_SEED_SUBDIVISION).contains(&n) {
        Ok(n)
    } else {
        Err(ParamError::Invalid(format!(
            "`seed_subdivision` (seeds per texel side) must be 1, 2, 3 or 4, got {n}"
        )))
    }
}

/// The 1-D moment weights shared by every seed of one phase: with B_0(t) = 1 − t and
/// B_1(t) = t on a cell [n, n + 1] (n = −2…1, offsets from the texel centre n₀ at or below
/// the seed), `lin[a]` is the weight of the texel at offset a ∈ −2…2 in E[f] for a linear
/// interpolant, and `quad[a][a']` the weight of the pair (a, a') in E[f g] (a tridiagonal
/// 5×5 matrix); both normalized by the truncated mass.
struct SeedWeights {
    lin: [f64; 5],
    quad: [[f64; 5]; 5],
}

/// The weights of a seed at `phase` ∈ [0, 1) texels past its texel centre, of standard
/// deviation `sigma` texels.
fn seed_weights_at(phase: f64, sigma: f64) -> SeedWeights {
    let gl = GaussLegendre::new(48);
    let g = |x: f64| {
        let d = x - phase;
        (-0.5 * d * d / (sigma * sigma)).exp() / (sigma * (2.0 * std::f64::consts::PI).sqrt())
    };
    let mut lin = [0.0; 5];
    let mut quad = [[0.0; 5]; 5];
    let mut mass = 0.0;
    for n in -WINDOW..WINDOW {
        let (a, b) = (n as f64, n as f64 + 1.0);
        let basis = |k: usize, x: f64| if k == 0 { b - x } else { x - a };
        // Split the cell at the Gaussian's centre so the rule sees a smooth integrand on
        // each piece even when σ is a small part of the cell (h = ¼).
        let mut cuts = vec![a];
        if phase > a && phase < b {
            cuts.push(phase);
        }
        cuts.push(b);
        for piece in cuts.windows(2) {
            let (p0, p1) = (piece[0], piece[1]);
            mass += gl.integrate(p0, p1, g);
            for k in 0..2 {
                let ia = (n + WINDOW) as usize + k;
                lin[ia] += gl.integrate(p0, p1, |x| basis(k, x) * g(x));
                for k2 in 0..2 {
                    let ib = (n + WINDOW) as usize + k2;
                    quad[ia][ib] += gl.integrate(p0, p1, |x| basis(k, x) * basis(k2, x) * g(x));
                }
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
}

/// Where seed `i` of a lattice of `per_texel` seeds per texel lies along one axis: the texel
/// centre index n₀ at or below it and its phase past that centre (texel centres at
/// half-integers, so texel centre n sits at n + ½). The seed sits at (i + ½)/n texels, i.e.
/// (2i + 1 − n)/(2n) texels past the first texel centre: in integers, so that every seed of
/// one phase gets the same weights.
fn seed_phase(i: i64, per_texel: usize) -> (i64, f64) {
    let n = per_texel as i64;
    let num = 2 * i + 1 - n;
    let n0 = num.div_euclid(2 * n);
    (n0, num.rem_euclid(2 * n) as f64 / (2 * n) as f64)
}

/// The weights of every phase of a lattice of `per_texel` seeds per texel, by seed index
/// modulo `per_texel`.
fn lattice_weights(per_texel: usize) -> Vec<SeedWeights> {
    let sigma = SEED_SIGMA / per_texel as f64;
    (0..per_texel as i64)
        .map(|r| seed_weights_at(seed_phase(r, per_texel).1, sigma))
        .collect()
}

/// Slope mean and covariance (xx, xy, yy) of seed (x, y) of the paper's lattice (one seed
/// per texel) over the interpolated map, without the roughness floor  [CCM19 eqs. 5–6].
pub fn seed_moments(map: &NormalMap, x: i64, y: i64) -> ([f64; 2], [f64; 3]) {
    lattice_seed_moments(map, 1, x, y)
}

/// Seed (i, j) of a lattice of `per_texel` seeds per texel (h = 1/`per_texel`).
pub fn lattice_seed_moments(
    map: &NormalMap,
    per_texel: usize,
    i: i64,
    j: i64,
) -> ([f64; 2], [f64; 3]) {
    lattice_moments(map, &lattice_weights(per_texel), i, j)
}

/// Seed (i, j) of the lattice whose phases' weights are `weights` (one per phase, n of them).
fn lattice_moments(
    map: &NormalMap,
    weights: &[SeedWeights],
    i: i64,
    j: i64,
) -> ([f64; 2], [f64; 3]) {
    let n = weights.len();
    let (x, y) = (seed_phase(i, n).0, seed_phase(j, n).0);
    let p = n as i64;
    moments_with(
        map,
        &weights[i.rem_euclid(p) as usize],
        &weights[j.rem_euclid(p) as usize],
        x,
        y,
    )
}

/// The moments over the 5×5 texels around texel (x, y), with the weights `wx` along x and
/// `wy` along y (the kernel is separable).
fn moments_with(
    map: &NormalMap,
    wx: &SeedWeights,
    wy: &SeedWeights,
    x: i64,
    y: i64,
) -> ([f64; 2], [f64; 3]) {
    let mut s = [[[0.0f64; 2]; 5]; 5];
    for (b, row) in s.iter_mut().enumerate() {
        for (a, v) in row.iter_mut().enumerate() {
            *v = map.slope(x + a as i64 - WINDOW, y + b as i64 - WINDOW);
        }
    }
    let mut mean = [0.0; 2];
    for (b, row) in s.iter().enumerate() {
        for (a, v) in row.iter().enumerate() {
            let wt = wx.lin[a] * wy.lin[b];
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
            let kb = wy.quad[b][b2];
            if kb == 0.0 {
                continue;
            }
            let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
            for a in 0usize..5 {
                let p = s[b][a];
                // a2 indexes the banded weight matrix and the row of slopes together.
                #[allow(clippy::needless_range_loop)]
                for a2 in a.saturating_sub(1)..(a + 2).min(5) {
                    let ka = wx.quad[a][a2];
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
    build_lattice_lobes(map, roughness_floor, 1)
}

/// One lobe per seed of a lattice of `per_texel` × `per_texel` seeds per texel, row-major
/// over the (width · per_texel) × (height · per_texel) lattice.
pub fn build_lattice_lobes(
    map: &NormalMap,
    roughness_floor: f64,
    per_texel: usize,
) -> Vec<SlopeLobe> {
    let weights = lattice_weights(per_texel);
    let lw = map.width() * per_texel;
    (0..map.texels() * per_texel * per_texel)
        .into_par_iter()
        .with_min_len(1024)
        .map(|k| {
            let (mean, cov) = lattice_moments(map, &weights, (k % lw) as i64, (k / lw) as i64);
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
        let w = seed_weights_at(0.0, SEED_SIGMA);
        assert!((w.lin.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        let total: f64 = w.quad.iter().flatten().sum();
        assert!((total - 1.0).abs() < 1e-14);
    }

    /// The seed moments of seed (i, j) on a lattice of `per_texel` seeds per texel, by the
    /// midpoint rule on a fine grid over ±2 texels around the seed.
    fn brute_force_moments(map: &NormalMap, per_texel: usize, i: i64, j: i64) -> [f64; 5] {
        let p = per_texel as f64;
        let c = Vec2::new((i as f64 + 0.5) / p, (j as f64 + 0.5) / p);
        let sigma = SEED_SIGMA / p;
        let n = 800;
        let (mut m0, mut m1, mut m2, mut mxx, mut mxy, mut myy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for a in 0..n {
            for b in 0..n {
                let dx = -2.0 + 4.0 * (a as f64 + 0.5) / n as f64;
                let dy = -2.0 + 4.0 * (b as f64 + 0.5) / n as f64;
                let g = (-0.5 * (dx * dx + dy * dy) / (sigma * sigma)).exp();
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
        [
            e1,
            e2,
            mxx / m0 - e1 * e1,
            mxy / m0 - e1 * e2,
            myy / m0 - e2 * e2,
        ]
    }

    #[test]
    fn moments_are_exact_against_brute_force_integration() {
        // A map with structure at the texel scale; seeds of every phase at h = 1, ½ and ¼.
        let (wd, ht) = (7usize, 5usize);
        let slopes: Vec<[f32; 2]> = (0..wd * ht)
            .map(|k| {
                let (x, y) = ((k % wd) as f32, (k / wd) as f32);
                [(x * 1.7).sin() * 0.4 + 0.1 * y, (y * 2.3 + x).cos() * 0.3]
            })
            .collect();
        let map = NormalMap::from_slopes(wd, ht, slopes).unwrap();
        let seeds: [(usize, i64, i64); 7] = [
            (1, 3, 2),
            (2, 6, 4),
            (2, 7, 5),
            (4, 12, 8),
            (4, 13, 9),
            (4, 14, 10),
            (4, 15, 11),
        ];
        for (per_texel, i, j) in seeds {
            let (mean, cov) = lattice_seed_moments(&map, per_texel, i, j);
            let r = brute_force_moments(&map, per_texel, i, j);
            let got = [mean[0], mean[1], cov[0], cov[1], cov[2]];
            for k in 0..5 {
                assert!(
                    (got[k] - r[k]).abs() < 2e-5,
                    "1/h = {per_texel}, seed ({i}, {j}), moment {k}: {} vs {}",
                    got[k],
                    r[k]
                );
            }
        }
    }

    #[test]
    fn lattice_seeds_sit_where_the_lattice_puts_them() {
        // On a map whose slope is linear in position the interpolation is exact, so a seed's
        // mean slope is the slope at its centre ((i + ½) h, (j + ½) h) texels, and its
        // covariance the spread of the linear field under a Gaussian of σ_k h.
        let (wd, ht) = (16usize, 16usize);
        let slope = |x: f64, y: f64| [0.02 * x - 0.1, -0.03 * y + 0.05];
        let slopes: Vec<[f32; 2]> = (0..wd * ht)
            .map(|k| {
                let (x, y) = ((k % wd) as f64 + 0.5, (k / wd) as f64 + 0.5);
                let s = slope(x, y);
                [s[0] as f32, s[1] as f32]
            })
            .collect();
        let map = NormalMap::from_slopes(wd, ht, slopes).unwrap();
        for per_texel in 1..=MAX_SEED_SUBDIVISION {
            let p = per_texel as i64;
            let lobes = build_lattice_lobes(&map, 0.01, per_texel);
            assert_eq!(lobes.len(), wd * ht * per_texel * per_texel);
            let sigma = SEED_SIGMA / per_texel as f64;
            // Seeds away from the wrap-around, where the periodic map is not linear.
            for (i, j) in [
                (3 * p, 4 * p),
                (5 * p + p - 1, 7 * p + p / 2),
                (8 * p + 1, 9 * p),
            ] {
                let h = 1.0 / per_texel as f64;
                let want = slope((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
                let f = lobes[(j * wd as i64 * p + i) as usize].to_f64();
                assert!(
                    (f.mean[0] - want[0]).abs() < 1e-6 && (f.mean[1] - want[1]).abs() < 1e-6,
                    "1/h = {per_texel}, seed ({i}, {j}): {:?} vs {want:?}",
                    f.mean
                );
                let vx = (0.02 * sigma).powi(2) + 1e-4;
                let vy = (0.03 * sigma).powi(2) + 1e-4;
                assert!((f.cov[0] - vx).abs() < 1e-4 * vx, "{:?} vs {vx}", f.cov);
                assert!((f.cov[2] - vy).abs() < 1e-4 * vy, "{:?} vs {vy}", f.cov);
            }
        }
    }

    #[test]
    fn seed_phases_repeat_with_the_subdivision() {
        for n in 1..=MAX_SEED_SUBDIVISION {
            for i in 0..40i64 {
                let (n0, phase) = seed_phase(i, n);
                let pos = (i as f64 + 0.5) / n as f64 - 0.5;
                assert!((n0 as f64 + phase - pos).abs() < 1e-12 && (0.0..1.0).contains(&phase));
                assert_eq!(phase, seed_phase(i.rem_euclid(n as i64), n).1);
            }
        }
        assert_eq!(check_seed_subdivision(3).unwrap(), 3);
        for bad in [0, 5, 100] {
            let e = check_seed_subdivision(bad).unwrap_err().to_string();
            assert!(
                e.contains("seed_subdivision") && e.contains("1, 2, 3 or 4"),
                "{e}"
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
