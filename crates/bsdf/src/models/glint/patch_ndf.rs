//! The patch NDF D_P of a footprint  [CCM19 eqs. 8–9]: in slope space
//!
//!   P22_P(h̃) = Σ_{i ∈ T} W_i P22_i(h̃) / Z,   D_P(ω_h) = P22_P(h̃) / cos⁴θ_h,
//!
//! evaluated through the slope hierarchy so that only lobes whose truncated support holds
//! h̃ and whose seed the footprint reaches are visited  [CCM19 §5], and its exact sampler.
//!
//! **Sampling** [CCM19 §5: "the ray footprint k_P is sampled giving a position u", then the
//! lobe there]. The paper reflects about the normal of the *interpolated map* at u, whose
//! density is the true P-NDF of eq. 8, not the mixture of eq. 9 the BRDF evaluates — a
//! sampler and a pdf that disagree. Here the position picks a *lobe*, and the lobe's slope
//! is sampled, with a rejection step that makes the lobe probability exactly ∝ W_i:
//!
//! 1. draw u ~ k_P;
//! 2. among the 4×4 seeds nearest u, pick seed i with probability k_i(u)/K_max, or reject
//!    with the remaining probability 1 − K(u)/K_max (K(u) = Σ k_i(u) over the 4×4 window,
//!    K_max = its maximum over u, the squared 1-D lattice sum θ(0)² ≈ 1.117);
//! 3. if seed i is outside T, return no sample; else draw the slope from lobe i
//!    (truncated Gaussian).
//!
//! The accepted pair (u, i) has density ∝ k_P(u) k_i(u), so P(i) = ∫ k_P k_i du / Z = W_i / Z
//! (the 4×4 window truncates k_i at ±2 texels, 5e-6 of its mass), and no lobe is returned
//! with probability 1 − Σ_T W_i / Z ≤ e^{−R²/2} = 3.4e-4: exactly the mass that the
//! truncated D_P (divided by Z, not by Σ_T W_i) lacks. The acceptance rate of step 2 is
//! Z / K_max ≈ 0.9. For a uniform query the lobe is drawn uniformly.

use super::footprint::{min_quadratic_over_box, FootprintQuery, Weighting};
use super::hierarchy::LEAF;
use super::lobe::{normal_of_slope, slope_of_normal, standard_normal_2d, CUTOFF_R2};
use super::lobe_blocks::{lane_sum, BlockLanes};
use super::microsurface::SEED_SIGMA;
use super::surface::GlintSurface;
use crate::lanes::F32x8;
use crate::math::rng::RandomSource;
use crate::math::{Vec2, Vec3};
use std::sync::OnceLock;

/// Attempts of the rejection sampler before it gives up (probability < 1e-200).
const MAX_TRIES: usize = 512;

/// K_max = (Σ_n φ_σk(n))²: the largest total seed weight at any point (reached at a seed).
pub fn seed_weight_sum_max() -> f64 {
    static K: OnceLock<f64> = OnceLock::new();
    *K.get_or_init(|| {
        let s: f64 = (-8..=8)
            .map(|n| {
                let x = n as f64;
                (-0.5 * x * x / (SEED_SIGMA * SEED_SIGMA)).exp()
            })
            .sum();
        let t = s / (SEED_SIGMA * (2.0 * std::f64::consts::PI).sqrt());
        t * t
    })
}

/// The four seed weights along an axis at distances d, d − 1, d − 2, d − 3 from the first,
/// norm · e^{−(d − a)² c} for a = 0..3, by their ratios e^{c(2(d − a) − 1)}, each the last
/// times `step` = e^{−2c}: two exponentials an axis instead of four (the lobe draw runs for
/// every sample; within 1e-14 of the direct form, tested).
#[inline]
fn seed_weights_along(d: f64, c: f64, step: f64, norm: f64) -> [f64; 4] {
    let mut g = [norm * (-d * d * c).exp(); 4];
    let mut ratio = (c * (2.0 * d - 1.0)).exp();
    for a in 1..4 {
        g[a] = g[a - 1] * ratio;
        ratio *= step;
    }
    g
}

/// A patch NDF: a surface seen through a footprint query.
#[derive(Clone, Copy)]
pub struct PatchNdf<'a> {
    pub surface: &'a GlintSurface,
    pub query: &'a FootprintQuery,
}

impl<'a> PatchNdf<'a> {
    pub fn new(surface: &'a GlintSurface, query: &'a FootprintQuery) -> Self {
        PatchNdf { surface, query }
    }

    /// P22_P at slope `s`  [CCM19 eq. 9 in slope space].
    #[inline]
    pub fn p22(&self, s: [f64; 2]) -> f64 {
        self.p22_counting(s).0
    }

    /// P22_P at `s` and the number of lobes evaluated (for the benchmarks and docs): the
    /// leaf blocks of the hierarchy whose slope box holds `s` and whose texels the
    /// footprint's truncation may reach, each summed in lanes
    /// ([`super::lobe_blocks::LobeBlock::accumulate`]; AVX2 registers where the CPU has
    /// them, the same bits either way).
    pub fn p22_counting(&self, s: [f64; 2]) -> (f64, usize) {
        if !(s[0].is_finite() && s[1].is_finite()) {
            return (0.0, 0);
        }
        #[cfg(target_arch = "x86_64")]
        if crate::lanes::avx2::available() {
            // SAFETY: the CPU has AVX2 and FMA (tested just above).
            return unsafe { self.p22_avx2(s) };
        }
        self.p22_lanes::<F32x8>(s)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn p22_avx2(&self, s: [f64; 2]) -> (f64, usize) {
        self.p22_lanes::<crate::lanes::F32x8Avx2>(s)
    }

    #[inline(always)]
    fn p22_lanes<L: BlockLanes>(&self, s: [f64; 2]) -> (f64, usize) {
        let sf = [s[0] as f32, s[1] as f32];
        let surf = self.surface;
        let q = self.query;
        let (w, h) = surf.lattice_size();
        let mut acc = L::zero();
        let mut touched = 0usize;
        let lobes_in =
            |bx: usize, by: usize| ((w - bx * LEAF).min(LEAF)) * ((h - by * LEAF).min(LEAF));
        match q.weighting {
            Weighting::Uniform => {
                surf.hierarchy.for_each_leaf(
                    sf,
                    |_, _, _, _| true,
                    |bx, by| {
                        touched += lobes_in(bx, by);
                        surf.lobes
                            .block(bx, by)
                            .accumulate(sf, [0.0; 2], [0.0; 3], &mut acc);
                    },
                );
            }
            Weighting::Gaussian => {
                let (wf, hf) = (w as f64, h as f64);
                let metric = q.s_inv.map(|v| v as f32);
                let reach = FootprintQuery::ellipse_half_extent(q.s);
                let [a, b, c] = q.s_inv;
                for &(tx, ty) in &q.tiles {
                    let (ox, oy) = (tx as f64 * wf, ty as f64 * hf);
                    // The footprint's centre and truncation box in this tile's texels.
                    let (cx, cy) = (q.center.x - ox, q.center.y - oy);
                    surf.hierarchy.for_each_leaf(
                        sf,
                        |x0, y0, x1, y1| {
                            // Seed centres of the node: [x0 + ½, x1 − ½] × [y0 + ½, y1 − ½].
                            let (lx, hx) = (x0 as f64 + 0.5, x1 as f64 - 0.5);
                            let (ly, hy) = (y0 as f64 + 0.5, y1 as f64 - 0.5);
                            // Outside the truncation ellipse's box: no seed can count.
                            if hx < cx - reach.x || lx > cx + reach.x {
                                return false;
                            }
                            if hy < cy - reach.y || ly > cy + reach.y {
                                return false;
                            }
                            // The node's centre inside the ellipse: some seed may count.
                            let (dx, dy) = (0.5 * (lx + hx) - cx, 0.5 * (ly + hy) - cy);
                            if a * dx * dx + 2.0 * b * dx * dy + c * dy * dy <= CUTOFF_R2 {
                                return true;
                            }
                            min_quadratic_over_box(q.s_inv, Vec2::new(cx, cy), [lx, hx], [ly, hy])
                                <= CUTOFF_R2
                        },
                        |bx, by| {
                            touched += lobes_in(bx, by);
                            let d0 = [
                                ((bx * LEAF) as f64 + 0.5 - cx) as f32,
                                ((by * LEAF) as f64 + 0.5 - cy) as f32,
                            ];
                            surf.lobes
                                .block(bx, by)
                                .accumulate(sf, d0, metric, &mut acc);
                        },
                    );
                }
            }
        }
        (lane_sum(acc.store()) * q.weight_scale, touched)
    }

    /// D_P(ω_h) = P22_P(h̃)/cos⁴θ_h  [CCM19 eq. 2 applied to eq. 9]; 0 below the horizon.
    #[inline]
    pub fn d(&self, h: Vec3) -> f64 {
        if !(h.z > 0.0) {
            return 0.0;
        }
        let z2 = h.z * h.z;
        if z2 * z2 < 1e-300 {
            return 0.0;
        }
        self.p22(slope_of_normal(h)) / (z2 * z2)
    }

    /// Density (solid angle of m) of [`PatchNdf::sample_normal`]: D_P(m) cos θ_m.
    #[inline]
    pub fn pdf_normal(&self, m: Vec3) -> f64 {
        self.d(m) * m.z.max(0.0)
    }

    /// Draws a lobe index with probability W_i/Z, or `None` with the probability
    /// 1 − Σ_T W_i/Z of a seed outside the truncation T (module notes).
    pub fn sample_lobe(&self, rng: &mut dyn RandomSource) -> Option<usize> {
        let surf = self.surface;
        let (w, h) = surf.lattice_size();
        let q = self.query;
        if q.weighting == Weighting::Uniform {
            let k = ((rng.next_f64() * (w * h) as f64) as usize).min(w * h - 1);
            return Some(k);
        }
        let [l11, l21, l22] = q.footprint_chol;
        let k_max = seed_weight_sum_max();
        let inv2s2 = 0.5 / (SEED_SIGMA * SEED_SIGMA);
        let norm1 = 1.0 / (SEED_SIGMA * (2.0 * std::f64::consts::PI).sqrt());
        let step = (-2.0 * inv2s2).exp();
        let row = |d: f64| seed_weights_along(d, inv2s2, step, norm1);
        for _ in 0..MAX_TRIES {
            let (zx, zy) = standard_normal_2d(rng.next_2d());
            let u = q.center + Vec2::new(l11 * zx, l21 * zx + l22 * zy);
            let bx = (u.x - 0.5).floor() as i64 - 1;
            let by = (u.y - 0.5).floor() as i64 - 1;
            // Distances to the first of the 4 × 4 nearest seeds: in [1, 2).
            let gx = row(u.x - bx as f64 - 0.5);
            let gy = row(u.y - by as f64 - 0.5);
            let (sx, sy): (f64, f64) = (gx.iter().sum(), gy.iter().sum());
            let xi = rng.next_f64() * k_max;
            if xi >= sx * sy {
                continue;
            }
            // Row b with probability gy[b]/sy, then column a with gx[a]/sx, from one number.
            let mut t = xi / sx;
            let mut b = 0;
            while b < 3 && t >= gy[b] {
                t -= gy[b];
                b += 1;
            }
            let mut r = t / gy[b] * sx;
            let mut a = 0;
            while a < 3 && r >= gx[a] {
                r -= gx[a];
                a += 1;
            }
            let (ix, iy) = (bx + a as i64, by + b as i64);
            let ui = Vec2::new(ix as f64 + 0.5, iy as f64 + 0.5);
            if q.mahalanobis2(ui) > CUTOFF_R2 {
                // A seed outside T: no lobe. Not a retry: D_P is divided by Z, the weight of
                // every seed, so it integrates to Σ_T W_i / Z < 1 and the sampler must fail
                // with the missing probability 1 − Σ_T W_i / Z (retrying would return a lobe
                // with probability W_i / Σ_T W_i, more than pdf claims, and no failure:
                // 3.4e-4 of the mass in the wrong place, a chi-square failure of the
                // "no direction" cell).
                return None;
            }
            let x = ix.rem_euclid(w as i64) as usize;
            let y = iy.rem_euclid(h as i64) as usize;
            return Some(y * w + x);
        }
        None
    }

    /// Draws a microfacet normal with density [`PatchNdf::pdf_normal`]: a lobe, then a slope
    /// from it.
    pub fn sample_normal(&self, rng: &mut dyn RandomSource) -> Option<Vec3> {
        let k = self.sample_lobe(rng)?;
        let lobe = self.surface.lobes.at(k).to_f64();
        Some(normal_of_slope(lobe.sample_slope(rng.next_2d())))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rng::Pcg32;
    use crate::models::glint::footprint::Footprint;
    use crate::models::glint::generate::{generate, NormalMapKind};

    #[test]
    fn the_avx2_and_portable_queries_give_the_same_bits() {
        #[cfg(target_arch = "x86_64")]
        if crate::lanes::avx2::available() {
            let map = generate(NormalMapKind::Scratched, 64, 3).unwrap();
            let surf = GlintSurface::build(map, 0.01, "t").unwrap();
            let mut rng = Pcg32::new(3, 4);
            let mut nonzero = 0;
            for (k, sigma) in [0.3, 1.0, 4.0, 12.0, 200.0].into_iter().enumerate() {
                let fp = Footprint::isotropic(Vec2::new(5.3 + 9.0 * k as f64, 60.8), sigma);
                let q = FootprintQuery::new(fp, 64, 64);
                let ndf = PatchNdf::new(&surf, &q);
                for _ in 0..200 {
                    let Some(m) = ndf.sample_normal(&mut rng) else {
                        continue;
                    };
                    let s = slope_of_normal(m);
                    let portable = ndf.p22_lanes::<F32x8>(s);
                    // SAFETY: AVX2 and FMA are available (tested above).
                    let avx2 = unsafe { ndf.p22_avx2(s) };
                    assert_eq!(portable.0.to_bits(), avx2.0.to_bits(), "σ {sigma} s {s:?}");
                    assert_eq!(portable.1, avx2.1);
                    nonzero += (avx2.0 > 0.0) as usize;
                }
            }
            assert!(nonzero > 900, "{nonzero}");
        }
    }

    #[test]
    fn seed_weights_by_ratios_are_the_direct_ones() {
        let c = 0.5 / (SEED_SIGMA * SEED_SIGMA);
        let mut worst: f64 = 0.0;
        for k in 0..=1000 {
            let d = 1.0 + k as f64 / 1000.0 * (1.0 - 1e-12);
            let g = seed_weights_along(d, c, (-2.0 * c).exp(), 0.7);
            for (a, v) in g.into_iter().enumerate() {
                let x = d - a as f64;
                let direct = 0.7 * (-x * x * c).exp();
                worst = worst.max((v - direct).abs() / direct);
            }
        }
        assert!(worst < 1e-14, "{worst}");
    }

    #[test]
    fn k_max_is_the_lattice_sum_at_a_seed() {
        let k = seed_weight_sum_max();
        assert!((k - 1.117_03).abs() < 1e-4, "{k}");
    }

    #[test]
    fn lobe_sampling_follows_the_weights() {
        // Small map, sub-texel footprint: compare lobe frequencies with W_i / Σ_T W_i.
        let map = generate(NormalMapKind::Bumpy, 16, 3).unwrap();
        let surf = GlintSurface::build(map, 0.01, "t").unwrap();
        let fp = Footprint::from_sigmas(Vec2::new(5.3, 15.8), 0.6, 0.3, 0.4);
        let q = FootprintQuery::new(fp, 16, 16);
        let ndf = PatchNdf::new(&surf, &q);
        let mut rng = Pcg32::new(1, 2);
        let n = 400_000;
        // Cell 256: no lobe (a seed outside the truncation T).
        let mut counts = vec![0usize; 257];
        for _ in 0..n {
            counts[ndf.sample_lobe(&mut rng).unwrap_or(256)] += 1;
        }
        let mut expected = vec![0.0; 256];
        for &(tx, ty) in &q.tiles {
            for y in 0..16 {
                for x in 0..16 {
                    let u = Vec2::new((tx * 16 + x) as f64 + 0.5, (ty * 16 + y) as f64 + 0.5);
                    let m = q.mahalanobis2(u);
                    if m <= CUTOFF_R2 {
                        expected[y as usize * 16 + x as usize] += (-0.5 * m).exp();
                    }
                }
            }
        }
        // P(i) = W_i / Z (not W_i / Σ_T W_i): the probabilities D_P is built from.
        for e in &mut expected {
            *e *= q.weight_scale;
        }
        let kept: f64 = expected.iter().sum();
        expected.push(1.0 - kept);
        let mut chi2 = 0.0;
        let mut dof = 0;
        for k in 0..257 {
            let e = expected[k] * n as f64;
            if e > 5.0 {
                chi2 += (counts[k] as f64 - e).powi(2) / e;
                dof += 1;
            } else {
                assert!(counts[k] as f64 <= 5.0 * e + 10.0);
            }
        }
        // The truncated mass is large enough here to be tested (≈ 1e-4 of the draws).
        assert!(expected[256] * n as f64 > 20.0, "{}", expected[256]);
        // chi2 / dof ≈ 1 for a correct sampler; a 1 % bias would give ~ 40 here.
        assert!(chi2 / (dof as f64) < 1.6, "chi2 {chi2} dof {dof}");
    }
}
