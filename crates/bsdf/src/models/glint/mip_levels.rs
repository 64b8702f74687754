//! The NDF mip pyramid of the approximate masking term  [CCM19 §4.2.2, Fig. 4]: each level
//! halves the previous one and stores, per texel, the slope moments E[x̃], E[ỹ], E[x̃²],
//! E[ỹ²], E[x̃ỹ] averaged over the lobes it covers — five `f32`. Filtering the moments
//! linearly is exact for the mixture (LEAN mapping, Olano & Baker 2010; the paper follows
//! Dupuy et al. 2013): the moment-matched single lobe of a block has the mean and the
//! covariance (σ_x, σ_y and correlation) of the block's mixture, which is what the paper
//! filters per level. Level 0 is not stored: it is read from the lobes themselves.
//!
//! Sizes halve with rounding up (a 2^k map gives 2^(k−l) texels at level l); a texel of
//! level l covers texels [x·2^l, min((x+1)·2^l, W)) of the map, and its moments are the
//! texel-count-weighted average of its children's, so any map size works.

use super::lobe::{LobeF64, SlopeLobe};
use super::lobe_blocks::LobeBlocks;

/// Moments of a block of the map: mean slope and second moments (xx, xy, yy).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments {
    pub mean: [f64; 2],
    pub second: [f64; 3],
}

impl Moments {
    pub fn of_lobe(l: &SlopeLobe) -> Moments {
        let f = l.to_f64();
        let [mx, my] = f.mean;
        Moments {
            mean: f.mean,
            second: [f.cov[0] + mx * mx, f.cov[1] + mx * my, f.cov[2] + my * my],
        }
    }

    /// The moment-matched lobe (covariance = second moments − mean meanᵀ), with its
    /// variances kept positive.
    pub fn lobe(&self) -> LobeF64 {
        let [mx, my] = self.mean;
        let xx = (self.second[0] - mx * mx).max(1e-12);
        let yy = (self.second[2] - my * my).max(1e-12);
        let lim = 0.999 * (xx * yy).sqrt();
        LobeF64 {
            mean: self.mean,
            cov: [xx, (self.second[1] - mx * my).clamp(-lim, lim), yy],
        }
    }

    #[inline]
    pub fn add_scaled(&mut self, o: &Moments, w: f64) {
        self.mean[0] += w * o.mean[0];
        self.mean[1] += w * o.mean[1];
        for k in 0..3 {
            self.second[k] += w * o.second[k];
        }
    }

    pub fn scaled(mut self, w: f64) -> Moments {
        self.mean = self.mean.map(|v| v * w);
        self.second = self.second.map(|v| v * w);
        self
    }

    fn to_f32(self) -> [f32; 5] {
        [
            self.mean[0] as f32,
            self.mean[1] as f32,
            self.second[0] as f32,
            self.second[1] as f32,
            self.second[2] as f32,
        ]
    }

    fn from_f32(v: [f32; 5]) -> Moments {
        Moments {
            mean: [v[0] as f64, v[1] as f64],
            second: [v[2] as f64, v[3] as f64, v[4] as f64],
        }
    }
}

#[derive(Clone, Debug)]
struct MipLevel {
    w: usize,
    texels: Vec<[f32; 5]>,
}

/// The pyramid above level 0.
#[derive(Clone, Debug)]
pub struct MomentPyramid {
    width: usize,
    height: usize,
    /// levels[l − 1] is level l.
    levels: Vec<MipLevel>,
}

impl MomentPyramid {
    pub fn build(lobes: &[SlopeLobe], width: usize, height: usize) -> Self {
        use rayon::prelude::*;
        let mut levels: Vec<MipLevel> = Vec::new();
        let mut l = 1;
        while width.div_ceil(1 << (l - 1)) > 1 || height.div_ceil(1 << (l - 1)) > 1 {
            let (w, h) = (width.div_ceil(1 << l), height.div_ceil(1 << l));
            let prev = levels.last();
            let texels: Vec<[f32; 5]> = (0..w * h)
                .into_par_iter()
                .with_min_len(1024)
                .map(|k| {
                    let (x, y) = (k % w, k / w);
                    let mut acc = Moments::default();
                    let mut total = 0.0;
                    for cy in 2 * y..(2 * y + 2) {
                        for cx in 2 * x..(2 * x + 2) {
                            let (ax, ay) = (
                                block_extent(width, l - 1, cx),
                                block_extent(height, l - 1, cy),
                            );
                            let area =
                                (ax.1.saturating_sub(ax.0) * ay.1.saturating_sub(ay.0)) as f64;
                            if area == 0.0 {
                                continue;
                            }
                            let m = match prev {
                                None => Moments::of_lobe(&lobes[cy * width + cx]),
                                Some(p) => Moments::from_f32(p.texels[cy * p.w + cx]),
                            };
                            acc.add_scaled(&m, area);
                            total += area;
                        }
                    }
                    acc.scaled(1.0 / total).to_f32()
                })
                .collect();
            levels.push(MipLevel { w, texels });
            l += 1;
        }
        MomentPyramid {
            width,
            height,
            levels,
        }
    }

    /// Number of levels including level 0.
    pub fn levels(&self) -> usize {
        self.levels.len() + 1
    }

    /// Texels of level `l` per side.
    pub fn level_size(&self, l: usize) -> (usize, usize) {
        (self.width.div_ceil(1 << l), self.height.div_ceil(1 << l))
    }

    /// Moments of texel (x, y) of level `l` (level 0 from the lobes).
    #[inline]
    pub fn moments(&self, lobes: &LobeBlocks, l: usize, x: usize, y: usize) -> Moments {
        if l == 0 {
            return Moments::of_lobe(&lobes.get(x, y));
        }
        let lv = &self.levels[l - 1];
        Moments::from_f32(lv.texels[y * lv.w + x])
    }

    pub fn size_bytes(&self) -> usize {
        self.levels.iter().map(|l| l.texels.len() * 20).sum()
    }
}

/// The texel range [x0, x1) of the map covered by texel `x` of level `l` along a side of
/// `n` texels.
#[inline]
pub fn block_extent(n: usize, l: usize, x: usize) -> (usize, usize) {
    let x0 = x << l;
    (x0.min(n), ((x + 1) << l).min(n))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn top_level_holds_the_global_moments_for_any_size() {
        for (w, h) in [(8usize, 8usize), (7, 5), (1, 3)] {
            let lobes: Vec<SlopeLobe> = (0..w * h)
                .map(|k| {
                    let t = k as f64;
                    SlopeLobe::from_moments(
                        [t.sin() * 0.3, t.cos() * 0.2],
                        [0.01 + 0.001 * t, 0.002, 0.02],
                    )
                })
                .collect();
            let p = MomentPyramid::build(&lobes, w, h);
            let top = p.levels() - 1;
            assert_eq!(p.level_size(top), (1, 1));
            let m = p.moments(&LobeBlocks::new(&lobes, w, h), top, 0, 0);
            let mut g = Moments::default();
            for l in &lobes {
                g.add_scaled(&Moments::of_lobe(l), 1.0 / (w * h) as f64);
            }
            for k in 0..2 {
                assert!((m.mean[k] - g.mean[k]).abs() < 1e-6, "{w}x{h}");
            }
            for k in 0..3 {
                assert!((m.second[k] - g.second[k]).abs() < 1e-6, "{w}x{h}");
            }
        }
    }
}
