//! One row of an albedo table at a material's own α: what the compensated models read at
//! every call, interpolated once when the material is built.
//!
//! [`AlbedoTable`](super::albedo_tables::AlbedoTable) is bilinear in (μ, α); a material has
//! one α, so the blend of the two rows around it is made once ([`AlbedoTable::row_at`]) and a
//! lookup is then one square root, one index and one multiply–add: the same function as the
//! table's `albedo(μ, α)` (the two interpolations commute; the values agree to rounding,
//! tested), without the `powf` that finds the row. Its sampler draws from the blended row
//! directly: the density is the table's exact one (the mixture of the two rows' densities
//! weighted by their mass is the blend's own density), one random number fewer.
//!
//! [`SquareNodes`] is the piecewise-linear interpolant on nodes μ_k = (k/(N − 1))² that both
//! the albedo rows and the compensated dielectric's reflection shares use, on the same 32
//! nodes, so that one search ([`Located`]) serves both lookups of a direction.

use super::albedo_tables::{AlbedoTable, MU_NODES};
use crate::math::rng::RandomSource;
use crate::math::INV_PI;

/// A function of μ ∈ [0, 1], linear in μ between the nodes μ_k = (k/(N − 1))², kept as node
/// values and slopes so that a lookup needs no division.
#[derive(Clone, Debug, PartialEq)]
pub struct SquareNodes<const N: usize> {
    values: [f64; N],
    /// (values[k + 1] − values[k]) / (μ_{k+1} − μ_k); the last entry repeats the one before.
    slopes: [f64; N],
}

/// A μ located among the nodes of a [`SquareNodes`]: its interval k and μ − μ_k.
#[derive(Clone, Copy, Debug)]
pub struct Located {
    k: usize,
    offset: f64,
}

/// μ of node k of N.
#[inline(always)]
pub const fn square_node<const N: usize>(k: usize) -> f64 {
    let x = k as f64 * (1.0 / (N - 1) as f64);
    x * x
}

/// Buckets of μ that find a lookup's interval without a square root: bucket b covers
/// [b/B, (b + 1)/B), and with B = 4096 no bucket holds more than one node (the closest
/// nodes, μ₀ = 0 and μ₁ = 1/(N − 1)², are at least 1/1024 apart for N ≤ 33).
const BUCKETS: usize = 4096;

impl<const N: usize> SquareNodes<N> {
    /// The interpolant through `values` at the nodes.
    pub fn new(values: [f64; N]) -> Self {
        let mut slopes = [0.0; N];
        for k in 0..N - 1 {
            let (p, q) = (square_node::<N>(k), square_node::<N>(k + 1));
            slopes[k] = (values[k + 1] - values[k]) / (q - p);
        }
        slopes[N - 1] = slopes[N - 2];
        SquareNodes { values, slopes }
    }

    /// The nodes μ_k.
    const NODES: [f64; N] = {
        let mut n = [0.0; N];
        let mut k = 0;
        while k < N {
            n[k] = square_node::<N>(k);
            k += 1;
        }
        n
    };

    /// Per bucket of μ, the last interval (≤ N − 2) whose node is at or below the bucket's
    /// start: the lookup's interval is it or the next.
    const FIRST: [u8; BUCKETS] = {
        assert!(N >= 2 && N <= 33);
        let mut t = [0u8; BUCKETS];
        let mut b = 0;
        let mut k = 0;
        while b < BUCKETS {
            let start = b as f64 / BUCKETS as f64;
            while k + 1 < N - 1 && square_node::<N>(k + 1) <= start {
                k += 1;
            }
            t[b] = k as u8;
            b += 1;
        }
        t
    };

    /// The value at μ (clamped to [0, 1]): linear in μ on the interval [μ_k, μ_{k+1}]
    /// that holds it, found by its bucket (one load and one comparison, no square root).
    #[inline(always)]
    pub fn at(&self, mu: f64) -> f64 {
        self.at_located(Self::locate(mu))
    }

    /// Where μ (clamped to [0, 1]) falls among the nodes: what [`at_located`](Self::at_located)
    /// reads, so that functions on the same nodes share one search.
    #[inline(always)]
    pub fn locate(mu: f64) -> Located {
        let mu = mu.clamp(0.0, 1.0);
        let b = crate::math::cell_index(mu * BUCKETS as f64, BUCKETS);
        let mut k = Self::FIRST[b] as usize;
        if k < N - 2 && mu >= Self::NODES[k + 1] {
            k += 1;
        }
        Located {
            k,
            offset: mu - Self::NODES[k],
        }
    }

    /// The value at a μ found by [`locate`](Self::locate) on nodes of the same count.
    #[inline(always)]
    pub fn at_located(&self, at: Located) -> f64 {
        self.values[at.k] + at.offset * self.slopes[at.k]
    }

    /// The node values.
    pub fn values(&self) -> &[f64; N] {
        &self.values
    }
}

/// E(μ) at one α, with what the compensation lobe's density and sampler need.
#[derive(Clone, Debug)]
pub struct AlbedoRow {
    e: SquareNodes<MU_NODES>,
    /// E_avg = 2 ∫ E μ dμ of the interpolant.
    average: f64,
    /// 1/(π (1 − E_avg)), 0 when nothing is missing: the lobe density's normalization.
    density_norm: f64,
    /// The cumulative ∫ (1 − E) μ dμ over the μ intervals.
    cumulative: [f64; MU_NODES - 1],
}

impl AlbedoRow {
    /// The row of node values `e`, with its average and cumulative masses (the blends of the
    /// table's, which are linear in E).
    pub(super) fn new(e: [f64; MU_NODES], average: f64, cumulative: [f64; MU_NODES - 1]) -> Self {
        let missing = 1.0 - average;
        AlbedoRow {
            e: SquareNodes::new(e),
            average,
            density_norm: if missing > 1e-12 {
                INV_PI / missing
            } else {
                0.0
            },
            cumulative,
        }
    }

    /// E(μ): the table's `albedo(μ, α)` at this row's α.
    #[inline(always)]
    pub fn albedo(&self, mu: f64) -> f64 {
        self.e.at(mu)
    }

    /// 1 − E(μ), at least 0: the energy single scattering loses.
    #[inline(always)]
    pub fn missing(&self, mu: f64) -> f64 {
        self.missing_located(Self::locate(mu))
    }

    /// Where μ falls among the row's nodes (μ_k = (k/31)²), for
    /// [`missing_located`](Self::missing_located) and for other functions tabulated on the
    /// same nodes.
    #[inline(always)]
    pub fn locate(mu: f64) -> Located {
        SquareNodes::<MU_NODES>::locate(mu)
    }

    /// [`missing`](Self::missing) at a located μ.
    #[inline(always)]
    pub fn missing_located(&self, at: Located) -> f64 {
        (1.0 - self.e.at_located(at)).max(0.0)
    }

    /// E_avg.
    #[inline(always)]
    pub fn average(&self) -> f64 {
        self.average
    }

    /// Solid-angle density of [`sample_mu`](Self::sample_mu) with a uniform azimuth for a
    /// direction with cos θ = μ: (1 − E(μ)) μ / (π (1 − E_avg)) [KC17]; 0 when nothing is
    /// missing. The table's `lobe_density(μ, α)`.
    #[inline(always)]
    pub fn lobe_density(&self, mu: f64) -> f64 {
        self.lobe_density_of_missing(self.missing(mu), mu)
    }

    /// [`lobe_density`](Self::lobe_density) from 1 − E(μ) already read.
    #[inline(always)]
    pub fn lobe_density_of_missing(&self, missing: f64, mu: f64) -> f64 {
        if mu <= 0.0 {
            return 0.0;
        }
        missing * mu * self.density_norm
    }

    /// Draws μ with density 2 (1 − E(μ)) μ / (1 − E_avg) on [0, 1]: an interval by its
    /// cumulative mass, then μ ∝ μ on it by rejection against the linear 1 − E (acceptance
    /// at least ½).
    pub fn sample_mu(&self, rng: &mut dyn RandomSource) -> Option<f64> {
        let last = MU_NODES - 2;
        let mass = self.cumulative[last];
        if !(mass > 0.0) {
            return None;
        }
        sample_in_row(&self.cumulative, self.e.values(), rng)
    }
}

/// Draws μ from one tabulated row: an interval by the row's `cumulative` masses of
/// (1 − E) μ, then μ ∝ μ on it by rejection against the linear 1 − E between the interval's
/// nodes `e[k]`, `e[k + 1]` (acceptance at least ½) — the one sampler of
/// [`AlbedoRow::sample_mu`] and [`AlbedoTable::sample_mu`].
pub(super) fn sample_in_row(
    cumulative: &[f64],
    e: &[f64],
    rng: &mut dyn RandomSource,
) -> Option<f64> {
    let last = MU_NODES - 2;
    let target = rng.next_f64() * cumulative[last];
    let k = cumulative.partition_point(|&c| c <= target).min(last);
    let node = |k: usize| {
        let x = k as f64 / (MU_NODES - 1) as f64;
        x * x
    };
    let (p, q) = (node(k), node(k + 1));
    let (lp, lq) = (1.0 - e[k], 1.0 - e[k + 1]);
    let top = lp.max(lq);
    if !(top > 0.0) {
        return None;
    }
    for _ in 0..200 {
        let mu = (p * p + rng.next_f64() * (q * q - p * p)).sqrt();
        let l = lp + (lq - lp) * (mu - p) / (q - p);
        if rng.next_f64() * top < l {
            return Some(mu);
        }
    }
    None
}

impl AlbedoTable {
    /// The row at `alpha`: the blend of the two rows around it, as `albedo(μ, alpha)`,
    /// `average(alpha)`, `lobe_density(μ, alpha)` and `sample_mu(alpha, …)` blend them.
    pub fn row_at(&self, alpha: f64) -> AlbedoRow {
        let (j, t) = Self::row_of(alpha);
        let blend = |a: f64, b: f64| a + t * (b - a);
        let e = std::array::from_fn(|k| blend(self.entry(j, k), self.entry(j + 1, k)));
        let cumulative = std::array::from_fn(|k| {
            blend(self.cumulative_mass(j, k), self.cumulative_mass(j + 1, k))
        });
        AlbedoRow::new(e, self.average(alpha), cumulative)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rng::Pcg32;
    use crate::microfacet::{Ggx, Masking, Ndf};
    use crate::models::multiple_scattering::albedo_tables::TableFresnel;

    /// The row is the table at its α: E, the lobe density and E_avg to rounding, at random μ
    /// and α between and on the rows; its samples follow its density (a histogram of μ
    /// against the density's integral per bin).
    #[test]
    fn the_row_is_the_table_at_its_alpha() {
        let ndf = Ndf::Ggx(Ggx::isotropic(1.0).unwrap());
        for fresnel in [TableFresnel::One, TableFresnel::Dielectric(1.5)] {
            let table = AlbedoTable::shared(&ndf, Masking::SmithCorrelated, fresnel).unwrap();
            let mut rng = Pcg32::new(7, 3);
            for alpha in [0.0, 0.02, 0.3, 0.77, 1.5, 9.9, 10.0] {
                let row = table.row_at(alpha);
                assert!((row.average() - table.average(alpha)).abs() < 1e-15);
                for _ in 0..500 {
                    let mu = rng.next_f64();
                    let (a, b) = (row.albedo(mu), table.albedo(mu, alpha));
                    assert!((a - b).abs() < 1e-13, "α {alpha} μ {mu}: {a} vs {b}");
                    let (a, b) = (row.lobe_density(mu), table.lobe_density(mu, alpha));
                    assert!(
                        (a - b).abs() < 1e-12 * (1.0 + b),
                        "α {alpha} μ {mu}: {a} vs {b}"
                    );
                }
                for mu in [0.0, 1.0, 0.25] {
                    assert!((row.albedo(mu) - table.albedo(mu, alpha)).abs() < 1e-13);
                }
            }
            // Samples against the density: 20 bins of μ, 200 000 draws.
            let row = table.row_at(0.77);
            let (bins, n) = (20, 200_000);
            let mut count = vec![0usize; bins];
            let mut drawn = 0;
            for _ in 0..n {
                if let Some(mu) = row.sample_mu(&mut rng) {
                    count[((mu * bins as f64) as usize).min(bins - 1)] += 1;
                    drawn += 1;
                }
            }
            assert_eq!(drawn, n, "the sampler gave up");
            let mut chi2 = 0.0;
            for (b, &c) in count.iter().enumerate() {
                // ∫ over the bin of 2π · density · (solid angle element dμ dφ → 2π dμ).
                let (lo, hi) = (b as f64 / bins as f64, (b + 1) as f64 / bins as f64);
                let steps = 200;
                let expected: f64 = (0..steps)
                    .map(|s| {
                        let mu = lo + (s as f64 + 0.5) * (hi - lo) / steps as f64;
                        2.0 * std::f64::consts::PI * row.lobe_density(mu) * (hi - lo) / steps as f64
                    })
                    .sum::<f64>()
                    * n as f64;
                chi2 += (c as f64 - expected).powi(2) / expected;
            }
            // 19 degrees of freedom: p = 1e-4 at 49.
            assert!(chi2 < 49.0, "{fresnel:?}: chi2 {chi2}");
        }
    }

    /// The bucketed interval search gives the interpolant of the square-root index (the
    /// former lookup) to rounding, at random μ and at every node and its neighbours.
    #[test]
    fn bucketed_lookups_are_the_square_root_lookups() {
        fn check<const N: usize>() {
            let f = SquareNodes::<N>::new(std::array::from_fn(|k| ((k * 7919) % 13) as f64));
            let by_root = |mu: f64| {
                let k = ((mu.sqrt() * (N - 1) as f64) as usize).min(N - 2);
                f.values[k] + (mu - square_node::<N>(k)) * f.slopes[k]
            };
            let mut mus: Vec<f64> = (0..=100_000).map(|i| i as f64 / 100_000.0).collect();
            for k in 0..N {
                let m = square_node::<N>(k);
                mus.extend([m, m.next_up(), m.next_down()].map(|x| x.clamp(0.0, 1.0)));
            }
            for mu in mus {
                let (a, b) = (f.at(mu), by_root(mu));
                assert!(
                    (a - b).abs() <= 1e-13 * (1.0 + b.abs()),
                    "N {N} μ {mu}: {a} vs {b}"
                );
            }
        }
        check::<5>();
        check::<32>();
        check::<33>();
    }

    #[test]
    fn square_nodes_interpolate_linearly_in_mu() {
        let f = SquareNodes::<5>::new([0.0, 1.0, 4.0, 2.0, 2.0]);
        assert_eq!(f.at(0.0), 0.0);
        assert!((f.at(1.0 / 16.0) - 1.0).abs() < 1e-15);
        assert!((f.at(0.5 * (1.0 / 16.0 + 0.25)) - 2.5).abs() < 1e-14);
        assert_eq!(f.at(1.0), 2.0);
        assert_eq!(f.at(7.0), 2.0);
        assert_eq!(f.at(-1.0), 0.0);
    }
}
