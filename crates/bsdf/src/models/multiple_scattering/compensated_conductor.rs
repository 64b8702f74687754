//! Rough conductor with energy compensation (`energy = "compensated"`): today's
//! single-scattering lobe plus the deterministic lobe of Kulla & Conty 2017 [KC17] that
//! returns, on average, the energy single scattering loses (see
//! [`albedo_tables`](super::albedo_tables) for E and its tables):
//!
//! f = f_ss + F_ms (1 − E(μ_o)) (1 − E(μ_i)) / (π (1 − E_avg))
//!
//! with E the directional albedo of the lobe with F = 1. The second term integrates to
//! 1 − E(μ_o) over the hemisphere, so a white conductor (F = 1) reflects E + (1 − E) = 1 at
//! every angle up to the table's error. With a coloured Fresnel term the missing light has
//! met several facets; KC17 account for it by the factor
//! F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg)), F_avg = 2 ∫ F(μ) μ dμ (per channel, the
//! `specular_reflectance` folded into F): the light reflected at least once more after
//! being trapped, summed as a geometric series of bounces that each keep F_avg and escape
//! with probability E_avg. The lobe is symmetric in μ_i and μ_o, so the BRDF stays
//! reciprocal.
//!
//! **Sampling.** With probability E(μ_o) the single-scattering lobe's sampler; otherwise the
//! compensation lobe's exact sampler (density (1 − E(μ_i)) μ_i / (π (1 − E_avg))). The pdf
//! is the exact mixture and the weight eval·cos/pdf; a direction drawn from the lobe reuses
//! the lobe's own density and value instead of evaluating them again.
//!
//! **Cost.** E is read from the table's row at the material's α ([`AlbedoRow`]), blended
//! once when the material is built: a lookup is a square root and a multiply–add, so the
//! compensated model costs the single-scattering lobe plus two lookups (issue 16 point 7
//! asks ≤ 1.3× the lobe's cost; measured in docs/performance.md).

use super::albedo_row::AlbedoRow;
use super::albedo_tables::{table_alpha, AlbedoTable, TableFresnel};
use crate::bsdf::{BsdfContext, BsdfSample, LobeFlags};
use crate::error::{ParamError, ParamResult};
use crate::finite::guard;
use crate::math::quadrature::GaussLegendre;
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::{Vec3, INV_PI, TWO_PI};
use crate::microfacet::specular_lobe::SpecularLobe;
use crate::models::rough_conductor::RoughConductor;
use crate::two_sided::OpaqueBsdf;
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct CompensatedConductor {
    single: RoughConductor,
    table: Arc<AlbedoTable>,
    /// The table's row at the lobe's α.
    row: AlbedoRow,
    /// F_ms / (π (1 − E_avg)) per channel: the compensation lobe is this times
    /// (1 − E(μ_o)) (1 − E(μ_i)).
    scale: Spectrum,
}

/// F_avg = 2 ∫₀¹ F(μ) μ dμ per channel (64-point Gauss–Legendre).
pub fn fresnel_average(f: impl Fn(f64) -> Spectrum) -> Spectrum {
    let rule = GaussLegendre::shared64();
    let mut s = Spectrum::ZERO;
    for (x, w) in rule.nodes.iter().zip(&rule.weights) {
        let mu = 0.5 * (x + 1.0);
        s += f(mu) * (w * mu);
    }
    s
}

impl CompensatedConductor {
    /// Adds the compensation lobe to a rough conductor (Beckmann or GGX).
    pub fn new(single: RoughConductor) -> ParamResult<Self> {
        let lobe = single.lobe().ok_or_else(|| {
            ParamError::Invalid("a smooth conductor loses no energy: nothing to compensate".into())
        })?;
        let table = AlbedoTable::shared(&lobe.ndf, lobe.masking, TableFresnel::One)?;
        let alpha = table_alpha(&lobe.ndf);
        let e_avg = table.average(alpha);
        let f_avg = fresnel_average(|mu| single.fresnel().eval(mu)) * single.tint();
        let missing = 1.0 - e_avg;
        let scale = if missing > 1e-12 {
            // F_ms [KC17]; 1 − F_avg (1 − E_avg) ≥ E_avg > 0.
            f_avg.map(|f| f * f * e_avg / (1.0 - f * missing)) * (INV_PI / missing)
        } else {
            Spectrum::ZERO
        };
        Ok(CompensatedConductor {
            single,
            row: table.row_at(alpha),
            table,
            scale,
        })
    }

    pub fn single(&self) -> &RoughConductor {
        &self.single
    }

    pub fn table(&self) -> &AlbedoTable {
        &self.table
    }

    fn lobe(&self) -> &SpecularLobe {
        self.single.lobe().expect("checked in new")
    }

    /// The compensation lobe for an upper-hemisphere pair, from 1 − E of each side.
    #[inline]
    fn compensation(&self, missing_o: f64, i: Vec3) -> Spectrum {
        self.scale * (missing_o * self.row.missing(i.z))
    }

    /// Probability of drawing from the single-scattering lobe, E(μ_o), and 1 − E(μ_o) (at
    /// least 0).
    #[inline]
    fn single_share(&self, o: Vec3) -> (f64, f64) {
        if self.scale.is_black() {
            return (1.0, 0.0);
        }
        let e = self.row.albedo(o.z);
        (e.clamp(0.0, 1.0), (1.0 - e).max(0.0))
    }

    /// The mixture density from the lobe's density `lobe_pdf` of the pair.
    #[inline]
    fn mixture_pdf(&self, share: f64, lobe_pdf: f64, i: Vec3) -> f64 {
        share * lobe_pdf + (1.0 - share) * self.row.lobe_density(i.z)
    }
}

impl OpaqueBsdf for CompensatedConductor {
    fn flags(&self) -> LobeFlags {
        LobeFlags::GLOSSY_REFLECTION | LobeFlags::DIFFUSE_REFLECTION
    }

    fn eval(&self, wo: Vec3, wi: Vec3, ctx: &BsdfContext, rng: &mut dyn RandomSource) -> Spectrum {
        let missing_o = self.single_share(wo).1;
        self.single.eval(wo, wi, ctx, rng) + self.compensation(missing_o, wi)
    }

    fn sample(
        &self,
        wo: Vec3,
        ctx: &BsdfContext,
        rng: &mut dyn RandomSource,
    ) -> Option<BsdfSample> {
        let o = wo;
        let (share, missing_o) = self.single_share(o);
        // The lobe's value f_ss and density of the drawn pair.
        let (i, f_ss, lobe_pdf, lobe) = if rng.next_f64() < share {
            let lobe = self.lobe();
            let (i, _, lobe_pdf) = lobe.sample(o, rng.next_2d())?;
            let f_ss = self.single.tint() * lobe.eval(o, i, |c| self.single.fresnel().eval(c));
            (i, f_ss, lobe_pdf, LobeFlags::GLOSSY_REFLECTION)
        } else {
            let mu = self.row.sample_mu(rng)?;
            let r = (1.0 - mu * mu).max(0.0).sqrt();
            let (s, c) = (TWO_PI * rng.next_f64()).sin_cos();
            let i = Vec3::new(r * c, r * s, mu);
            let f_ss = self.single.eval(o, i, ctx, rng);
            (
                i,
                f_ss,
                self.lobe().pdf(o, i),
                LobeFlags::DIFFUSE_REFLECTION,
            )
        };
        if i.z <= 0.0 {
            return None;
        }
        let pdf = self.mixture_pdf(share, lobe_pdf, i);
        if !(pdf > 0.0) {
            return None;
        }
        let weight = (f_ss + self.compensation(missing_o, i)) * (i.z / pdf);
        weight.is_finite().then_some(BsdfSample {
            wi: i,
            weight,
            pdf,
            lobe,
            eta: 1.0,
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, _: &BsdfContext) -> f64 {
        let (o, i) = (wo, wi);
        let (share, _) = self.single_share(o);
        let p = self.mixture_pdf(share, self.lobe().pdf(o, i), i);
        guard(p, || {
            format!("{} pdf(wo = {wo:?}, wi = {wi:?})", self.describe())
        })
    }

    fn albedo_excess(&self) -> f64 {
        super::albedo_tables::COMPENSATION_ERROR
    }

    fn lobe_width(&self) -> f64 {
        self.single.lobe_width()
    }

    fn describe(&self) -> String {
        let s = self.single.describe();
        format!("{}, energy=compensated)", s.strip_suffix(')').unwrap_or(&s))
    }
}
