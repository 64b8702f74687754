//! A piecewise-constant distribution over a grid of cells with non-negative weights, sampled
//! by inversion: a marginal CDF picks the row, that row's conditional CDF the column (the
//! construction of pbrt-v4's `PiecewiseConstant2D`, PBR book 4th ed. §A.5.2, and the role of
//! Mitsuba 3's `Hierarchical2D` in its `envmap`).
//!
//! The probability of a cell is read from the same CDF entries the sampler inverts, so
//! [`Distribution2D::pmf`] and [`Distribution2D::sample`] agree to the last bit. The
//! fractional position inside the chosen cell is returned too, uniformly distributed in
//! [0, 1)², so a caller can place the sample inside the cell with whatever measure it likes
//! (the environment map draws the position inside a bilinear patch from it).
//!
//! CDFs are f64: at 8k×4k cells a float CDF would lose the probabilities of dim cells.

use glam::DVec2;

/// Largest f64 below 1.
const ONE_MINUS_EPS: f64 = 1.0 - f64::EPSILON / 2.0;

#[derive(Clone, Debug)]
pub struct Distribution2D {
    width: usize,
    height: usize,
    /// `height + 1` entries, 0 … 1.
    marginal: Vec<f64>,
    /// `height` rows of `width + 1` entries, each 0 … 1.
    conditional: Vec<f64>,
    total: f64,
}

/// Normalized running sum of `w` into `cdf` (`w.len() + 1` entries). Returns the sum;
/// when it is 0 the CDF is made uniform (such a row is never chosen).
fn build_cdf(w: impl ExactSizeIterator<Item = f64>, cdf: &mut [f64]) -> f64 {
    let n = w.len();
    cdf[0] = 0.0;
    let mut s = 0.0;
    for (k, v) in w.enumerate() {
        s += v;
        cdf[k + 1] = s;
    }
    if s > 0.0 {
        let inv = 1.0 / s;
        for c in cdf.iter_mut() {
            *c *= inv;
        }
    } else {
        for (k, c) in cdf.iter_mut().enumerate() {
            *c = k as f64 / n as f64;
        }
    }
    cdf[n] = 1.0;
    s
}

/// Index k with cdf[k] ≤ u < cdf[k + 1] (u < 1 = cdf[n], so such a cell has positive mass).
#[inline]
fn find_interval(cdf: &[f64], u: f64) -> usize {
    (cdf.partition_point(|&c| c <= u) - 1).min(cdf.len() - 2)
}

impl Distribution2D {
    /// A distribution over `width × height` cells (row-major `weights`). Negative and
    /// non-finite weights count as 0.
    pub fn new(width: usize, height: usize, weights: &[f64]) -> Self {
        assert!(width > 0 && height > 0 && weights.len() == width * height);
        let clean = |v: f64| if v.is_finite() && v > 0.0 { v } else { 0.0 };
        let mut conditional = vec![0.0; height * (width + 1)];
        let mut row_sums = Vec::with_capacity(height);
        for y in 0..height {
            let row = &weights[y * width..(y + 1) * width];
            let cdf = &mut conditional[y * (width + 1)..(y + 1) * (width + 1)];
            row_sums.push(build_cdf(row.iter().map(|&v| clean(v)), cdf));
        }
        let mut marginal = vec![0.0; height + 1];
        let total = build_cdf(row_sums.into_iter(), &mut marginal);
        Distribution2D {
            width,
            height,
            marginal,
            conditional,
            total,
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// Sum of the (cleaned) weights; 0 means nothing can be sampled.
    pub fn total(&self) -> f64 {
        self.total
    }

    #[inline]
    fn row(&self, y: usize) -> &[f64] {
        &self.conditional[y * (self.width + 1)..(y + 1) * (self.width + 1)]
    }

    /// Probability of cell (x, y).
    #[inline]
    pub fn pmf(&self, x: usize, y: usize) -> f64 {
        if self.total <= 0.0 || x >= self.width || y >= self.height {
            return 0.0;
        }
        let row = self.row(y);
        (self.marginal[y + 1] - self.marginal[y]) * (row[x + 1] - row[x])
    }

    /// Draws a cell: `u.y` picks the row, `u.x` the column. Returns the cell, its
    /// probability and the position inside it in [0, 1)², or `None` when all weights are 0.
    #[inline]
    pub fn sample(&self, u: DVec2) -> Option<(usize, usize, f64, DVec2)> {
        if self.total <= 0.0 {
            return None;
        }
        let clamp = |v: f64| {
            if v.is_finite() {
                v.clamp(0.0, ONE_MINUS_EPS)
            } else {
                0.0
            }
        };
        let (ux, uy) = (clamp(u.x), clamp(u.y));
        let y = find_interval(&self.marginal, uy);
        let (m0, m1) = (self.marginal[y], self.marginal[y + 1]);
        let row = self.row(y);
        let x = find_interval(row, ux);
        let (c0, c1) = (row[x], row[x + 1]);
        let frac = DVec2::new(
            ((ux - c0) / (c1 - c0)).clamp(0.0, ONE_MINUS_EPS),
            ((uy - m0) / (m1 - m0)).clamp(0.0, ONE_MINUS_EPS),
        );
        Some((x, y, (m1 - m0) * (c1 - c0), frac))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use facette_bsdf::math::rng::{Pcg32, RandomSource};

    #[test]
    fn frequencies_match_the_pmf() {
        let w = [1.0, 0.0, 3.0, 2.0, f64::NAN, -1.0, 0.5, 0.0, 4.5];
        let d = Distribution2D::new(3, 3, &w);
        assert_eq!(d.total(), 11.0);
        let mut counts = [0usize; 9];
        let mut rng = Pcg32::new(1, 0);
        let n = 200_000;
        for _ in 0..n {
            let (x, y, p, f) = d.sample(rng.next_2d()).unwrap();
            assert_eq!(p, d.pmf(x, y));
            assert!(p > 0.0 && (0.0..1.0).contains(&f.x) && (0.0..1.0).contains(&f.y));
            counts[y * 3 + x] += 1;
        }
        for k in 0..9 {
            let expect = w[k].max(0.0) / 11.0;
            let expect = if expect.is_nan() { 0.0 } else { expect };
            assert!((d.pmf(k % 3, k / 3) - expect).abs() < 1e-15);
            let freq = counts[k] as f64 / n as f64;
            assert!((freq - expect).abs() < 4e-3, "cell {k}: {freq} vs {expect}");
        }
    }

    #[test]
    fn extremes_and_empty() {
        let d = Distribution2D::new(2, 2, &[0.0, 1.0, 1.0, 0.0]);
        for u in [
            DVec2::ZERO,
            DVec2::ONE,
            DVec2::splat(f64::NAN),
            DVec2::splat(-3.0),
        ] {
            let (x, y, p, _) = d.sample(u).unwrap();
            assert!(p > 0.0 && d.pmf(x, y) == p);
        }
        let empty = Distribution2D::new(2, 1, &[0.0, 0.0]);
        assert!(empty.sample(DVec2::splat(0.5)).is_none());
        assert_eq!(empty.pmf(0, 0), 0.0);
    }
}
