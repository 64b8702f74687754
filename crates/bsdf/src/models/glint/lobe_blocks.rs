//! The lobes of a map stored by leaf block of the slope hierarchy, in lanes: the 4×4 lobes
//! of a block side by side in two [`F32x8`] per field (mean slope, inverse covariance and
//! the truncated Gaussian's peak), so that the patch NDF's inner loop [CCM19 eq. 9]
//! evaluates a whole block — both truncation tests, the seed weight and the lobe — in lane
//! operations and one exponential per eight lobes, instead of one lobe at a time.
//!
//! A block's lane j holds the texel (j mod 4, ⌊j/4⌋) of the block; lanes past the map's
//! edge (a map whose size is not a multiple of 4) hold a lobe with a NaN mean, which fails
//! every truncation test. 24 bytes per texel: the five numbers of a [`SlopeLobe`] and its
//! peak (stored, since √|Σ⁻¹| in `f32` would lose digits for strongly correlated lobes).

use super::hierarchy::LEAF;
use super::lobe::{SlopeLobe, CUTOFF_R2};
use crate::lanes::{F32x8, Mask, Real};

/// Lobes per block.
pub const BLOCK: usize = LEAF * LEAF;

/// The 16 lobes of one leaf block: rows 0–1 of the block in lanes `[0]`, rows 2–3 in `[1]`.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct LobeBlock {
    mean_x: [F32x8; 2],
    mean_y: [F32x8; 2],
    /// Σ⁻¹ = [[a, b], [b, c]].
    a: [F32x8; 2],
    b: [F32x8; 2],
    c: [F32x8; 2],
    /// The truncated Gaussian's peak value ([`SlopeLobe::peak`]).
    peak: [F32x8; 2],
}

/// Column and row of each lane of a half block, relative to the half's first texel.
const LANE_X: F32x8 = F32x8([0.0, 1.0, 2.0, 3.0, 0.0, 1.0, 2.0, 3.0]);
const LANE_Y: F32x8 = F32x8([0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]);

impl LobeBlock {
    const EMPTY: LobeBlock = LobeBlock {
        mean_x: [F32x8([f32::NAN; 8]); 2],
        mean_y: [F32x8([f32::NAN; 8]); 2],
        a: [F32x8([0.0; 8]); 2],
        b: [F32x8([0.0; 8]); 2],
        c: [F32x8([0.0; 8]); 2],
        peak: [F32x8([0.0; 8]); 2],
    };

    fn set(&mut self, j: usize, l: &SlopeLobe) {
        let (h, k) = (j / 8, j % 8);
        self.mean_x[h].0[k] = l.mean[0];
        self.mean_y[h].0[k] = l.mean[1];
        self.a[h].0[k] = l.inv_cov[0];
        self.b[h].0[k] = l.inv_cov[1];
        self.c[h].0[k] = l.inv_cov[2];
        self.peak[h].0[k] = l.peak() as f32;
    }

    fn get(&self, j: usize) -> SlopeLobe {
        let (h, k) = (j / 8, j % 8);
        SlopeLobe {
            mean: [self.mean_x[h].0[k], self.mean_y[h].0[k]],
            inv_cov: [self.a[h].0[k], self.b[h].0[k], self.c[h].0[k]],
        }
    }

    /// Adds to `acc`, lane by lane, P22_j(s) · e^{−½ m_j} for the block's lobes j whose
    /// slope truncation (m̃ − μ_j)ᵀΣ_j⁻¹(m̃ − μ_j) ≤ R² and seed truncation m_j ≤ R² both
    /// hold, with m_j = d_jᵀ B d_j the seed's squared distance (metric `b`) from the
    /// footprint centre and d_j = `d0` + (column, row) of the seed: the summand of CCM19
    /// eq. 9 before the footprint's scale [`super::footprint::FootprintQuery::weight_scale`].
    /// `b` = 0 weights every seed by 1 (the uniform query). Written once over the lane type:
    /// [`F32x8`] and, in an AVX2 build, `F32x8Avx2` give the same bits.
    #[inline(always)]
    pub fn accumulate<L: BlockLanes>(&self, s: [f32; 2], d0: [f32; 2], b: [f32; 3], acc: &mut L) {
        let r2 = L::splat(CUTOFF_R2);
        let (sx, sy) = (L::splat(s[0] as f64), L::splat(s[1] as f64));
        let [ba, bb, bc] = b.map(|v| L::splat(v as f64));
        for h in 0..2 {
            // The seeds' squared distance from the footprint centre, m_j = d_jᵀ B d_j.
            let dx = L::splat(d0[0] as f64) + L::load(&LANE_X);
            let dy = L::splat(d0[1] as f64 + 2.0 * h as f64) + L::load(&LANE_Y);
            let m = ba * dx * dx + (bb + bb) * dx * dy + bc * dy * dy;
            let ex = sx - L::load(&self.mean_x[h]);
            let ey = sy - L::load(&self.mean_y[h]);
            let bxy = L::load(&self.b[h]);
            let q = L::load(&self.a[h]) * ex * ex
                + (bxy + bxy) * ex * ey
                + L::load(&self.c[h]) * ey * ey;
            let inside = q.le(r2) & m.le(r2);
            let v = L::load(&self.peak[h]) * (L::splat(-0.5) * (q + m)).exp();
            *acc = *acc + L::select(inside, v, L::zero());
        }
    }
}

/// Eight lobes as the exact masking sums them (CCM19 eqs. 12–17): mean slope,
/// covariance (xx, xy, yy) and the seed weight, all 0 in lanes whose weight is 0.
#[derive(Clone, Copy, Debug)]
pub struct MaskingLanes {
    pub mx: F32x8,
    pub my: F32x8,
    pub xx: F32x8,
    pub xy: F32x8,
    pub yy: F32x8,
    pub w: F32x8,
}

impl LobeBlock {
    /// Half `h` of the block as weighted masking lobes: the covariance from the stored
    /// inverse, the weight e^{−½ m_j} of the seed at `d0` + (column, row) from the footprint
    /// centre in the metric `b` (as in [`LobeBlock::accumulate`]) where m_j ≤ R² and the
    /// lane holds a lobe, 0 elsewhere. `None` when no lane has a weight.
    #[inline(always)]
    pub fn weighted_half(&self, h: usize, d0: [f32; 2], b: [f32; 3]) -> Option<MaskingLanes> {
        type L = F32x8;
        let dx = L::splat(d0[0] as f64) + LANE_X;
        let dy = L::splat(d0[1] as f64 + 2.0 * h as f64) + LANE_Y;
        let [ba, bb, bc] = b.map(|v| L::splat(v as f64));
        let m = ba * dx * dx + (bb + bb) * dx * dy + bc * dy * dy;
        let (mx, my) = (self.mean_x[h], self.mean_y[h]);
        // Lanes past the map's edge hold a NaN mean.
        let inside = m.le(L::splat(CUTOFF_R2)) & mx.eq(mx);
        if inside.none() {
            return None;
        }
        let zero = L::zero();
        let (a, bxy, c) = (self.a[h], self.b[h], self.c[h]);
        let inv_det = L::one() / L::select(inside, a * c - bxy * bxy, L::one());
        Some(MaskingLanes {
            mx: L::select(inside, mx, zero),
            my: L::select(inside, my, zero),
            xx: L::select(inside, c * inv_det, zero),
            xy: L::select(inside, -bxy * inv_det, zero),
            yy: L::select(inside, a * inv_det, zero),
            w: L::select(inside, (L::splat(-0.5) * m).exp(), zero),
        })
    }
}

/// Eight f32 lanes a block's fields load into: the portable [`F32x8`] and, on x86-64, the
/// AVX2 register lanes (used only where the CPU has AVX2: [`crate::lanes::avx2`]).
pub trait BlockLanes: Real {
    fn load(v: &F32x8) -> Self;
    fn store(self) -> F32x8;
}

impl BlockLanes for F32x8 {
    #[inline(always)]
    fn load(v: &F32x8) -> Self {
        *v
    }
    #[inline(always)]
    fn store(self) -> F32x8 {
        self
    }
}

#[cfg(target_arch = "x86_64")]
impl BlockLanes for crate::lanes::F32x8Avx2 {
    #[inline(always)]
    fn load(v: &F32x8) -> Self {
        crate::lanes::F32x8Avx2::from_array(v.0)
    }
    #[inline(always)]
    fn store(self) -> F32x8 {
        F32x8(self.to_array())
    }
}

/// Every lobe of a map, by leaf block (row-major blocks).
#[derive(Clone, Debug)]
pub struct LobeBlocks {
    blocks: Vec<LobeBlock>,
    /// Blocks per row.
    bw: usize,
    width: usize,
    height: usize,
}

impl LobeBlocks {
    /// The blocks of the `width`×`height` row-major lobes.
    pub fn new(lobes: &[SlopeLobe], width: usize, height: usize) -> Self {
        assert_eq!(lobes.len(), width * height);
        let (bw, bh) = (width.div_ceil(LEAF), height.div_ceil(LEAF));
        let mut blocks = vec![LobeBlock::EMPTY; bw * bh];
        for y in 0..height {
            for x in 0..width {
                let j = (y % LEAF) * LEAF + x % LEAF;
                blocks[(y / LEAF) * bw + x / LEAF].set(j, &lobes[y * width + x]);
            }
        }
        LobeBlocks {
            blocks,
            bw,
            width,
            height,
        }
    }

    /// The lobe of texel (x, y).
    #[inline]
    pub fn get(&self, x: usize, y: usize) -> SlopeLobe {
        self.blocks[(y / LEAF) * self.bw + x / LEAF].get((y % LEAF) * LEAF + x % LEAF)
    }

    /// The lobe of texel index k = y·width + x.
    #[inline]
    pub fn at(&self, k: usize) -> SlopeLobe {
        self.get(k % self.width, k / self.width)
    }

    /// The block of leaf (bx, by).
    #[inline(always)]
    pub fn block(&self, bx: usize, by: usize) -> &LobeBlock {
        &self.blocks[by * self.bw + bx]
    }

    /// Number of lobes (texels).
    pub fn len(&self) -> usize {
        self.width * self.height
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The lobes in row-major texel order.
    pub fn iter(&self) -> impl Iterator<Item = SlopeLobe> + '_ {
        (0..self.len()).map(|k| self.at(k))
    }

    /// Bytes held.
    pub fn size_bytes(&self) -> usize {
        self.blocks.len() * std::mem::size_of::<LobeBlock>()
    }
}

/// The lanes' sum.
#[inline(always)]
pub fn lane_sum(v: F32x8) -> f64 {
    v.0.iter().map(|&x| x as f64).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lobes(w: usize, h: usize) -> Vec<SlopeLobe> {
        (0..w * h)
            .map(|k| {
                let t = k as f64;
                SlopeLobe::from_moments(
                    [(t * 0.37).sin() * 0.3, (t * 0.11).cos() * 0.2],
                    [
                        0.01 + 0.02 * (k % 5) as f64,
                        0.004 * ((k % 3) as f64 - 1.0),
                        0.02,
                    ],
                )
            })
            .collect()
    }

    #[test]
    fn blocks_give_back_every_lobe_for_any_map_size() {
        for (w, h) in [(13usize, 9usize), (4, 4), (1, 7)] {
            let l = lobes(w, h);
            let b = LobeBlocks::new(&l, w, h);
            assert_eq!(b.len(), w * h);
            for (k, lobe) in b.iter().enumerate() {
                assert_eq!(lobe, l[k]);
            }
        }
    }

    #[test]
    fn a_block_sums_what_the_lobes_give_one_by_one() {
        let (w, h) = (7usize, 6usize);
        let l = lobes(w, h);
        let blocks = LobeBlocks::new(&l, w, h);
        let metric = [0.3f32, -0.05, 0.2];
        let centre = [2.7f64, 3.1f64];
        for q in 0..50 {
            let s = [
                ((q as f32) * 0.071).sin() * 0.3,
                ((q as f32) * 0.13).cos() * 0.2,
            ];
            let mut acc = F32x8::zero();
            for by in 0..h.div_ceil(LEAF) {
                for bx in 0..w.div_ceil(LEAF) {
                    let d0 = [
                        ((bx * LEAF) as f64 + 0.5 - centre[0]) as f32,
                        ((by * LEAF) as f64 + 0.5 - centre[1]) as f32,
                    ];
                    blocks.block(bx, by).accumulate(s, d0, metric, &mut acc);
                }
            }
            let mut one_by_one = 0.0;
            for y in 0..h {
                for x in 0..w {
                    let (dx, dy) = (x as f64 + 0.5 - centre[0], y as f64 + 0.5 - centre[1]);
                    let [a, b, c] = metric.map(|v| v as f64);
                    let m = a * dx * dx + 2.0 * b * dx * dy + c * dy * dy;
                    if m <= CUTOFF_R2 {
                        one_by_one += l[y * w + x].p22(s) * (-0.5 * m).exp();
                    }
                }
            }
            let got = lane_sum(acc);
            assert!(
                (got - one_by_one).abs() <= 1e-5 * one_by_one.max(1e-3),
                "{got} vs {one_by_one}"
            );
        }
    }
}
