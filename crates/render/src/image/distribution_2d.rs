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
//!
//! **Guide tables** (the cutpoint method, Chen & Asau 1974; Devroye 1986 §III.2.4): with
//! each CDF of n cells, a table of n + 1 indices, guide[g] = the cell of u = g/n, bounds the
//! search for a u in [g/n, (g+1)/n) to the cells guide[g] … guide[g + 1] — usually one or
//! two — instead of a binary search through the whole row (9 dependent loads at 512
//! columns, the largest part of an environment-map sample's time before). The cell found
//! is the binary search's, bit for bit (tested): the inversion, and with it a
//! low-discrepancy sampler's stratification, is unchanged.

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
    /// The guide of the marginal (`height + 1` entries) and of each row (`width + 1`
    /// entries a row).
    marginal_guide: Vec<u32>,
    conditional_guide: Vec<u32>,
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

/// The guide of a CDF of n cells: entry g is `find_interval(cdf, g/n)` (g < n), entry n the
/// last cell.
fn build_guide(cdf: &[f64], guide: &mut [u32]) {
    let n = cdf.len() - 1;
    for (g, entry) in guide.iter_mut().enumerate().take(n) {
        *entry = find_interval(cdf, g as f64 / n as f64) as u32;
    }
    guide[n] = (n - 1) as u32;
}

/// [`find_interval`] for u ∈ [0, 1) through the CDF's guide: the same cell.
#[inline]
fn find_interval_guided(cdf: &[f64], guide: &[u32], u: f64) -> usize {
    let n = cdf.len() - 1;
    let g = ((u * n as f64) as usize).min(n - 1);
    let (lo, hi) = (guide[g] as usize, guide[g + 1] as usize);
    // The cell lies in lo ..= hi: the first entry above u among cdf[lo + 1 ..= hi].
    lo + cdf[lo + 1..=hi].partition_point(|&c| c <= u)
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
        let mut marginal_guide = vec![0; height + 1];
        build_guide(&marginal, &mut marginal_guide);
        let mut conditional_guide = vec![0; height * (width + 1)];
        for (cdf, guide) in conditional
            .chunks(width + 1)
            .zip(conditional_guide.chunks_mut(width + 1))
        {
            build_guide(cdf, guide);
        }
        Distribution2D {
            width,
            height,
            marginal,
            conditional,
            marginal_guide,
            conditional_guide,
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
        self.sample_batch(&[u], [true])[0]
    }

    /// [`sample`](Self::sample) for the lanes of `set` at once (the others `None`), each
    /// lane's cell the one `sample` draws. The stages run across all lanes before the next
    /// begins: a row's guide and CDF entries are usually not in the nearest caches (at
    /// 512 × 256 the rows' CDFs and guides are 1.5 MB), and loads that do not wait on each
    /// other's results let their misses overlap instead of queueing one lane behind
    /// another.
    #[inline]
    pub fn sample_batch<const N: usize>(
        &self,
        u: &[DVec2; N],
        set: [bool; N],
    ) -> [Option<(usize, usize, f64, DVec2)>; N] {
        let mut out = [None; N];
        if self.total <= 0.0 {
            return out;
        }
        let clamp = |v: f64| {
            if v.is_finite() {
                v.clamp(0.0, ONE_MINUS_EPS)
            } else {
                0.0
            }
        };
        let (w, w1) = (self.width, self.width + 1);
        // The rows, from the marginal (small: it stays in cache).
        let (mut ux, mut uy, mut y) = ([0.0; N], [0.0; N], [0usize; N]);
        for i in 0..N {
            if set[i] {
                (ux[i], uy[i]) = (clamp(u[i].x), clamp(u[i].y));
                y[i] = find_interval_guided(&self.marginal, &self.marginal_guide, uy[i]);
            }
        }
        // Each lane's guide entries in its row: loads independent of each other.
        let (mut lo, mut hi) = ([0usize; N], [0usize; N]);
        for i in 0..N {
            if set[i] {
                let g = ((ux[i] * w as f64) as usize).min(w - 1);
                let guide = &self.conditional_guide[y[i] * w1..(y[i] + 1) * w1];
                (lo[i], hi[i]) = (guide[g] as usize, guide[g + 1] as usize);
            }
        }
        // The cell in lo ..= hi (usually lo itself: no load), as `find_interval_guided`.
        let mut x = [0usize; N];
        for i in 0..N {
            if set[i] {
                x[i] = lo[i] + self.row(y[i])[lo[i] + 1..=hi[i]].partition_point(|&c| c <= ux[i]);
            }
        }
        for i in 0..N {
            if set[i] {
                let (m0, m1) = (self.marginal[y[i]], self.marginal[y[i] + 1]);
                let row = self.row(y[i]);
                let (c0, c1) = (row[x[i]], row[x[i] + 1]);
                let frac = DVec2::new(
                    ((ux[i] - c0) / (c1 - c0)).clamp(0.0, ONE_MINUS_EPS),
                    ((uy[i] - m0) / (m1 - m0)).clamp(0.0, ONE_MINUS_EPS),
                );
                out[i] = Some((x[i], y[i], (m1 - m0) * (c1 - c0), frac));
            }
        }
        out
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

    /// The guided search finds the binary search's cell for every u: on CDFs with empty
    /// cells (repeated entries), one dominant cell, uniform ones, at the guide's own
    /// boundaries g/n and one ulp either side, and at random u.
    #[test]
    fn the_guide_finds_the_binary_searchs_cell() {
        let mut rng = Pcg32::new(5, 2);
        let rows: Vec<Vec<f64>> = vec![
            vec![1.0, 0.0, 0.0, 3.0, 0.0, 2.0, 0.0],
            vec![0.0, 0.0, 0.0, 0.0, 1.0],
            vec![1e-300, 1.0, 1e-300],
            vec![1.0; 512],
            (0..513)
                .map(|k| ((k * 37) % 11) as f64 * (k % 3) as f64)
                .collect(),
            vec![5.0],
        ];
        for w in rows {
            let n = w.len();
            let mut cdf = vec![0.0; n + 1];
            build_cdf(w.iter().copied(), &mut cdf);
            let mut guide = vec![0; n + 1];
            build_guide(&cdf, &mut guide);
            let mut us: Vec<f64> = (0..n)
                .flat_map(|g| {
                    let u = g as f64 / n as f64;
                    [
                        u,
                        f64::from_bits(u.to_bits().saturating_sub(1)),
                        f64::from_bits(u.to_bits() + 1),
                    ]
                })
                .chain(cdf.iter().copied())
                .chain((0..2000).map(|_| rng.next_f64()))
                .collect();
            us.push(ONE_MINUS_EPS);
            for u in us.into_iter().filter(|u| (0.0..1.0).contains(u)) {
                assert_eq!(
                    find_interval_guided(&cdf, &guide, u),
                    find_interval(&cdf, u),
                    "n {n}, u {u}"
                );
            }
        }
    }

    /// The batch draws each chosen lane's cell as `sample` does one at a time (the same
    /// cell, probability and position, to the bit) and nothing for the other lanes.
    #[test]
    fn a_batch_draws_what_single_draws_do() {
        let (w, h) = (37, 19);
        let weights: Vec<f64> = (0..w * h)
            .map(|k| {
                if k % 7 == 3 {
                    0.0
                } else {
                    ((k * 31) % 17) as f64 + 1e-3
                }
            })
            .collect();
        let d = Distribution2D::new(w, h, &weights);
        let mut rng = Pcg32::new(3, 1);
        for round in 0..500 {
            let us: [DVec2; 8] = std::array::from_fn(|_| rng.next_2d());
            let set: [bool; 8] = std::array::from_fn(|i| (round + i) % 3 != 0);
            let batch = d.sample_batch(&us, set);
            for i in 0..8 {
                if set[i] {
                    assert_eq!(batch[i], d.sample(us[i]));
                    // The cell of the plain binary searches.
                    let y = find_interval(&d.marginal, us[i].y);
                    let x = find_interval(d.row(y), us[i].x);
                    let (bx, by, _, _) = batch[i].unwrap();
                    assert_eq!((bx, by), (x, y));
                } else {
                    assert!(batch[i].is_none());
                }
            }
        }
        let empty = Distribution2D::new(2, 1, &[0.0, 0.0]);
        assert_eq!(
            empty.sample_batch(&[DVec2::splat(0.5); 2], [true; 2]),
            [None; 2]
        );
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
