//! The acceleration hierarchy of the patch NDF: a quadtree over texel positions whose nodes
//! bound, in slope space, the lobes below them  [CCM19 §5: "a hierarchy of NDF bounding
//! boxes in the (u, ñ) space"].
//!
//! A query for a half-vector slope h̃ and a footprint descends only into nodes whose slope
//! box contains h̃ and whose texel range the footprint reaches (the caller's spatial test),
//! so it touches only the lobes that can contribute to eq. 9. A lobe's slope box is the
//! bounding box of its truncated support μ ± R(σ_x, σ_y) (R² = [`CUTOFF_R2`]; the paper uses
//! the 99 % box), exact where the paper's is approximate, so skipping a node never drops a
//! contribution. The position extent of a node is implicit in its index.
//!
//! Leaves hold [`LEAF`]×[`LEAF`] texels (their lobes are evaluated together, in lanes:
//! [`super::lobe_blocks`]): 16 bytes per
//! node, ≈ 1/12 node per texel — 1.33 bytes per texel, 5.3 MiB for a 2048² map.

use super::lobe::{SlopeLobe, CUTOFF_R2};

/// Side of a leaf block, in texels.
pub const LEAF: usize = 4;

/// One level of the quadtree: boxes (min x̃, min ỹ, max x̃, max ỹ) of `w`×`h` nodes, each
/// covering `LEAF·2^level` texels per side.
#[derive(Clone, Debug)]
struct Level {
    w: usize,
    h: usize,
    boxes: Vec<[f32; 4]>,
}

#[derive(Clone, Debug)]
pub struct SlopeHierarchy {
    /// levels[0] are the leaves; the last level is the 1×1 root.
    levels: Vec<Level>,
    width: usize,
    height: usize,
}

const EMPTY: [f32; 4] = [
    f32::INFINITY,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::NEG_INFINITY,
];

#[inline]
fn union(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    [
        a[0].min(b[0]),
        a[1].min(b[1]),
        a[2].max(b[2]),
        a[3].max(b[3]),
    ]
}

impl SlopeHierarchy {
    /// Builds the tree over the lobes of a `width`×`height` map (row-major).
    pub fn build(lobes: &[SlopeLobe], width: usize, height: usize) -> Self {
        use rayon::prelude::*;
        let (lw, lh) = (width.div_ceil(LEAF), height.div_ceil(LEAF));
        let r = CUTOFF_R2.sqrt();
        let leaves: Vec<[f32; 4]> = (0..lw * lh)
            .into_par_iter()
            .map(|k| {
                let (bx, by) = (k % lw, k / lw);
                let mut b = EMPTY;
                for y in by * LEAF..((by + 1) * LEAF).min(height) {
                    for x in bx * LEAF..((bx + 1) * LEAF).min(width) {
                        let l = lobes[y * width + x];
                        let f = l.to_f64();
                        let (ex, ey) = (r * f.cov[0].sqrt(), r * f.cov[2].sqrt());
                        // Widened by one f32 ulp-scale margin: the lobe test runs in f32.
                        let pad = 1e-6 * (1.0 + f.mean[0].abs().max(f.mean[1].abs()));
                        b = union(
                            b,
                            [
                                (f.mean[0] - ex - pad) as f32,
                                (f.mean[1] - ey - pad) as f32,
                                (f.mean[0] + ex + pad) as f32,
                                (f.mean[1] + ey + pad) as f32,
                            ],
                        );
                    }
                }
                b
            })
            .collect();
        let mut levels = vec![Level {
            w: lw,
            h: lh,
            boxes: leaves,
        }];
        while levels.last().map(|l| l.w > 1 || l.h > 1).unwrap_or(false) {
            let prev = levels.last().unwrap();
            let (w, h) = (prev.w.div_ceil(2), prev.h.div_ceil(2));
            let mut boxes = vec![EMPTY; w * h];
            for y in 0..prev.h {
                for x in 0..prev.w {
                    let k = (y / 2) * w + x / 2;
                    boxes[k] = union(boxes[k], prev.boxes[y * prev.w + x]);
                }
            }
            levels.push(Level { w, h, boxes });
        }
        SlopeHierarchy {
            levels,
            width,
            height,
        }
    }

    /// Bytes held by the node boxes.
    pub fn size_bytes(&self) -> usize {
        self.levels.iter().map(|l| l.boxes.len() * 16).sum()
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        self.levels.iter().map(|l| l.boxes.len()).sum()
    }

    /// The slope box of the whole map.
    pub fn root_box(&self) -> [f32; 4] {
        self.levels.last().map(|l| l.boxes[0]).unwrap_or(EMPTY)
    }

    /// Calls `leaf(bx, by)` for every leaf block (texels [4bx, 4bx + 4) × [4by, 4by + 4))
    /// whose slope box contains `s`, inside nodes accepted by `node_ok(x0, y0, x1, y1)` (a
    /// half-open texel range). `node_ok` must be conservative: reject a node only when no
    /// texel of its range can contribute.
    #[inline]
    pub fn for_each_leaf(
        &self,
        s: [f32; 2],
        mut node_ok: impl FnMut(usize, usize, usize, usize) -> bool,
        mut leaf: impl FnMut(usize, usize),
    ) {
        let top = self.levels.len() - 1;
        // Depth-first; at most 3 siblings pending per level plus the current node.
        let mut stack: [(u8, u32, u32); 128] = [(0, 0, 0); 128];
        let mut sp = 0usize;
        stack[sp] = (top as u8, 0, 0);
        sp += 1;
        while sp > 0 {
            sp -= 1;
            let (lv, x, y) = stack[sp];
            let level = &self.levels[lv as usize];
            let b = level.boxes[y as usize * level.w + x as usize];
            if !(s[0] >= b[0] && s[0] <= b[2] && s[1] >= b[1] && s[1] <= b[3]) {
                continue;
            }
            let side = LEAF << lv;
            let x0 = x as usize * side;
            let y0 = y as usize * side;
            let x1 = (x0 + side).min(self.width);
            let y1 = (y0 + side).min(self.height);
            if !node_ok(x0, y0, x1, y1) {
                continue;
            }
            if lv == 0 {
                leaf(x as usize, y as usize);
                continue;
            }
            let child = &self.levels[lv as usize - 1];
            for cy in (2 * y)..(2 * y + 2).min(child.h as u32) {
                for cx in (2 * x)..(2 * x + 2).min(child.w as u32) {
                    stack[sp] = (lv - 1, cx, cy);
                    sp += 1;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn queries_find_exactly_the_lobes_whose_support_holds_the_slope() {
        // 13×9 texels (not a multiple of the leaf size), lobes spread in slope.
        let (w, h) = (13usize, 9usize);
        let lobes: Vec<SlopeLobe> = (0..w * h)
            .map(|k| {
                let t = k as f64;
                SlopeLobe::from_moments(
                    [(t * 0.37).sin() * 0.8, (t * 0.11).cos() * 0.5],
                    [0.001 + 0.002 * (k % 5) as f64, 0.0, 0.002],
                )
            })
            .collect();
        let tree = SlopeHierarchy::build(&lobes, w, h);
        for q in 0..200 {
            let s = [
                ((q as f32) * 0.071).sin() * 0.9,
                ((q as f32) * 0.13).cos() * 0.6,
            ];
            let mut found = vec![false; w * h];
            tree.for_each_leaf(
                s,
                |_, _, _, _| true,
                |bx, by| {
                    for y in by * LEAF..((by + 1) * LEAF).min(h) {
                        for x in bx * LEAF..((bx + 1) * LEAF).min(w) {
                            found[y * w + x] = true;
                        }
                    }
                },
            );
            for (k, l) in lobes.iter().enumerate() {
                if l.mahalanobis2(s) <= CUTOFF_R2 as f32 {
                    assert!(found[k], "lobe {k} missed for {s:?}");
                }
            }
        }
        assert!(tree.size_bytes() > 0 && tree.nodes() >= 1);
    }
}
