//! Patch masking and projected area  [CCM19 §4.2, eqs. 10–17], exact and approximate.
//!
//! Everything reduces to the patch's visible projected area
//! I_P(v) = ∫ ⟨v, m⟩ D_P(m) dω_m = Σ_i W_i I_i(v) / Σ_i W_i  [CCM19 eq. 12], with I_i the
//! closed form of [`super::lobe`]:
//!
//! - projected area A_P(v) = Σ W_i (v_z − v_⊥·μ_i)⁺ / Σ W_i  [CCM19 eq. 17];
//! - Λ_P(v) = (I_P(v) − A_P(v)) / A_P(v)  [CCM19 eq. 15] and G1_dist = 1/(1 + Λ_P) =
//!   A_P/I_P  [CCM19 eqs. 11, 14];
//! - G2 = χ⁺(h·o) χ⁺(h·i) G1_dist(o) G1_dist(i)  [CCM19 eqs. 10, 16].
//!
//! In the P-BRDF (eq. 7) the projected areas cancel: F G2 D_P / (4 A_P(o) A_P(i)) =
//! F χ⁺χ⁺ D_P / (4 I_P(o) I_P(i)). The BSDF therefore only needs I_P, which also keeps it
//! defined where a footprint's mean facet faces away from a direction (A_P = 0, Λ_P = ∞).
//!
//! **Exact** (`masking = "exact"`): the sum over the footprint's seeds T (the same
//! truncation as the patch NDF). Its cost grows with the footprint's area, so above a
//! budget of seeds (`masking_lobes`, default [`DEFAULT_MASKING_LOBES`]; 0 = unlimited) the
//! sum is taken over the blocks of the coarsest-needed mip level instead, each block a
//! moment-matched lobe weighted by its area — exact at level 0, an approximation beyond
//! (measured in the tests and docs/glints.md).
//!
//! **Approximate** (`masking = "approx"`, after §4.2.2): the exact term with a budget of
//! [`APPROX_BLOCKS`] — the sum over the blocks of the mip level at which the footprint
//! spans at most that many (the seeds themselves for the smallest footprints), each
//! block one Beckmann lobe with the W-weighted moments of its seeds — CCM19's filtered
//! lobe taken per block, not once for the whole footprint. A query costs at most a few
//! lane groups (two for 16 blocks).
//!
//! Why not the paper's single lobe (ERRATA 18): I_P enters the P-BRDF's denominator, and a Gaussian's
//! tail is far lighter than the mixture's. Where a footprint's mean facet turns away from a
//! grazing direction, the single lobe's I_P underflows while the footprint still has
//! facets facing that direction: measured on 256² flakes at θ_o 80–90°, the sampler's
//! weight (F = 1) reached 4.5e19 with a mean of 1.8e14 — pixels of 1e18 and beyond at a
//! sphere's silhouette. With the blocks' mixture the largest weight is 1.0e3 and the mean
//! 1.45, as the exact term's (6.3e3 and 1.53; the albedo w.r.t. cos θ_i may exceed 1 for a
//! tilted footprint, see [`super::glint_bsdf`]); test `approximate_masking_is_bounded_at_grazing_views`.
//!
//! Block weights at level l: area · N(centre; c, Σ_P + v_l I) with v_l = σ_k² + (4^l − 1)/12,
//! the second moment of the seed weights summed over a 2^l × 2^l block (σ_k² at level 0,
//! where the weights are exactly the W_i).

use super::footprint::{FootprintQuery, Weighting};
use super::hierarchy::LEAF;
use super::lobe::{expected_positive_part, LobeF64, CUTOFF_R2};
use super::lobe_blocks::{lane_sum, BlockLanes, MaskingLanes};
use super::microsurface::SEED_SIGMA;
use super::mip_levels::{block_extent, Moments};
use super::surface::GlintSurface;
use crate::error::{ParamError, ParamResult};
use crate::lanes::{F32x8, Mask, Real};
use crate::math::special::erfc_lanes;
use crate::math::{Vec2, Vec3, PI};

/// Default budget of lobes summed by the exact masking term.
pub const DEFAULT_MASKING_LOBES: usize = 1024;

/// Blocks (at most) whose filtered lobes the approximate term sums.
pub const APPROX_BLOCKS: f64 = 16.0;

/// Which masking-shadowing and projected area the P-BRDF uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MaskingMode {
    /// CCM19 eqs. 13–17 summed over the footprint's lobes.
    Exact,
    /// CCM19 §4.2.2 per block: the filtered lobes of at most [`APPROX_BLOCKS`] mip blocks.
    Approx,
}

impl MaskingMode {
    pub const NAMES: &'static [&'static str] = &["exact", "approx"];

    pub fn parse(s: &str) -> ParamResult<Self> {
        match s {
            "exact" => Ok(MaskingMode::Exact),
            "approx" | "approximate" => Ok(MaskingMode::Approx),
            other => Err(ParamError::UnknownChoice {
                what: "glint masking".into(),
                given: other.into(),
                valid: Self::NAMES.join(", "),
            }),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            MaskingMode::Exact => "exact",
            MaskingMode::Approx => "approx",
        }
    }
}

/// Variance of the summed seed weights of a level-l block (per axis).
#[inline]
fn level_variance(l: usize) -> f64 {
    let side = (1u64 << l) as f64;
    SEED_SIGMA * SEED_SIGMA + (side * side - 1.0) / 12.0
}

/// Estimated number of level-l blocks in the footprint's truncation ellipse.
fn blocks_estimate(surface: &GlintSurface, query: &FootprintQuery, l: usize) -> f64 {
    match query.weighting {
        Weighting::Uniform => {
            let (w, h) = surface.pyramid.level_size(l);
            (w * h) as f64
        }
        Weighting::Gaussian => {
            let s = level_covariance(query, l);
            let area = PI * CUTOFF_R2 * (s[0] * s[2] - s[1] * s[1]).max(0.0).sqrt();
            area / ((1u64 << (2 * l)) as f64) + 1.0
        }
    }
}

/// Σ_P + v_l I, from the query's S = Σ_P + σ_k² I.
fn level_covariance(query: &FootprintQuery, l: usize) -> [f64; 3] {
    let extra = level_variance(l) - SEED_SIGMA * SEED_SIGMA;
    [query.s[0] + extra, query.s[1], query.s[2] + extra]
}

/// The finest level whose block count in the footprint is at most `budget` (0: level 0).
pub fn choose_level(surface: &GlintSurface, query: &FootprintQuery, budget: f64) -> usize {
    let top = surface.pyramid.levels() - 1;
    if budget <= 0.0 {
        return 0;
    }
    (0..=top)
        .find(|&l| blocks_estimate(surface, query, l) <= budget)
        .unwrap_or(top)
}

/// Calls `f(moments, weight)` for every block of level `l` in the footprint (unnormalized
/// weights; see the module notes).
pub fn for_each_block(
    surface: &GlintSurface,
    query: &FootprintQuery,
    l: usize,
    mut f: impl FnMut(Moments, f64),
) {
    let (w, h) = surface.lattice_size();
    let (lw, lh) = surface.pyramid.level_size(l);
    let lobes = surface.lobes();
    if query.weighting == Weighting::Uniform {
        for by in 0..lh {
            let (y0, y1) = block_extent(h, l, by);
            for bx in 0..lw {
                let (x0, x1) = block_extent(w, l, bx);
                let area = ((x1 - x0) * (y1 - y0)) as f64;
                f(surface.pyramid.moments(lobes, l, bx, by), area);
            }
        }
        return;
    }
    let s = level_covariance(query, l);
    let det = (s[0] * s[2] - s[1] * s[1]).max(1e-300);
    let inv = [s[2] / det, -s[1] / det, s[0] / det];
    let e = FootprintQuery::ellipse_half_extent(s);
    let c = query.center;
    let (wf, hf) = (w as f64, h as f64);
    for (tx, ty) in query.tiles_reached(s, inv) {
        let (ox, oy) = (tx as f64 * wf, ty as f64 * hf);
        let range = |lo: f64, hi: f64, n: usize, nb: usize| -> (usize, usize) {
            let a = lo.max(0.0);
            let b = hi.min(n as f64 - 1e-9);
            if b < a {
                return (1, 0);
            }
            (
                ((a as usize) >> l).min(nb - 1),
                ((b as usize) >> l).min(nb - 1),
            )
        };
        let (bx0, bx1) = range(c.x - e.x - ox, c.x + e.x - ox, w, lw);
        let (by0, by1) = range(c.y - e.y - oy, c.y + e.y - oy, h, lh);
        if bx1 < bx0 || by1 < by0 {
            continue;
        }
        for by in by0..=by1 {
            let (y0, y1) = block_extent(h, l, by);
            let cy = oy + 0.5 * (y0 + y1) as f64;
            for bx in bx0..=bx1 {
                let (x0, x1) = block_extent(w, l, bx);
                let d = Vec2::new(ox + 0.5 * (x0 + x1) as f64, cy) - c;
                let q = inv[0] * d.x * d.x + 2.0 * inv[1] * d.x * d.y + inv[2] * d.y * d.y;
                if q > CUTOFF_R2 {
                    continue;
                }
                let area = ((x1 - x0) * (y1 - y0)) as f64;
                // An `f32` exponential: the weight is stored in `f32` lanes anyway.
                let weight = f64::from((-0.5 * q as f32).exp());
                f(surface.pyramid.moments(lobes, l, bx, by), area * weight);
            }
        }
    }
}

/// A lobe with its normalized weight, flattened for the inner loop: mean x, mean y, Σxx,
/// Σxy, Σyy, weight.
type WeightedLobe = [f64; 6];

const EMPTY_LANES: MaskingLanes = MaskingLanes {
    mx: F32x8([0.0; 8]),
    my: F32x8([0.0; 8]),
    xx: F32x8([0.0; 8]),
    xy: F32x8([0.0; 8]),
    yy: F32x8([0.0; 8]),
    w: F32x8([0.0; 8]),
};

/// Appends lobe number `n` (counted from 0) to `lanes`, eight to a lane group, in order
/// (unused lanes weigh 0).
fn push_lobe(lanes: &mut Vec<MaskingLanes>, n: usize, e: &WeightedLobe) {
    let j = n % 8;
    if j == 0 {
        lanes.push(EMPTY_LANES);
    }
    let c = lanes.last_mut().expect("a lane group was pushed at lane 0");
    for (field, v) in [
        &mut c.mx, &mut c.my, &mut c.xx, &mut c.xy, &mut c.yy, &mut c.w,
    ]
    .into_iter()
    .zip(e)
    {
        field.0[j] = *v as f32;
    }
}

/// `lobes` eight to a lane group, in order.
fn lanes_of(lobes: &[WeightedLobe]) -> Vec<MaskingLanes> {
    let mut out = Vec::with_capacity(lobes.len().div_ceil(8));
    for (n, e) in lobes.iter().enumerate() {
        push_lobe(&mut out, n, e);
    }
    out
}

/// The lobes of the lanes whose weight is not 0.
fn lobes_of(lanes: &[MaskingLanes]) -> impl Iterator<Item = WeightedLobe> + '_ {
    lanes.iter().flat_map(|c| {
        (0..8)
            .filter(|&j| c.w.0[j] != 0.0)
            .map(|j| [c.mx, c.my, c.xx, c.xy, c.yy, c.w].map(|f| f.0[j] as f64))
    })
}

/// The footprint's level-0 lobes (the seeds themselves) with their unnormalized weights
/// e^{−½ (u_i − c)ᵀS⁻¹(u_i − c)} (= W_i up to the footprint's scale), read a leaf block
/// half at a time in lanes: what [`for_each_block`] gives at level 0, without a lobe's
/// round trip through its moments. Returns the lanes and the weights' sum.
fn level_zero_lanes(surface: &GlintSurface, query: &FootprintQuery) -> (Vec<MaskingLanes>, f64) {
    if query.weighting == Weighting::Uniform {
        return block_lanes(surface, query, 0);
    }
    let lobes = surface.lobes();
    let mut total = 0.0;
    let (w, h) = surface.lattice_size();
    let s = query.s;
    let det = (s[0] * s[2] - s[1] * s[1]).max(1e-300);
    let inv = [s[2] / det, -s[1] / det, s[0] / det];
    let b = inv.map(|v| v as f32);
    let e = FootprintQuery::ellipse_half_extent(s);
    let c = query.center;
    let (wf, hf) = (w as f64, h as f64);
    let mut lanes = Vec::new();
    for (tx, ty) in query.tiles_reached(s, inv) {
        let (ox, oy) = (tx as f64 * wf, ty as f64 * hf);
        let range = |lo: f64, hi: f64, n: usize| -> Option<(usize, usize)> {
            let a = lo.max(0.0);
            let b = hi.min(n as f64 - 1e-9);
            (b >= a).then_some(((a as usize) / LEAF, (b as usize) / LEAF))
        };
        let (Some((bx0, bx1)), Some((by0, by1))) = (
            range(c.x - e.x - ox, c.x + e.x - ox, w),
            range(c.y - e.y - oy, c.y + e.y - oy, h),
        ) else {
            continue;
        };
        // Two halves a block at most (growing the list one by one cost 6 % of a render).
        lanes.reserve(2 * (bx1 - bx0 + 1) * (by1 - by0 + 1));
        for by in by0..=by1 {
            for bx in bx0..=bx1 {
                // The block's first seed centre relative to the footprint centre.
                let d0 = [
                    (ox + (bx * LEAF) as f64 + 0.5 - c.x) as f32,
                    (oy + (by * LEAF) as f64 + 0.5 - c.y) as f32,
                ];
                let block = lobes.block(bx, by);
                for half in 0..2 {
                    if let Some(l) = block.weighted_half(half, d0, b) {
                        total += lane_sum(l.w);
                        lanes.push(l);
                    }
                }
            }
        }
    }
    (lanes, total)
}

/// The blocks of level `l` in the footprint as lobes in lanes, packed (no empty lanes),
/// with the weights' sum.
fn block_lanes(
    surface: &GlintSurface,
    query: &FootprintQuery,
    l: usize,
) -> (Vec<MaskingLanes>, f64) {
    // Room for the approximate term's ~16 blocks: this runs at every shading point.
    let mut lanes = Vec::with_capacity(3);
    let mut n = 0;
    let mut total = 0.0;
    for_each_block(surface, query, l, |m, w| {
        let l = m.lobe();
        push_lobe(
            &mut lanes,
            n,
            &[l.mean[0], l.mean[1], l.cov[0], l.cov[1], l.cov[2], w],
        );
        n += 1;
        total += w;
    });
    (lanes, total)
}

/// The masking term of one footprint.
#[derive(Clone, Debug)]
pub struct PatchMasking {
    mode: MaskingMode,
    /// The lobes in lanes, weights normalized (what I_P sums).
    lanes: Vec<MaskingLanes>,
    level: usize,
}

/// Mean and second moments of the normalized weighted lobes of `lanes`, summed in lanes
/// (`f32` products, `f64` totals).
fn lane_moments(lanes: &[MaskingLanes]) -> Moments {
    let mut acc = [F32x8::splat(0.0); 5];
    for e in lanes {
        let (mx, my) = (e.mx, e.my);
        let wx = e.w * mx;
        let wy = e.w * my;
        acc[0] = acc[0] + wx;
        acc[1] = acc[1] + wy;
        acc[2] = acc[2] + e.w * e.xx + wx * mx;
        acc[3] = acc[3] + e.w * e.xy + wx * my;
        acc[4] = acc[4] + e.w * e.yy + wy * my;
    }
    let [mx, my, xx, xy, yy] = acc.map(lane_sum);
    Moments {
        mean: [mx, my],
        second: [xx, xy, yy],
    }
}

impl PatchMasking {
    /// CCM19 eqs. 13–17 over the footprint's lobes (module notes on `budget`).
    pub fn exact(surface: &GlintSurface, query: &FootprintQuery, budget: usize) -> Self {
        let level = choose_level(surface, query, budget as f64);
        let (lanes, total) = if level == 0 {
            level_zero_lanes(surface, query)
        } else {
            block_lanes(surface, query, level)
        };
        Self::normalized(MaskingMode::Exact, lanes, total, level)
    }

    /// CCM19 §4.2.2 per block: the moment-matched lobes of the at most [`APPROX_BLOCKS`]
    /// blocks of the footprint's level (module notes) — the exact sum with that budget.
    /// At level 0 the lobes are therefore read a leaf block half at a time, as the exact
    /// term's, not through each seed's moments.
    pub fn approx(surface: &GlintSurface, query: &FootprintQuery) -> Self {
        PatchMasking {
            mode: MaskingMode::Approx,
            ..Self::exact(surface, query, APPROX_BLOCKS as usize)
        }
    }

    /// The term with its weights divided by their sum. A footprint whose truncation holds
    /// no lobe (it does not happen for a sanitized footprint; kept finite all the same)
    /// gets one narrow lobe around the normal.
    fn normalized(
        mode: MaskingMode,
        mut lanes: Vec<MaskingLanes>,
        total: f64,
        level: usize,
    ) -> Self {
        if total > 0.0 {
            let scale = F32x8::splat(1.0 / total);
            for l in lanes.iter_mut() {
                l.w = l.w * scale;
            }
        } else {
            lanes = lanes_of(&[[0.0, 0.0, 1e-4, 0.0, 1e-4, 1.0]]);
        }
        PatchMasking { mode, lanes, level }
    }

    pub fn new(
        mode: MaskingMode,
        surface: &GlintSurface,
        query: &FootprintQuery,
        budget: usize,
    ) -> Self {
        match mode {
            MaskingMode::Exact => Self::exact(surface, query, budget),
            MaskingMode::Approx => Self::approx(surface, query),
        }
    }

    pub fn mode(&self) -> MaskingMode {
        self.mode
    }

    /// The mip level the sum runs over (0: the lobes themselves).
    pub fn level(&self) -> usize {
        self.level
    }

    /// Number of lobes summed per query.
    pub fn lobe_count(&self) -> usize {
        self.weighted_lobes().count()
    }

    /// The lobes with their normalized weights.
    fn weighted_lobes(&self) -> impl Iterator<Item = WeightedLobe> + '_ {
        lobes_of(&self.lanes)
    }

    /// The footprint's moment-matched lobe: mean and covariance of the summed lobes'
    /// P22_P (the single lobe of CCM19 §4.2.2).
    pub fn filtered_lobe(&self) -> LobeF64 {
        lane_moments(&self.lanes).lobe()
    }

    /// I_P(v) = ∫ ⟨v, m⟩ D_P(m) dω_m  [CCM19 eq. 12 denominator] over the term's lobes
    /// (exact: the footprint's; approximate: its blocks'). `v` in the upper hemisphere. The
    /// sum runs in `f32` lanes (AVX2 where the CPU has it, the same bits;
    /// [`expected_positive_part_lanes`]), within 2e-5 (relative) of
    /// [`PatchMasking::visible_projected_area_f64`] (tested).
    #[inline]
    pub fn visible_projected_area(&self, v: Vec3) -> f64 {
        #[cfg(target_arch = "x86_64")]
        if crate::lanes::avx2::available() {
            // SAFETY: the CPU has AVX2 and FMA (tested just above).
            return unsafe { self.area_avx2(v) };
        }
        self.area_lanes::<F32x8>(v)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn area_avx2(&self, v: Vec3) -> f64 {
        self.area_lanes::<crate::lanes::F32x8Avx2>(v)
    }

    #[inline(always)]
    fn area_lanes<L: BlockLanes>(&self, v: Vec3) -> f64 {
        let (vx, vy, vz) = (L::splat(v.x), L::splat(v.y), L::splat(v.z));
        let (vxx, vxy, vyy) = (
            L::splat(v.x * v.x),
            L::splat(2.0 * v.x * v.y),
            L::splat(v.y * v.y),
        );
        let mut acc = L::zero();
        for e in &self.lanes {
            let d = vz - vx * L::load(&e.mx) - vy * L::load(&e.my);
            let s2 = vxx * L::load(&e.xx) + vxy * L::load(&e.xy) + vyy * L::load(&e.yy);
            acc = acc + L::load(&e.w) * expected_positive_part_lanes(d, s2.max(L::zero()).sqrt());
        }
        lane_sum(acc.store())
    }

    /// I_P(v) summed in `f64` lobe by lobe (the reference of the lanes' sum).
    pub fn visible_projected_area_f64(&self, v: Vec3) -> f64 {
        let mut sum = 0.0;
        for e in self.weighted_lobes() {
            let d = v.z - v.x * e[0] - v.y * e[1];
            let s2 = v.x * v.x * e[2] + 2.0 * v.x * v.y * e[3] + v.y * v.y * e[4];
            sum += e[5] * expected_positive_part(d, s2.max(0.0).sqrt());
        }
        sum
    }

    /// A_P(v)  [CCM19 eq. 17] (approximate: from the blocks' mean slopes).
    pub fn projected_area(&self, v: Vec3) -> f64 {
        self.weighted_lobes()
            .map(|e| e[5] * (v.z - v.x * e[0] - v.y * e[1]).max(0.0))
            .sum()
    }

    /// Λ_P(v)  [CCM19 eq. 15]; ∞ when A_P = 0.
    pub fn lambda(&self, v: Vec3) -> f64 {
        let a = self.projected_area(v);
        if a <= 0.0 {
            return f64::INFINITY;
        }
        (self.visible_projected_area(v) - a).max(0.0) / a
    }

    /// G1_dist(v) = 1/(1 + Λ_P(v))  [CCM19 eq. 14].
    pub fn g1_distant(&self, v: Vec3) -> f64 {
        let i = self.visible_projected_area(v);
        if i <= 0.0 {
            return 0.0;
        }
        (self.projected_area(v) / i).min(1.0)
    }
}

/// E[X⁺] for X ~ N(d, s²) over lanes: s φ(d/s) + d Φ(d/s) (d⁺ where s = 0), with Φ from
/// [`erfc_lanes`] — the lanes' form of [`expected_positive_part`]. For a lobe facing away
/// (d < 0) the two terms cancel, and in `f32` the relative error grows with |ν| (ν = d/s):
/// measured below 2.7e-5 for ν ≥ −4 and 1.5e-3 for −12 ≤ ν < −4, where the lobe's value
/// is below e^{−8} of its width.
#[inline(always)]
pub fn expected_positive_part_lanes<L: Real>(d: L, s: L) -> L {
    let has_width = s.gt(L::splat(1e-30));
    let nu = d / L::select(has_width, s, L::one());
    // ν ≥ 5.8: Φ(ν) = 1 − 3e-9 and s φ(ν) = 1e-8 d, below f32's resolution of d — the
    // common case (narrow lobes facing v) costs no exponential.
    if (nu.ge(L::splat(5.8)) | !has_width).all() {
        return d.max(L::zero());
    }
    let phi = (L::splat(-0.5) * nu * nu).exp() * L::splat(1.0 / (2.0 * PI).sqrt());
    let cdf = L::splat(0.5) * erfc_lanes(-nu * L::splat(std::f64::consts::FRAC_1_SQRT_2));
    let e = L::select(has_width, s * phi + d * cdf, d);
    e.max(L::zero())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::glint::footprint::Footprint;
    use crate::models::glint::generate::{generate, NormalMapKind};

    #[test]
    fn the_lanes_sum_is_the_f64_sum() {
        let map = generate(NormalMapKind::Bumpy, 64, 5).unwrap();
        let surf = GlintSurface::build(map, 0.01, "t").unwrap();
        let mut worst: f64 = 0.0;
        for (k, sigma) in [0.5, 3.0, 9.0].into_iter().enumerate() {
            let q = FootprintQuery::new(
                Footprint::isotropic(Vec2::new(10.3 + 17.0 * k as f64, 40.7), sigma),
                64,
                64,
            );
            let m = PatchMasking::exact(&surf, &q, 0);
            for t in 0..40 {
                let theta = 0.9999 * std::f64::consts::FRAC_PI_2 * (t as f64 / 39.0).sqrt();
                let v = crate::math::spherical_direction(theta, 0.77 * t as f64);
                let (a, b) = (m.visible_projected_area(v), m.visible_projected_area_f64(v));
                worst = worst.max((a - b).abs() / b.max(1e-30));
                #[cfg(target_arch = "x86_64")]
                if crate::lanes::avx2::available() {
                    // SAFETY: AVX2 and FMA are available (tested above).
                    let c = unsafe { m.area_avx2(v) };
                    assert_eq!(c.to_bits(), m.area_lanes::<F32x8>(v).to_bits());
                }
            }
        }
        println!("I_P in lanes against f64: largest relative difference {worst:.1e}");
        assert!(worst < 2e-5, "relative difference {worst}");
    }

    #[test]
    fn expected_positive_part_in_lanes_follows_the_f64_one() {
        // Largest relative error for ν ≥ −4 and for ν < −4 (printed: docs and comments).
        let mut worst = [0.0f64; 2];
        for i in 0..=400 {
            let nu = -12.0 + 0.06 * i as f64;
            for s in [1e-3, 0.3, 2.0] {
                let d = nu * s;
                let f = expected_positive_part(d, s);
                let l = expected_positive_part_lanes(F32x8::splat(d), F32x8::splat(s)).0[0] as f64;
                let tol = 1e-6 * (1.0 + nu.min(0.0).powi(4)) * f + 1e-37;
                let k = (nu < -4.0) as usize;
                worst[k] = worst[k].max((l - f).abs() / f);
                assert!((l - f).abs() <= tol, "ν {nu} s {s}: {l} vs {f}");
            }
        }
        println!(
            "relative error: ν ≥ −4 {:.1e}, −12 ≤ ν < −4 {:.1e}",
            worst[0], worst[1]
        );
        let z = expected_positive_part_lanes(F32x8::splat(0.5), F32x8::zero()).0[0];
        assert_eq!(z, 0.5);
    }

    #[test]
    fn a_flat_map_has_beckmann_masking() {
        let map =
            super::super::normal_map::NormalMap::from_slopes(8, 8, vec![[0.0, 0.0]; 64]).unwrap();
        let surf = GlintSurface::build(map, 0.2, "flat").unwrap();
        let q = FootprintQuery::new(Footprint::isotropic(Vec2::new(4.0, 4.0), 2.0), 8, 8);
        let b = crate::microfacet::Beckmann::isotropic(0.2 * std::f64::consts::SQRT_2).unwrap();
        for mode in [MaskingMode::Exact, MaskingMode::Approx] {
            let m = PatchMasking::new(mode, &surf, &q, DEFAULT_MASKING_LOBES);
            for t in [0.0, 0.5, 1.0, 1.4, 1.55] {
                let v = crate::math::spherical_direction(t, 0.3);
                let l = crate::microfacet::Distribution::lambda(&b, v);
                assert!((m.lambda(v) - l).abs() < 1e-5 * (1.0 + l), "{mode:?} {t}");
            }
        }
    }

    #[test]
    fn exact_level_zero_sums_the_footprint_lobes() {
        let map = generate(NormalMapKind::Bumpy, 32, 1).unwrap();
        let surf = GlintSurface::build(map, 0.01, "b").unwrap();
        let q = FootprintQuery::new(Footprint::isotropic(Vec2::new(7.0, 30.0), 1.5), 32, 32);
        let m = PatchMasking::exact(&surf, &q, 0);
        assert_eq!(m.level(), 0);
        // Direct sum over every seed of every tile.
        let v = crate::math::spherical_direction(1.2, 0.4);
        let (mut num, mut den) = (0.0, 0.0);
        for ty in -2..=2i64 {
            for tx in -2..=2i64 {
                for y in 0..32 {
                    for x in 0..32 {
                        let u = Vec2::new((tx * 32 + x) as f64 + 0.5, (ty * 32 + y) as f64 + 0.5);
                        let d = q.mahalanobis2(u);
                        if d > CUTOFF_R2 {
                            continue;
                        }
                        let w = (-0.5 * d).exp();
                        let l = surf.lobes().get(x as usize, y as usize).to_f64();
                        num += w * l.visible_projected_area(v);
                        den += w;
                    }
                }
            }
        }
        // The lobes are kept in f32 lanes (covariance from the stored inverse, weight from an
        // f32 exponential): the f64 sum over them and the lanes' sum to f32 precision.
        let i = m.visible_projected_area_f64(v);
        assert!((i - num / den).abs() < 2e-7 * i, "{i} {}", num / den);
        let i = m.visible_projected_area(v);
        assert!((i - num / den).abs() < 1e-6 * i, "{i} {}", num / den);
    }
}
