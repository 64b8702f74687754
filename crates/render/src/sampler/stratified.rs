//! Jittered stratified sampling, per dimension, without stored tables.
//!
//! Each dimension of a pixel's samples is stratified on its own: in 1D the spp samples
//! fill spp equal strata, one each; in 2D they fill a grid of sx × sy cells with
//! sx = ⌊√spp⌋ and sy = ⌈spp / sx⌉ (sx · sy ≥ spp, so every sample has its own cell; when
//! spp is not a product some cells stay empty). Which sample takes which stratum is a
//! pseudo-random permutation keyed by (seed, pixel, dimension) — Kensler's hash
//! permutation (`hash::permute`, Kensler 2013, "Correlated Multi-Jittered Sampling") — so
//! the dimensions are not correlated with each other (the "padding" of stratified patterns,
//! Pharr, Jakob & Humphreys, "Physically Based Rendering", 4th ed., §8.5), and the jitter
//! inside a stratum is a hash of the same key and the sample number. Nothing is stored
//! per pixel: every value is a pure function of (seed, pixel, sample number, dimension).
//!
//! Sample numbers at or beyond the spp given (a caller exceeding it) start another round
//! of strata with a fresh permutation. The strata count is capped at 2^30 (far beyond any
//! render), which keeps sx · sy below the 2^32 that the permutation accepts.

use super::hash::{hash_unit, permute, ONE_MINUS_EPSILON};
use facette_bsdf::math::rng::mix_seed;
use glam::DVec2;

/// Cap on the strata per dimension.
const MAX_STRATA: u64 = 1 << 30;

/// Domain separation of the hashes (arbitrary odd constants).
const STRATIFIED_TAG: u64 = 0x57ea_7a1f_0000_0007;
const JITTER_TAG: u64 = 0x01f7_7e20_0000_0009;

/// The strata of one render: built once from the total sample count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Strata {
    seed: u64,
    /// Strata in 1D: spp, capped.
    n: u64,
    /// The 2D grid: sx columns, sy rows.
    sx: u64,
    sy: u64,
}

impl Strata {
    pub(crate) fn new(seed: u64, spp: usize) -> Strata {
        let n = (spp as u64).clamp(1, MAX_STRATA);
        let sx = n.isqrt();
        let sy = n.div_ceil(sx);
        Strata { seed, n, sx, sy }
    }

    /// The state of one camera sample.
    pub(crate) fn start(&self, x: usize, y: usize, sample_index: u64) -> StrataSample {
        let pixel = mix_seed(mix_seed(self.seed ^ STRATIFIED_TAG, x as u64), y as u64);
        StrataSample {
            strata: *self,
            pixel_key: mix_seed(pixel, sample_index / self.n),
            s: (sample_index % self.n) as u32,
        }
    }
}

/// One camera sample of a [`Strata`] layout.
#[derive(Clone, Debug)]
pub(crate) struct StrataSample {
    strata: Strata,
    /// Hash of the seed, the pixel and the round of strata.
    pixel_key: u64,
    /// The sample's number in its round (< n).
    s: u32,
}

impl StrataSample {
    /// The permutation key and the jitter hash of dimension `dim`.
    #[inline]
    fn keys(&self, dim: u32) -> (u32, u64) {
        let key = mix_seed(self.pixel_key, dim as u64);
        (key as u32, mix_seed(key ^ JITTER_TAG, self.s as u64))
    }

    /// Dimension `dim`: the sample's stratum among n, jittered.
    pub(crate) fn get_1d(&self, dim: u32) -> f64 {
        let (key, jitter) = self.keys(dim);
        let stratum = permute(self.s, self.strata.n, key);
        ((stratum as f64 + hash_unit(jitter)) / self.strata.n as f64).min(ONE_MINUS_EPSILON)
    }

    /// Dimensions `dim` and `dim + 1`: the sample's cell of the sx × sy grid, jittered.
    pub(crate) fn get_2d(&self, dim: u32) -> DVec2 {
        let (key, jitter) = self.keys(dim);
        let Strata { sx, sy, .. } = self.strata;
        let cell = permute(self.s, sx * sy, key) as u64;
        let (cx, cy) = (cell % sx, cell / sx);
        let (jx, jy) = (hash_unit(jitter), hash_unit(mix_seed(jitter, 1)));
        DVec2::new(
            ((cx as f64 + jx) / sx as f64).min(ONE_MINUS_EPSILON),
            ((cy as f64 + jy) / sy as f64).min(ONE_MINUS_EPSILON),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampler_stratified_grid_shape() {
        for (spp, sx, sy) in [
            (1, 1, 1),
            (2, 1, 2),
            (10, 3, 4),
            (16, 4, 4),
            (17, 4, 5),
            (1000, 31, 33),
        ] {
            let s = Strata::new(0, spp);
            assert_eq!((s.n, s.sx, s.sy), (spp as u64, sx, sy), "spp {spp}");
            assert!(s.sx * s.sy >= s.n);
        }
        let s = Strata::new(0, 0);
        assert_eq!((s.n, s.sx, s.sy), (1, 1, 1));
        let s = Strata::new(0, usize::MAX);
        assert_eq!(s.n, MAX_STRATA);
        assert!(s.sx * s.sy < 1 << 32);
    }

    #[test]
    fn sampler_stratified_non_square_counts() {
        // spp = 10: one value per 1/10 stratum in 1D, ten distinct cells of the 3 × 4 grid.
        let st = Strata::new(3, 10);
        for dim in [0u32, 4] {
            let mut strata = [0; 10];
            let mut cells = [0; 12];
            for s in 0..10 {
                let smp = st.start(2, 9, s);
                strata[(smp.get_1d(dim) * 10.0) as usize] += 1;
                let p = smp.get_2d(dim);
                cells[(p.y * 4.0) as usize * 3 + (p.x * 3.0) as usize] += 1;
            }
            assert!(strata.iter().all(|&c| c == 1), "{strata:?}");
            assert_eq!(cells.iter().filter(|&&c| c == 1).count(), 10, "{cells:?}");
        }
        // A second round (indices 10..20) is stratified too, with another permutation.
        let first: Vec<f64> = (0..10).map(|s| st.start(2, 9, s).get_1d(0)).collect();
        let mut strata = [0; 10];
        for s in 10..20 {
            let v = st.start(2, 9, s).get_1d(0);
            assert!(!first.contains(&v));
            strata[(v * 10.0) as usize] += 1;
        }
        assert!(strata.iter().all(|&c| c == 1));
    }
}
