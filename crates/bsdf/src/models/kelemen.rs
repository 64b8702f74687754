//! The coupled specular-matte BRDF of KSK01.
//!
//! - Specular: f_s(L, V) = P_H(H) F(H·L) / (2 (1 + L·V)) = P_H(H) F / (4 cos²β)  [KSK01 eq. 3],
//!   with Ward, Beckmann or Phong half-vector densities (see
//!   [`crate::microfacet::half_vector_density`]).
//! - Matte: f_m(L, V) = k (1 − a_s(θ')) (1 − a_s(θ)) / (π (1 − ā_s))  [KSK01 §2.2], where
//!   a_s(θ) = ∫ f_s cos θ dω is the specular albedo and ā_s = (1/π) ∫ a_s(θ) cos θ dω its
//!   average. With k = 1 the total albedo is exactly 1 at every angle [KSK01 eq. 7].
//!
//! a_s(θ) is tabulated when the material is built (91 angles, 0°…90°, linear interpolation),
//! each entry either by the Monte Carlo quadrature of KSK01 §2.1.5 with the specular
//! sampler — randomized QMC with `table_samples` points in 8 rotations, whose standard
//! error is kept — or, with `table_tolerance` (the material syntax's default, 1e-4), by
//! adaptive quadrature over the half-vector
//! hemisphere (a_s(θ) = ∫ P_H(H) F(H·V) (L·n)/(H·V) dω_H, KSK01 eq. 3 with
//! dω_L = 4 (H·V) dω_H, cut where L crosses the horizon; see
//! `albedo_quadrature::reflection_integral_adaptive`) to that relative tolerance, whose error estimate is
//! kept (`albedo_table_error`). ā_s integrates the interpolated table exactly.
//!
//! Sampling (KSK01 §2.1.4, §2.2.1): the specular lobe through H and reflection; the matte
//! lobe by the inverse cumulative table of (1 − a_s(θ)) cos θ. KSK01 writes the cumulative as
//! I(θ') = ∫_0^θ' (1 − a_s(ξ)) cos ξ dξ, which omits the sin ξ of the solid-angle measure; the
//! density proportional to (1 − a_s(θ')) cos θ' needs ∫ (1 − a_s) cos ξ sin ξ dξ, used here.
//! Lobes are chosen with probabilities proportional to KSK01's a_s(θ) and k̃ (1 − a_s(θ)); the
//! third outcome of KSK01's Russian roulette, termination with probability
//! (1 − k̃)(1 − a_s(θ)), is left to the integrator: [`Kelemen::lobe_probabilities`] exposes
//! the three, and `sample` returns weights for the two scattering lobes only.
//!
//! | key | meaning | range | default |
//! |---|---|---|---|
//! | `distribution` | `ward`, `beckmann` or `phong` half-vector density | — | `ward` |
//! | `alpha` | RMS slope m (ward, beckmann) | (0, 10] | required |
//! | `exponent` | Phong exponent n | [0, 1e7] | required for phong |
//! | `ior` | index of the Fresnel term (dielectric) | > 1 | 1.5 |
//! | `kd` | matte colour k (number or RGB) | [0, 1] | 0.5 |
//! | `table_tolerance` | relative tolerance of adaptive albedo-table entries | [1e-12, 0.1] | 1e-4 |
//! | `table_samples` | QMC samples per albedo-table entry (instead of `table_tolerance`) | ≥ 64 | — |

use crate::bsdf::{BsdfContext, BsdfSample, LobeFlags};
use crate::checks::{check_min_count, check_reflectance};
use crate::error::ParamResult;
use crate::fresnel::Fresnel;
use crate::math::quadrature::GaussLegendre;
use crate::math::rng::{Pcg32, RandomSource};
use crate::math::spectrum::Spectrum;
use crate::math::warp::hammersley;
use crate::math::{reflect, Vec3, PI, TWO_PI};
use crate::microfacet::half_vector_density::HalfVectorDensity;
use crate::microfacet::integral::{check_tolerance_named, TableEntries};
use crate::models::multiple_scattering::albedo_quadrature::reflection_integral_adaptive;
use crate::two_sided::OpaqueBsdf;

/// Number of intervals of the albedo table over [0, π/2].
const TABLE_INTERVALS: usize = 90;

#[derive(Clone, Debug)]
pub struct Kelemen {
    density: HalfVectorDensity,
    fresnel: Fresnel,
    kd: Spectrum,
    /// The tables depend on the specular lobe only, so materials differing by k (a
    /// textured matte colour) share them.
    tables: std::sync::Arc<KelemenTables>,
}

/// Specular-albedo and matte-sampling tables.
#[derive(Clone, Debug, Default)]
struct KelemenTables {
    /// a_s(θ_k), θ_k = k·(π/2)/TABLE_INTERVALS, clamped to [0, 1].
    albedo: Vec<Spectrum>,
    /// Largest standard error (sampled entries) or estimated error (adaptive entries).
    albedo_error: f64,
    /// Per entry: the standard error or the error estimate (channel average).
    entry_errors: Vec<f64>,
    average: Spectrum,
    /// Cumulative of the matte sampling density in θ (piecewise linear g(θ) =
    /// (1 − ā_s(θ)) cos θ sin θ on the table grid).
    matte_cdf: Vec<f64>,
    matte_g: Vec<f64>,
}

impl Kelemen {
    pub fn new(
        density: HalfVectorDensity,
        fresnel: Fresnel,
        kd: Spectrum,
        table_samples: usize,
    ) -> ParamResult<Self> {
        Self::with_entries(density, fresnel, kd, TableEntries::Samples(table_samples))
    }

    /// [`Kelemen::new`] with the albedo table's entries sampled or adaptive
    /// (`TableEntries::Adaptive`: `table_tolerance`).
    pub fn with_entries(
        density: HalfVectorDensity,
        fresnel: Fresnel,
        kd: Spectrum,
        entries: TableEntries,
    ) -> ParamResult<Self> {
        check_reflectance("kd", kd)?;
        match entries {
            TableEntries::Samples(n) => {
                check_min_count("table_samples", n, 64)?;
            }
            TableEntries::Adaptive { tolerance } => {
                check_tolerance_named("table_tolerance", tolerance)?;
            }
        }
        let mut k = Kelemen {
            density,
            fresnel,
            kd,
            tables: Default::default(),
        };
        k.tables = std::sync::Arc::new(k.build_tables(entries));
        Ok(k)
    }

    /// The same material with another matte colour k (the tables are shared).
    pub fn with_kd(&self, kd: Spectrum) -> ParamResult<Self> {
        check_reflectance("kd", kd)?;
        Ok(Kelemen { kd, ..self.clone() })
    }

    /// a_s(θ) at cos θ = μ by adaptive quadrature to the relative tolerance `tolerance`
    /// (KSK01 eq. 3 integrated over the half-vectors; see the module notes): the value per
    /// channel and the largest estimated error. A Fresnel factor that is the same in every
    /// channel is integrated once.
    fn albedo_adaptive(&self, mu: f64, tolerance: f64) -> (Spectrum, f64) {
        let grey = matches!(self.fresnel, Fresnel::Dielectric { .. } | Fresnel::One);
        let channels = if grey {
            1
        } else {
            crate::math::spectrum::CHANNELS
        };
        let mut value = Spectrum::ZERO;
        let mut error = 0.0f64;
        for ch in 0..channels {
            let q = reflection_integral_adaptive(
                mu,
                self.density.typical_width(),
                tolerance,
                |h, i| {
                    let c = i.dot(h);
                    if !(c > 0.0) {
                        return 0.0;
                    }
                    // f_s cos θ_L dω_L = P_H F / (4 (H·V)²) · (L·n) · 4 (H·V) dω_H.
                    self.fresnel.eval(c)[ch] * self.density.density(h) * i.z / c
                },
            );
            value[ch] = q.value;
            error = error.max(q.error);
        }
        if grey {
            value = Spectrum::splat(value[0]);
        }
        (value, error)
    }

    /// Builds a_s(θ) [KSK01 §2.1.5], its average and the matte sampling table.
    fn build_tables(&self, entries: TableEntries) -> KelemenTables {
        let mut t = KelemenTables::default();
        use rayon::prelude::*;
        const ROT: usize = 8;
        let samples = match entries {
            TableEntries::Samples(n) => n,
            TableEntries::Adaptive { .. } => 0,
        };
        let per = (samples / ROT).max(8) as u32;
        let step = 0.5 * PI / TABLE_INTERVALS as f64;
        let rows: Vec<(Spectrum, f64)> = (0..=TABLE_INTERVALS)
            .into_par_iter()
            .map(|k| {
                let theta = (k as f64 * step).min(0.5 * PI - 1e-6);
                if let TableEntries::Adaptive { tolerance } = entries {
                    return self.albedo_adaptive(theta.cos(), tolerance);
                }
                let w = Vec3::new(theta.sin(), 0.0, theta.cos());
                let mut rng = Pcg32::new(0x00a1_bed0, k as u64);
                let mut means = [Spectrum::ZERO; ROT];
                for mean in means.iter_mut() {
                    let shift = rng.next_2d();
                    let mut s = Spectrum::ZERO;
                    for j in 0..per {
                        if let Some((_, weight)) =
                            self.sample_specular(w, hammersley(j, per, shift))
                        {
                            s += weight;
                        }
                    }
                    *mean = s / per as f64;
                }
                let mean = means.iter().fold(Spectrum::ZERO, |a, &b| a + b) / ROT as f64;
                let var = means
                    .iter()
                    .map(|m| (*m - mean).average().powi(2))
                    .sum::<f64>()
                    / (ROT as f64 - 1.0);
                (mean, (var / ROT as f64).sqrt())
            })
            .collect();
        t.albedo = rows
            .iter()
            .map(|r| r.0.map(|v| v.clamp(0.0, 1.0)))
            .collect();
        t.entry_errors = rows.iter().map(|r| r.1).collect();
        t.albedo_error = rows.iter().map(|r| r.1).fold(0.0, f64::max);
        // ā_s = 2 ∫ a_s(θ) cos θ sin θ dθ of the interpolated table, segment by segment.
        let gl = GaussLegendre::new(8);
        let mut avg = Spectrum::ZERO;
        for seg in 0..TABLE_INTERVALS {
            let (t0, t1) = (seg as f64 * step, (seg + 1) as f64 * step);
            for c in 0..crate::math::spectrum::CHANNELS {
                avg[c] +=
                    2.0 * gl.integrate(t0, t1, |x| albedo_in(&t.albedo, x)[c] * x.cos() * x.sin());
            }
        }
        t.average = avg;
        // Matte sampling: g(θ) = (1 − ā_s(θ)) cos θ sin θ, piecewise linear on the grid.
        t.matte_g = (0..=TABLE_INTERVALS)
            .map(|k| {
                let x = k as f64 * step;
                (1.0 - t.albedo[k].average()).max(0.0) * x.cos() * x.sin()
            })
            .collect();
        let mut cdf = vec![0.0; TABLE_INTERVALS + 1];
        for k in 0..TABLE_INTERVALS {
            cdf[k + 1] = cdf[k] + 0.5 * (t.matte_g[k] + t.matte_g[k + 1]) * step;
        }
        t.matte_cdf = cdf;
        t
    }

    /// Interpolated a_s(θ).
    pub fn albedo_at(&self, theta: f64) -> Spectrum {
        albedo_in(&self.tables.albedo, theta)
    }

    /// The average specular albedo ā_s.
    pub fn average_albedo(&self) -> Spectrum {
        self.tables.average
    }

    /// Largest standard error of the a_s table entries (sampled entries), or their largest
    /// estimated absolute error (adaptive entries).
    pub fn albedo_table_stderr(&self) -> f64 {
        self.tables.albedo_error
    }

    /// The tabulated a_s(θ_k) at θ_k = k·1° (k = 0…90; 90° is evaluated 1e-6 rad above the
    /// horizon) and its error: the standard error (sampled entries, channel average) or
    /// the estimated absolute error (adaptive entries).
    pub fn albedo_table_entry(&self, k: usize) -> (Spectrum, f64) {
        (self.tables.albedo[k], self.tables.entry_errors[k])
    }

    /// KSK01 §2.2.1's Russian-roulette probabilities for a path arriving along `wo`:
    /// (specular a_s, matte k̃ (1 − a_s), terminate (1 − k̃)(1 − a_s)).
    pub fn lobe_probabilities(&self, wo: Vec3) -> (f64, f64, f64) {
        let a = self.albedo_at(wo.z.abs().min(1.0).acos()).average();
        let k = self.kd.average();
        (a, k * (1.0 - a), (1.0 - k) * (1.0 - a))
    }

    /// Probability with which `sample` picks the specular lobe (the first two outcomes of
    /// `lobe_probabilities`, renormalized).
    fn specular_choice(&self, wo: Vec3) -> f64 {
        let (s, m, _) = self.lobe_probabilities(wo);
        if s + m <= 0.0 {
            1.0
        } else {
            s / (s + m)
        }
    }

    /// KSK01 eq. 3.
    #[inline]
    fn specular(&self, o: Vec3, i: Vec3) -> Spectrum {
        let hv = o + i;
        let hh = hv.length_squared();
        if hh <= 0.0 {
            return Spectrum::ZERO;
        }
        let h = hv / hh.sqrt();
        let p = self.density.density(h);
        if p == 0.0 {
            return Spectrum::ZERO;
        }
        // 2 (1 + L·V) = |L + V|².
        self.fresnel.eval(o.dot(h)) * (p / hh)
    }

    /// KSK01 §2.2.
    #[inline]
    fn matte(&self, o: Vec3, i: Vec3) -> Spectrum {
        let ao = self.albedo_at(o.z.min(1.0).acos());
        let ai = self.albedo_at(i.z.min(1.0).acos());
        let denom = Spectrum::ONE - self.tables.average;
        let num = (Spectrum::ONE - ao) * (Spectrum::ONE - ai);
        self.kd * num.zip(denom, |n, d| if d > 0.0 { n / d } else { 0.0 }) / PI
    }

    /// Specular sample from `o` (upper hemisphere): (wi, weight f_s cos/pdf_s).
    fn sample_specular(&self, o: Vec3, u: crate::math::Vec2) -> Option<(Vec3, Spectrum)> {
        let h = self.density.sample(u);
        let c = o.dot(h);
        if c <= 0.0 {
            return None;
        }
        let i = reflect(o, h);
        if i.z <= 0.0 {
            return None;
        }
        let ps = self.density.sample_pdf(h);
        if !(ps > 0.0) {
            return None;
        }
        // f_s cos θ_i / (p_s / (4 c)) = P_H F cos θ_i / (c p_s)   [KSK01 §2.1.5].
        Some((
            i,
            self.fresnel.eval(c) * (self.density.density(h) * i.z / (c * ps)),
        ))
    }

    fn pdf_specular(&self, o: Vec3, i: Vec3) -> f64 {
        let h = (o + i).normalize_or_zero();
        let c = o.dot(h);
        if h.z <= 0.0 || c <= 0.0 {
            return 0.0;
        }
        self.density.sample_pdf(h) / (4.0 * c)
    }

    fn pdf_matte(&self, i: Vec3) -> f64 {
        let theta = i.z.min(1.0).acos();
        let step = 0.5 * PI / TABLE_INTERVALS as f64;
        let x = (theta / step).clamp(0.0, TABLE_INTERVALS as f64);
        let k = crate::math::cell_index(x, TABLE_INTERVALS);
        let t = x - k as f64;
        let g = self.tables.matte_g[k] * (1.0 - t) + self.tables.matte_g[k + 1] * t;
        let total = self.tables.matte_cdf[TABLE_INTERVALS];
        let s = theta.sin();
        if total <= 0.0 || s <= 0.0 {
            // θ = 0 has measure zero; return the density's limit along the axis.
            return if total > 0.0 {
                (1.0 - self.tables.albedo[0].average()) / (TWO_PI * total)
            } else {
                0.0
            };
        }
        g / (TWO_PI * s * total)
    }

    fn sample_matte(&self, u: crate::math::Vec2) -> Option<Vec3> {
        let tables = &self.tables;
        let total = tables.matte_cdf[TABLE_INTERVALS];
        if total <= 0.0 {
            return None;
        }
        let target = u.x * total;
        let k = match tables.matte_cdf.binary_search_by(|c| c.total_cmp(&target)) {
            Ok(k) => k.min(TABLE_INTERVALS - 1),
            Err(k) => k.saturating_sub(1).min(TABLE_INTERVALS - 1),
        };
        let step = 0.5 * PI / TABLE_INTERVALS as f64;
        // Invert the quadratic cumulative of the linear g on [θ_k, θ_k+1].
        let (g0, g1) = (tables.matte_g[k], tables.matte_g[k + 1]);
        let r = target - tables.matte_cdf[k];
        let slope = (g1 - g0) / step;
        let dt = if slope.abs() < 1e-14 {
            if g0 > 0.0 {
                r / g0
            } else {
                0.0
            }
        } else {
            let disc = (g0 * g0 + 2.0 * slope * r).max(0.0);
            (disc.sqrt() - g0) / slope
        };
        let theta = (k as f64 * step + dt.clamp(0.0, step)).min(0.5 * PI);
        let phi = TWO_PI * u.y;
        let i = Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        );
        (i.z > 0.0).then_some(i)
    }
}

impl OpaqueBsdf for Kelemen {
    fn flags(&self) -> LobeFlags {
        LobeFlags::GLOSSY_REFLECTION | LobeFlags::DIFFUSE_REFLECTION
    }

    fn eval(&self, wo: Vec3, wi: Vec3, _: &BsdfContext, _: &mut dyn RandomSource) -> Spectrum {
        self.specular(wo, wi) + self.matte(wo, wi)
    }

    fn sample(
        &self,
        wo: Vec3,
        ctx: &BsdfContext,
        rng: &mut dyn RandomSource,
    ) -> Option<BsdfSample> {
        let o = wo;
        let ps = self.specular_choice(o);
        let (i, lobe) = if rng.next_f64() < ps {
            (
                self.sample_specular(o, rng.next_2d())?.0,
                LobeFlags::GLOSSY_REFLECTION,
            )
        } else {
            (
                self.sample_matte(rng.next_2d())?,
                LobeFlags::DIFFUSE_REFLECTION,
            )
        };
        let pdf = self.pdf(o, i, ctx);
        if !(pdf > 0.0) {
            return None;
        }
        let f = self.specular(o, i) + self.matte(o, i);
        Some(BsdfSample {
            wi: i,
            weight: f * (i.z / pdf),
            pdf,
            lobe,
            eta: 1.0,
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, _: &BsdfContext) -> f64 {
        let ps = self.specular_choice(wo);
        ps * self.pdf_specular(wo, wi) + (1.0 - ps) * self.pdf_matte(wi)
    }

    fn lobe_width(&self) -> f64 {
        self.density.typical_width()
    }

    fn describe(&self) -> String {
        let r = match self.density {
            HalfVectorDensity::Ward { m } | HalfVectorDensity::Beckmann { m } => {
                format!("alpha={}", crate::math::fmt_num(m))
            }
            HalfVectorDensity::Phong { n } => format!("exponent={}", crate::math::fmt_num(n)),
        };
        format!(
            "kelemen({} {r}, kd={:?}, {:?})",
            self.density.name(),
            self.kd.0,
            self.fresnel
        )
    }
}

/// a_s(θ) linearly interpolated in `table`.
fn albedo_in(table: &[Spectrum], theta: f64) -> Spectrum {
    let x = (theta / (0.5 * PI) * TABLE_INTERVALS as f64).clamp(0.0, TABLE_INTERVALS as f64);
    let k = crate::math::cell_index(x, TABLE_INTERVALS);
    let t = x - k as f64;
    table[k] * (1.0 - t) + table[k + 1] * t
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::adaptive_quadrature::{integrate_2d, InnerRange, Tolerance};
    use crate::math::spherical_direction;

    /// a_s(θ_o) [KSK01 §2.1.5] by an independent quadrature: f_s(o, i) cos θ_i over the
    /// hemisphere of i in (φ_i, θ_i), cut at the mirror direction (θ_o, π) ± a few widths.
    fn albedo_over_directions(k: &Kelemen, theta_o: f64, width: f64) -> (f64, f64) {
        let o = Vec3::new(theta_o.sin(), 0.0, theta_o.cos());
        let dphi: Vec<f64> = [0.5, 1.0, 2.0, 4.0]
            .iter()
            .flat_map(|s| {
                let d = (2.0 * s * width / theta_o.sin().max(1e-3)).min(0.9 * PI);
                [PI - d, PI + d]
            })
            .collect();
        let q = integrate_2d(
            0.0,
            TWO_PI,
            &[&[PI][..], &dphi].concat(),
            Tolerance::relative(1e-10),
            |_| InnerRange {
                lo: 0.0,
                hi: 0.5 * PI,
                breaks: [-4.0, -2.0, -1.0, 0.0, 1.0, 2.0, 4.0]
                    .iter()
                    .map(|s| theta_o + 2.0 * s * width)
                    .collect(),
            },
            |phi, theta| {
                let i = spherical_direction(theta, phi);
                k.specular(o, i)[0] * i.z * theta.sin()
            },
        );
        (q.value, q.error)
    }

    #[test]
    fn adaptive_albedo_table_meets_its_tolerance() {
        for (density, tol) in [
            (HalfVectorDensity::new("ward", 0.3).unwrap(), 1e-6),
            (HalfVectorDensity::new("beckmann", 0.1).unwrap(), 1e-4),
            (HalfVectorDensity::new("phong", 40.0).unwrap(), 1e-6),
        ] {
            let fresnel = Fresnel::Dielectric { eta: 1.5 };
            let kd = Spectrum::splat(0.5);
            let k = Kelemen::with_entries(
                density,
                fresnel,
                kd,
                TableEntries::Adaptive { tolerance: tol },
            )
            .unwrap();
            assert!(k.albedo_table_stderr() <= tol);
            let sampled = Kelemen::new(density, fresnel, kd, 1 << 16).unwrap();
            for deg in [0, 30, 60, 80, 89] {
                let (a, est) = k.albedo_table_entry(deg);
                let (r, r_err) =
                    albedo_over_directions(&k, (deg as f64).to_radians(), density.typical_width());
                let err = (a[0] - r).abs();
                let what = format!(
                    "{} at {deg}°: {a:?} ± {est:.1e} vs {r} ± {r_err:.1e}",
                    density.name()
                );
                assert!(err <= tol * r + r_err + 1e-12, "{what}");
                assert!(err <= est + r_err + 1e-12, "{what}");
                // The QMC table agrees within its standard errors.
                let (b, se) = sampled.albedo_table_entry(deg);
                assert!(
                    (b[0] - a[0]).abs() <= 4.0 * se + tol,
                    "{what}: QMC {b:?} ± {se:.1e}"
                );
            }
        }
        // The tolerance is validated with the key's name and range.
        let e = Kelemen::with_entries(
            HalfVectorDensity::new("ward", 0.3).unwrap(),
            Fresnel::Dielectric { eta: 1.5 },
            Spectrum::splat(0.5),
            TableEntries::Adaptive { tolerance: 0.2 },
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("table_tolerance") && e.contains("0.1"), "{e}");
    }
}
