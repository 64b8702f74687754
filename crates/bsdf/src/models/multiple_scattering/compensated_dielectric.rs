//! Rough dielectric with energy compensation (`energy = "compensated"`): WMLT07's
//! single-scattering BSDF plus the deterministic lobes of Kulla & Conty 2017 [KC17,
//! "dielectrics"] that restore, on each side, the energy single scattering loses, split
//! between reflection and transmission so that the result keeps WMLT07's generalized
//! reciprocity f(i, o)/η_o² = f(o, i)/η_i² (ERRATA 11).
//!
//! Let E_A(μ) be the single-scattering albedo (reflection + transmission, exact Fresnel, no
//! tints) for light arriving from side A (outside: relative index η; inside: 1/η), Ē_A its
//! cosine-weighted average (see [`albedo_tables`](super::albedo_tables)). For light i on
//! side A and view o on side B (f(i, o), i the light direction):
//!
//! - reflection (B = A): x_R,A (1 − E_A(μ_i)) (1 − E_A(μ_o)) / (π (1 − Ē_A)),
//! - transmission (B ≠ A): x_T,A (1 − E_A(μ_i)) (1 − E_B(μ_o)) / (π (1 − Ē_B)),
//!
//! with x_R,A + x_T,A = 1: light from i gets back exactly the 1 − E_A(μ_i) it lacked,
//! x_R,A of it on its own side. Generalized reciprocity of the transmission lobes requires
//! x_T,out (1 − Ē_out) = η² x_T,in (1 − Ē_in). KC17 take x_T,A proportional to the diffuse
//! transmittance 1 − F_avg,A of a flat interface (F_avg,out = r_e, F_avg,in = r_i of IL18
//! eq. 11, with η² (1 − r_i) = 1 − r_e) times a share fixed by that condition:
//! x_T,out = (1 − r_e) x, x_T,in = (1 − r_i)(1 − x), x = (1 − Ē_in)/((1 − Ē_out) + (1 − Ē_in)).
//! The tints multiply the lobes of their kind (`specular_reflectance` the reflection lobes,
//! `specular_transmittance` the transmission lobes). The split is a model: the tests measure
//! it against the random walk's reflectance and transmittance.
//!
//! **Sampling.** With probability E_A(μ_o) for the view's side A, WMLT07's sampler; otherwise
//! reflection (probability x_R,A) or transmission, with μ drawn from the compensation lobe's
//! exact density on that side. The pdf is the exact mixture, the weight eval·|cos|/pdf.

use super::albedo_tables::{table_alpha, AlbedoTable, TableFresnel};
use crate::bsdf::{Bsdf, BsdfContext, BsdfSample, LobeFlags, TransportMode};
use crate::error::{ParamError, ParamResult};
use crate::finite::guard;
use crate::fresnel::{external_diffuse_reflectance, internal_diffuse_reflectance};
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::{Vec3, INV_PI, TWO_PI};
use crate::models::rough_dielectric::RoughDielectric;
use std::sync::Arc;

/// What the compensation lobes need for one side of the interface.
#[derive(Clone, Debug)]
struct Side {
    table: Arc<AlbedoTable>,
    /// Ē at the material's α.
    average: f64,
    /// x_T: the transmitted share of the missing energy of light arriving from this side.
    transmitted: f64,
}

#[derive(Clone, Debug)]
pub struct CompensatedDielectric {
    single: RoughDielectric,
    alpha: f64,
    outside: Side,
    inside: Side,
    reflect_tint: Spectrum,
    transmit_tint: Spectrum,
}

/// Hemispherical average of the Fresnel reflectance of a flat interface seen from the side
/// whose far-side relative index is `eta` (r_e for η > 1, r_i of 1/η for η < 1).
fn fresnel_average(eta: f64) -> f64 {
    if eta >= 1.0 {
        external_diffuse_reflectance(eta)
    } else {
        internal_diffuse_reflectance(1.0 / eta)
    }
}

impl CompensatedDielectric {
    /// Adds the compensation lobes to a rough dielectric (Beckmann or GGX).
    pub fn new(single: RoughDielectric) -> ParamResult<Self> {
        let lobe = single.lobe().ok_or_else(|| {
            ParamError::Invalid("a smooth dielectric loses no energy: nothing to compensate".into())
        })?;
        let eta = single.eta();
        let alpha = table_alpha(&lobe.ndf);
        let out_t = AlbedoTable::shared(&lobe.ndf, lobe.masking, TableFresnel::Dielectric(eta))?;
        let in_t =
            AlbedoTable::shared(&lobe.ndf, lobe.masking, TableFresnel::Dielectric(1.0 / eta))?;
        let (avg_out, avg_in) = (out_t.average(alpha), in_t.average(alpha));
        let (miss_out, miss_in) = ((1.0 - avg_out).max(0.0), (1.0 - avg_in).max(0.0));
        let x = if miss_out + miss_in > 1e-12 {
            miss_in / (miss_out + miss_in)
        } else {
            0.5
        };
        let (tints_r, tints_t) = single.tints();
        Ok(CompensatedDielectric {
            alpha,
            outside: Side {
                table: out_t,
                average: avg_out,
                transmitted: (1.0 - fresnel_average(eta)) * x,
            },
            inside: Side {
                table: in_t,
                average: avg_in,
                transmitted: (1.0 - fresnel_average(1.0 / eta)) * (1.0 - x),
            },
            reflect_tint: tints_r,
            transmit_tint: tints_t,
            single,
        })
    }

    pub fn single(&self) -> &RoughDielectric {
        &self.single
    }

    /// The tables of the outside and inside (E for light from each side).
    pub fn tables(&self) -> (&AlbedoTable, &AlbedoTable) {
        (&self.outside.table, &self.inside.table)
    }

    /// x_T of the outside and of the inside.
    pub fn transmitted_shares(&self) -> (f64, f64) {
        (self.outside.transmitted, self.inside.transmitted)
    }

    #[inline]
    fn side(&self, w: Vec3) -> &Side {
        if w.z > 0.0 {
            &self.outside
        } else {
            &self.inside
        }
    }

    /// 1 − E_side(μ) for a direction on that side.
    #[inline]
    fn missing(&self, w: Vec3) -> f64 {
        (1.0 - self.side(w).table.albedo(w.z.abs(), self.alpha)).max(0.0)
    }

    /// The compensation lobes, f(i, o) with i the light direction.
    fn compensation(&self, i: Vec3, o: Vec3) -> Spectrum {
        let (a, b) = (self.side(i), self.side(o));
        let norm = 1.0 - b.average;
        if !(norm > 1e-12) {
            return Spectrum::ZERO;
        }
        let v = self.missing(i) * self.missing(o) * INV_PI / norm;
        if i.z * o.z > 0.0 {
            self.reflect_tint * ((1.0 - a.transmitted) * v)
        } else {
            self.transmit_tint * (a.transmitted * v)
        }
    }

    /// Probability of drawing from WMLT07's sampler: E of the view's side.
    #[inline]
    fn single_share(&self, wo: Vec3) -> f64 {
        1.0 - self.missing(wo)
    }
}

impl Bsdf for CompensatedDielectric {
    fn flags(&self) -> LobeFlags {
        LobeFlags::GLOSSY_REFLECTION
            | LobeFlags::GLOSSY_TRANSMISSION
            | LobeFlags::DIFFUSE_REFLECTION
            | LobeFlags::DIFFUSE_TRANSMISSION
    }

    fn eval(&self, wo: Vec3, wi: Vec3, ctx: &BsdfContext, rng: &mut dyn RandomSource) -> Spectrum {
        if wo.z == 0.0 || wi.z == 0.0 {
            return Spectrum::ZERO;
        }
        let (i, o) = match ctx.mode {
            TransportMode::Radiance => (wi, wo),
            TransportMode::Importance => (wo, wi),
        };
        let v = self.single.eval(wo, wi, ctx, rng) + self.compensation(i, o);
        guard(v, || {
            format!(
                "{} eval(wo = {wo:?}, wi = {wi:?}, {:?})",
                self.describe(),
                ctx.mode
            )
        })
    }

    fn sample(
        &self,
        wo: Vec3,
        ctx: &BsdfContext,
        rng: &mut dyn RandomSource,
    ) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let (wi, lobe) = if rng.next_f64() < self.single_share(wo) {
            let s = self.single.sample(wo, ctx, rng)?;
            (s.wi, s.lobe)
        } else {
            let here = self.side(wo);
            let reflect = rng.next_f64() >= here.transmitted;
            let there = match (reflect, wo.z > 0.0) {
                (true, _) => here,
                (false, true) => &self.inside,
                (false, false) => &self.outside,
            };
            let mu = there.table.sample_mu(self.alpha, rng)?;
            let r = (1.0 - mu * mu).max(0.0).sqrt();
            let (s, c) = (TWO_PI * rng.next_f64()).sin_cos();
            let z = if (wo.z > 0.0) == reflect { mu } else { -mu };
            let lobe = if reflect {
                LobeFlags::DIFFUSE_REFLECTION
            } else {
                LobeFlags::DIFFUSE_TRANSMISSION
            };
            (Vec3::new(r * c, r * s, z), lobe)
        };
        if wi.z == 0.0 {
            return None;
        }
        let pdf = self.pdf(wo, wi, ctx);
        if !(pdf > 0.0) {
            return None;
        }
        let weight = self.eval(wo, wi, ctx, rng) * (wi.z.abs() / pdf);
        let transmitted = wi.z * wo.z < 0.0;
        let eta = match (transmitted, wo.z > 0.0) {
            (false, _) => 1.0,
            (true, true) => self.single.eta(),
            (true, false) => 1.0 / self.single.eta(),
        };
        weight.is_finite().then_some(BsdfSample {
            wi,
            weight,
            pdf,
            lobe,
            eta,
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, ctx: &BsdfContext) -> f64 {
        if wo.z == 0.0 || wi.z == 0.0 {
            return 0.0;
        }
        let ps = self.single_share(wo);
        let here = self.side(wo);
        let lobe = if wi.z * wo.z > 0.0 {
            (1.0 - here.transmitted) * here.table.lobe_density(wi.z.abs(), self.alpha)
        } else {
            here.transmitted * self.side(wi).table.lobe_density(wi.z.abs(), self.alpha)
        };
        let p = ps * self.single.pdf(wo, wi, ctx) + (1.0 - ps) * lobe;
        guard(p, || {
            format!("{} pdf(wo = {wo:?}, wi = {wi:?})", self.describe())
        })
    }

    fn lobe_width(&self) -> f64 {
        self.single.lobe_width()
    }

    fn relative_ior(&self) -> Option<f64> {
        Some(self.single.eta())
    }

    fn describe(&self) -> String {
        let s = self.single.describe();
        format!("{}, energy=compensated)", s.strip_suffix(')').unwrap_or(&s))
    }
}
