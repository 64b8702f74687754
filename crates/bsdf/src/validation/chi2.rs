//! Chi-square goodness of fit of a sampler against its density, in the manner of Mitsuba 3's
//! `ChiSquareTest`: directions are binned on the sphere through a [`SphereMap`], expected
//! counts come from integrating the pdf over each bin (composite Simpson), cells with small
//! expected counts are pooled, and the p-value is compared with a significance corrected
//! for the number of tests by the caller.

use super::sphere_map::SphereMap;
use crate::math::rng::{mix_seed, Pcg32};
use crate::math::{Vec2, Vec3};
use rayon::prelude::*;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Test configuration.
#[derive(Clone, Copy, Debug)]
pub struct Chi2Config {
    /// Bins along u₁ (polar) and u₂ (azimuth).
    pub bins: (usize, usize),
    /// Number of samples drawn.
    pub samples: usize,
    /// Simpson sub-intervals per bin and dimension (even).
    pub subdivisions: usize,
    pub seed: u64,
}

impl Default for Chi2Config {
    fn default() -> Self {
        Chi2Config {
            bins: (32, 64),
            samples: 1_000_000,
            subdivisions: 6,
            seed: 7,
        }
    }
}

/// Outcome of one chi-square test.
#[derive(Clone, Debug)]
pub struct Chi2Outcome {
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
    /// ∫ pdf over the sphere (≤ 1; < 1 when the sampler can fail or has delta lobes).
    pub pdf_integral: f64,
    /// Fraction of draws that returned no direction or one outside the tested region.
    pub null_fraction: f64,
    /// Draws that landed where pdf = 0 (must be zero).
    pub zero_pdf_hits: usize,
    /// Draws returning non-finite or non-unit directions (must be zero).
    pub invalid: usize,
}

impl Chi2Outcome {
    /// Passes at the (already corrected) significance level.
    pub fn passes(&self, significance: f64) -> bool {
        self.zero_pdf_hits == 0 && self.invalid == 0 && self.p_value > significance
    }

    pub fn summary(&self) -> String {
        let mut s = format!(
            "chi2 = {:.1} (dof {}), p = {:.3e}, ∫pdf = {:.5}",
            self.statistic, self.dof, self.p_value, self.pdf_integral
        );
        if self.null_fraction > 0.0 {
            s += &format!(", outside/no-sample {:.4}", self.null_fraction);
        }
        if self.zero_pdf_hits > 0 {
            s += &format!(", {} samples where pdf = 0", self.zero_pdf_hits);
        }
        if self.invalid > 0 {
            s += &format!(", {} invalid directions", self.invalid);
        }
        s
    }
}

/// Runs the test. `sample` draws one direction (or `None` when the sampler produces no
/// direction, e.g. absorption); `pdf` is the density it claims.
pub fn chi2_test(
    map: &SphereMap,
    cfg: &Chi2Config,
    sample: impl Fn(&mut Pcg32) -> Option<Vec3> + Sync,
    pdf: impl Fn(Vec3) -> f64 + Sync,
) -> Chi2Outcome {
    chi2_test_region(map, cfg, |_| true, sample, pdf)
}

/// [`chi2_test`] restricted to a region of the sphere: directions outside `in_region` (and
/// draws without a direction) all fall in one cell whose expected probability is
/// 1 − ∫_region pdf. A lobe outside the region is then tested only through its total mass,
/// and needs no resolution from this map — the way a dielectric's reflection and
/// transmission lobes are tested each with a map zoomed on it.
pub fn chi2_test_region(
    map: &SphereMap,
    cfg: &Chi2Config,
    in_region: impl Fn(Vec3) -> bool + Sync,
    sample: impl Fn(&mut Pcg32) -> Option<Vec3> + Sync,
    pdf: impl Fn(Vec3) -> f64 + Sync,
) -> Chi2Outcome {
    let pdf = |d: Vec3| if in_region(d) { pdf(d) } else { 0.0 };
    let (nu, nv) = cfg.bins;
    let cells = nu * nv;
    const CHUNKS: usize = 64;
    let per_chunk = cfg.samples.div_ceil(CHUNKS);

    // Observed counts.
    let partial: Vec<(Vec<u32>, usize, usize, usize)> = (0..CHUNKS)
        .into_par_iter()
        .map(|c| {
            let mut rng = Pcg32::new(mix_seed(cfg.seed, c as u64), c as u64);
            let mut hist = vec![0u32; cells];
            let (mut null, mut zero, mut invalid) = (0, 0, 0);
            let n = per_chunk.min(cfg.samples.saturating_sub(c * per_chunk));
            for _ in 0..n {
                match sample(&mut rng) {
                    None => null += 1,
                    Some(d) => {
                        if !d.is_finite() || (d.length_squared() - 1.0).abs() > 1e-6 {
                            invalid += 1;
                            continue;
                        }
                        if !in_region(d) {
                            null += 1;
                            continue;
                        }
                        if !(pdf(d) > 0.0) {
                            zero += 1;
                        }
                        let u = map.to_unit(d);
                        let i = ((u.x * nu as f64) as usize).min(nu - 1);
                        let j = ((u.y * nv as f64) as usize).min(nv - 1);
                        hist[i * nv + j] += 1;
                    }
                }
            }
            (hist, null, zero, invalid)
        })
        .collect();
    let mut observed = vec![0f64; cells];
    let (mut null, mut zero, mut invalid) = (0usize, 0usize, 0usize);
    for (h, n, z, i) in partial {
        for (o, v) in observed.iter_mut().zip(h) {
            *o += v as f64;
        }
        null += n;
        zero += z;
        invalid += i;
    }

    let expected = expected_probabilities(map, cfg, &pdf);
    let pdf_integral: f64 = expected.iter().sum();
    let n = cfg.samples as f64;
    let mut cells_oe: Vec<(f64, f64)> = observed
        .iter()
        .zip(&expected)
        .map(|(&o, &e)| (o, e * n))
        .collect();
    // The "no direction" outcome is one more cell.
    let null_expected = ((1.0 - pdf_integral) * n).max(0.0);
    if null > 0 || null_expected >= 5.0 {
        cells_oe.push((null as f64, null_expected));
    }

    // Pool every cell with expected < 5, then grow the pool until it reaches 5.
    cells_oe.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut pool = (0.0, 0.0);
    let mut start = 0;
    while start < cells_oe.len() && cells_oe[start].1 < 5.0 {
        pool.0 += cells_oe[start].0;
        pool.1 += cells_oe[start].1;
        start += 1;
    }
    while start < cells_oe.len() && pool.1 < 5.0 && (pool.1 > 0.0 || pool.0 > 0.0) {
        pool.0 += cells_oe[start].0;
        pool.1 += cells_oe[start].1;
        start += 1;
    }
    let mut stat = 0.0;
    let mut k = 0usize;
    if pool.1 > 0.0 {
        stat += (pool.0 - pool.1) * (pool.0 - pool.1) / pool.1;
        k += 1;
    } else if pool.0 > 0.0 {
        stat = f64::INFINITY;
    }
    for &(o, e) in &cells_oe[start..] {
        stat += (o - e) * (o - e) / e;
        k += 1;
    }
    let dof = k.saturating_sub(1).max(1);
    let p_value = if stat.is_finite() {
        ChiSquared::new(dof as f64)
            .map(|d| d.sf(stat))
            .unwrap_or(0.0)
    } else {
        0.0
    };
    Chi2Outcome {
        statistic: stat,
        dof,
        p_value,
        pdf_integral,
        null_fraction: null as f64 / n,
        zero_pdf_hits: zero,
        invalid,
    }
}

/// Probability of each bin (row-major, u₁ major) under `pdf`: per-bin adaptive Simpson of
/// pdf·J, refined where the pdf is discontinuous inside a bin (e.g. at the horizon).
pub fn expected_probabilities(
    map: &SphereMap,
    cfg: &Chi2Config,
    pdf: &(impl Fn(Vec3) -> f64 + Sync),
) -> Vec<f64> {
    let (nu, nv) = cfg.bins;
    let sub = cfg.subdivisions.max(2) & !1;
    let integrand = |x: f64, y: f64| {
        let u = Vec2::new(x, y);
        let p = pdf(map.to_direction(u));
        if p.is_finite() {
            p * map.jacobian(u)
        } else {
            0.0
        }
    };
    (0..nu * nv)
        .into_par_iter()
        .map(|c| {
            let (i, j) = (c / nv, c % nv);
            let (hu, hv) = (1.0 / nu as f64, 1.0 / nv as f64);
            integrate_cell(
                &integrand,
                (i as f64 * hu, (i + 1) as f64 * hu),
                (j as f64 * hv, (j + 1) as f64 * hv),
                sub,
                8,
            )
        })
        .collect()
}

/// ∫∫ f over a rectangle by Simpson's rule on `sub`×`sub` intervals, compared with the
/// 2×2-interval rule on the same points; where they disagree the cell is split in four
/// (up to `depth` levels). A step inside a cell (the pdf vanishing at the horizon) then
/// costs an error that halves with each level instead of a fixed O(h) bias.
fn integrate_cell(
    f: &(impl Fn(f64, f64) -> f64 + Sync),
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    sub: usize,
    depth: u32,
) -> f64 {
    let n = sub + 1;
    let mut vals = vec![0.0; n * n];
    // Edge points are nudged inside the cell: the map's Jacobian may be discontinuous
    // across a cell boundary (the two halves of a zoomed SphereMap), and each cell must see
    // its own one-sided limit.
    let at = |k: usize| (k as f64 / sub as f64).clamp(1e-9, 1.0 - 1e-9);
    for a in 0..n {
        let x = x0 + (x1 - x0) * at(a);
        for b in 0..n {
            let y = y0 + (y1 - y0) * at(b);
            vals[a * n + b] = f(x, y);
        }
    }
    let w = |k: usize, m: usize| -> f64 {
        if k == 0 || k == m {
            1.0
        } else if k % 2 == 1 {
            4.0
        } else {
            2.0
        }
    };
    let area = (x1 - x0) * (y1 - y0);
    let mut fine = 0.0;
    for a in 0..n {
        for b in 0..n {
            fine += w(a, sub) * w(b, sub) * vals[a * n + b];
        }
    }
    fine *= area / (9.0 * (sub * sub) as f64);
    let half = sub / 2;
    let mut coarse = 0.0;
    for (ka, a) in [0, half, sub].iter().enumerate() {
        for (kb, b) in [0, half, sub].iter().enumerate() {
            coarse += w(ka, 2) * w(kb, 2) * vals[a * n + b];
        }
    }
    coarse *= area / 36.0;
    if depth == 0 || (fine - coarse).abs() <= 1e-8 + 1e-5 * fine.abs() {
        return fine;
    }
    let (xm, ym) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    integrate_cell(f, (x0, xm), (y0, ym), sub, depth - 1)
        + integrate_cell(f, (xm, x1), (y0, ym), sub, depth - 1)
        + integrate_cell(f, (x0, xm), (ym, y1), sub, depth - 1)
        + integrate_cell(f, (xm, x1), (ym, y1), sub, depth - 1)
}

/// Šidák-corrected per-test significance for `tests` tests at overall level `alpha`.
pub fn corrected_significance(alpha: f64, tests: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / tests.max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rng::RandomSource;
    use crate::math::warp::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};

    #[test]
    fn accepts_a_correct_sampler_and_rejects_a_wrong_pdf() {
        let cfg = Chi2Config {
            samples: 200_000,
            ..Default::default()
        };
        let map = SphereMap::standard();
        let ok = chi2_test(
            &map,
            &cfg,
            |r| Some(square_to_cosine_hemisphere(r.next_2d())),
            cosine_hemisphere_pdf,
        );
        assert!(ok.passes(1e-3), "{}", ok.summary());
        assert!((ok.pdf_integral - 1.0).abs() < 1e-4);
        // Claiming a uniform hemisphere density for cosine samples must fail.
        let bad = chi2_test(
            &map,
            &cfg,
            |r| Some(square_to_cosine_hemisphere(r.next_2d())),
            |d| {
                if d.z > 0.0 {
                    0.5 / std::f64::consts::PI
                } else {
                    0.0
                }
            },
        );
        assert!(!bad.passes(1e-3), "{}", bad.summary());
    }

    #[test]
    fn missing_mass_is_a_cell() {
        // A sampler that fails half the time, with a pdf integrating to 1/2.
        let cfg = Chi2Config {
            samples: 100_000,
            ..Default::default()
        };
        let out = chi2_test(
            &SphereMap::standard(),
            &cfg,
            |r| {
                if r.next_f64() < 0.5 {
                    None
                } else {
                    Some(square_to_cosine_hemisphere(r.next_2d()))
                }
            },
            |d| 0.5 * cosine_hemisphere_pdf(d),
        );
        assert!(out.passes(1e-3), "{}", out.summary());
        // Claiming the full pdf while failing half the time is detected.
        let out = chi2_test(
            &SphereMap::standard(),
            &cfg,
            |r| {
                if r.next_f64() < 0.5 {
                    None
                } else {
                    Some(square_to_cosine_hemisphere(r.next_2d()))
                }
            },
            cosine_hemisphere_pdf,
        );
        assert!(!out.passes(1e-3), "{}", out.summary());
    }
}
