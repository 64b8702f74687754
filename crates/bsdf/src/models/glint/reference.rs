//! Ground truth for the patch NDF: the slope histogram of the interpolated normal map inside
//! a footprint  [CCM19 eq. 8; Fig. 5 "built using normal map binning"], seen through the
//! near-specular microsurface of roughness σ_ε that the paper's reference renders use
//! (§5.2.2): positions u ~ k_P, slope = interpolated map slope at u plus a N(0, σ_ε² I)
//! micro-slope. Compared with the mixture's P22_P integrated over the same bins.

use super::footprint::Footprint;
use super::lobe::standard_normal_2d;
use super::normal_map::NormalMap;
use super::patch_ndf::PatchNdf;
use crate::math::rng::{mix_seed, Pcg32, RandomSource};
use crate::math::Vec2;
use rayon::prelude::*;

/// A regular grid of bins over a rectangle of slope space.
#[derive(Clone, Copy, Debug)]
pub struct SlopeGrid {
    pub min: [f64; 2],
    pub max: [f64; 2],
    pub bins: usize,
}

impl SlopeGrid {
    /// Square grid centred on `center` with half-width `half`.
    pub fn centred(center: [f64; 2], half: f64, bins: usize) -> Self {
        SlopeGrid {
            min: [center[0] - half, center[1] - half],
            max: [center[0] + half, center[1] + half],
            bins,
        }
    }

    #[inline]
    pub fn bin_of(&self, s: [f64; 2]) -> Option<usize> {
        let fx = (s[0] - self.min[0]) / (self.max[0] - self.min[0]);
        let fy = (s[1] - self.min[1]) / (self.max[1] - self.min[1]);
        if !(0.0..1.0).contains(&fx) || !(0.0..1.0).contains(&fy) {
            return None;
        }
        let n = self.bins;
        Some(((fy * n as f64) as usize).min(n - 1) * n + ((fx * n as f64) as usize).min(n - 1))
    }

    pub fn bin_size(&self) -> [f64; 2] {
        [
            (self.max[0] - self.min[0]) / self.bins as f64,
            (self.max[1] - self.min[1]) / self.bins as f64,
        ]
    }
}

/// Probability per bin of the reference slopes (Monte Carlo with `samples` positions).
pub fn reference_histogram(
    map: &NormalMap,
    footprint: Footprint,
    roughness_floor: f64,
    grid: &SlopeGrid,
    samples: usize,
    seed: u64,
) -> Vec<f64> {
    let fp = footprint.sanitized();
    let [l11, l21, l22] = super::lobe::cholesky2(fp.cov);
    const CHUNKS: usize = 64;
    let per = samples.div_ceil(CHUNKS);
    let parts: Vec<Vec<u32>> = (0..CHUNKS)
        .into_par_iter()
        .map(|c| {
            let mut rng = Pcg32::new(mix_seed(seed, c as u64), 0x72656620);
            let mut h = vec![0u32; grid.bins * grid.bins];
            for _ in 0..per {
                let (zx, zy) = standard_normal_2d(rng.next_2d());
                let u = fp.center + Vec2::new(l11 * zx, l21 * zx + l22 * zy);
                let s = map.interpolated_slope(u);
                let (ex, ey) = standard_normal_2d(rng.next_2d());
                let s = [s[0] + roughness_floor * ex, s[1] + roughness_floor * ey];
                if let Some(b) = grid.bin_of(s) {
                    h[b] += 1;
                }
            }
            h
        })
        .collect();
    let total = (per * CHUNKS) as f64;
    let mut out = vec![0.0; grid.bins * grid.bins];
    for p in parts {
        for (o, v) in out.iter_mut().zip(p) {
            *o += v as f64 / total;
        }
    }
    out
}

/// Probability per bin of the patch NDF: ∫ P22_P over each bin by the midpoint rule on
/// `sub`×`sub` points per bin.
pub fn patch_ndf_histogram(ndf: &PatchNdf, grid: &SlopeGrid, sub: usize) -> Vec<f64> {
    let n = grid.bins;
    let [bw, bh] = grid.bin_size();
    (0..n * n)
        .into_par_iter()
        .map(|k| {
            let (bx, by) = (k % n, k / n);
            let mut acc = 0.0;
            for j in 0..sub {
                for i in 0..sub {
                    let s = [
                        grid.min[0] + (bx as f64 + (i as f64 + 0.5) / sub as f64) * bw,
                        grid.min[1] + (by as f64 + (j as f64 + 0.5) / sub as f64) * bh,
                    ];
                    acc += ndf.p22(s);
                }
            }
            acc * bw * bh / (sub * sub) as f64
        })
        .collect()
}

/// Total variation distance ½ Σ |p − q| (0: identical, 1: disjoint).
pub fn total_variation(p: &[f64], q: &[f64]) -> f64 {
    0.5 * p.iter().zip(q).map(|(a, b)| (a - b).abs()).sum::<f64>()
}
