//! Rough dielectric (WMLT07): microfacet reflection and refraction from either side of an
//! interface between the outside (index 1 relative, the side the normal points to) and an
//! inside of relative index η.
//!
//! - f_r(i,o) = F(i,h_r) G(i,o,h_r) D(h_r) / (4 |i·n| |o·n|), h_r ∝ ±(i + o)  [WMLT07 eqs. 13, 20]
//! - f_t(i,o) = |i·h_t||o·h_t| / (|i·n||o·n|) · η_o² (1 − F(i,h_t)) G D(h_t) / (η_i (i·h_t) + η_o (o·h_t))²,
//!   h_t ∝ −(η_i i + η_o o)  [WMLT07 eqs. 16, 21]
//!
//! with i the light direction. The BTDF is not reciprocal, f_t(i,o)/η_o² = f_t(o,i)/η_i²
//! (ERRATA 11): in radiance mode `eval(wo, wi)` is f(i = wi, o = wo), in importance mode
//! f(i = wo, o = wi).
//!
//! Sampling follows WMLT07 §5.3: draw m (visible normals by default; D(m)|m·n| as in the
//! paper; or the widened Beckmann α† = (1.2 − 0.2 √|i·n|) α), choose reflection with
//! probability F(i, m), reflect [eq. 39] or refract [eq. 40]; the importance-mode weight is
//! eq. 41, |i·m| G / (|i·n| |m·n|) for the paper's sampler, and radiance mode multiplies the
//! transmitted weight by (η_o/η_i)² — the radiance compression across the interface.
//! When α = 0 the lobes are Dirac deltas.
//!
//! | key | meaning | range | default |
//! |---|---|---|---|
//! | microfacet keys | see `docs/materials.md` | | |
//! | `ior` | index of refraction of the inside | > 0, ≠ `ext_ior` | 1.5 |
//! | `ext_ior` | index of the outside | > 0 | 1 |
//! | `preset` | a measured rough glass of WMLT07 Fig. 12: `ground`, `frosted`, `etched`, `antiglare` (uses the Beckmann or GGX fit per `distribution`, n = 1.51) | — | — |
//! | `sampling` | `visible`, `distribution` or `widened` (Beckmann α† of WMLT07 §5.3) | — | `visible` |
//! | `specular_reflectance`, `specular_transmittance` | multipliers (number or RGB) | [0, 1] | 1 |

use crate::bsdf::{Bsdf, BsdfContext, BsdfSample, LobeFlags, TransportMode};
use crate::error::{ParamError, ParamResult};
use crate::finite::guard;
use crate::fresnel::fresnel_dielectric;
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::{fmt_num, reflect, refract, Vec2, Vec3};
use crate::microfacet::specular_lobe::SpecularLobe;
use crate::microfacet::{Distribution, Ndf};

/// A measured rough glass of WMLT07 Fig. 12 (fitted at normal incidence, n = 1.51).
#[derive(Clone, Copy, Debug)]
pub struct MeasuredGlass {
    pub name: &'static str,
    pub beckmann_alpha: f64,
    pub ggx_alpha: f64,
}

/// WMLT07 Fig. 12.
pub const MEASURED_GLASSES: &[MeasuredGlass] = &[
    MeasuredGlass {
        name: "ground",
        beckmann_alpha: 0.344,
        ggx_alpha: 0.394,
    },
    MeasuredGlass {
        name: "frosted",
        beckmann_alpha: 0.400,
        ggx_alpha: 0.454,
    },
    MeasuredGlass {
        name: "etched",
        beckmann_alpha: 0.493,
        ggx_alpha: 0.553,
    },
    MeasuredGlass {
        name: "antiglare",
        beckmann_alpha: 0.023,
        ggx_alpha: 0.027,
    },
];

/// Index of refraction of the measured glasses [WMLT07 §6.1].
pub const MEASURED_GLASS_IOR: f64 = 1.51;

#[derive(Clone, Debug)]
pub struct RoughDielectric {
    eta: f64,
    lobe: Option<SpecularLobe>,
    widened: bool,
    reflect_tint: Spectrum,
    transmit_tint: Spectrum,
}

impl RoughDielectric {
    /// `eta` = η_inside / η_outside. `widened` selects WMLT07's α† sampling (Beckmann only).
    pub fn new(
        eta: f64,
        lobe: Option<SpecularLobe>,
        widened: bool,
        reflect_tint: Spectrum,
        transmit_tint: Spectrum,
    ) -> ParamResult<Self> {
        crate::checks::check_range("eta", eta, 1e-3, 1e3, crate::checks::Bounds::Closed)?;
        if (eta - 1.0).abs() < 1e-4 {
            return Err(ParamError::Invalid(format!(
                "ior / ext_ior = {eta}: the two indices must differ (by at least 1e-4) for the \
                 interface to refract (WMLT07 §4.2)"
            )));
        }
        if let Some(l) = &lobe {
            if !l.masking.supports_transmission() {
                return Err(ParamError::Invalid(format!(
                    "masking `{}` is not defined for refraction; use `smith` or `smith-correlated`",
                    l.masking.name()
                )));
            }
            if widened && !matches!(l.ndf, Ndf::Beckmann(_)) {
                return Err(ParamError::Invalid(
                    "sampling = \"widened\" (WMLT07 §5.3) applies to the beckmann distribution"
                        .into(),
                ));
            }
        }
        Ok(RoughDielectric {
            eta,
            lobe,
            widened,
            reflect_tint,
            transmit_tint,
        })
    }

    pub fn eta(&self) -> f64 {
        self.eta
    }

    /// `None`: perfectly smooth.
    pub fn lobe(&self) -> Option<&SpecularLobe> {
        self.lobe.as_ref()
    }

    /// The `specular_reflectance` and `specular_transmittance` multipliers.
    pub fn tints(&self) -> (Spectrum, Spectrum) {
        (self.reflect_tint, self.transmit_tint)
    }

    /// True for WMLT07's widened Beckmann sampling.
    pub fn widened(&self) -> bool {
        self.widened
    }

    /// (index on the side of w, index on the other side), relative to the outside.
    #[inline]
    fn indices(&self, w: Vec3) -> (f64, f64) {
        if w.z > 0.0 {
            (1.0, self.eta)
        } else {
            (self.eta, 1.0)
        }
    }

    /// The widened Beckmann of WMLT07 §5.3 for a given |cos θ| of the sampled-from direction.
    #[inline]
    fn widened_ndf(&self, lobe: &SpecularLobe, cos_theta: f64) -> Ndf {
        let s = 1.2 - 0.2 * cos_theta.abs().sqrt();
        lobe.ndf.scaled(s).unwrap_or_else(|| lobe.ndf.clone())
    }

    /// Draws a microfacet normal for sampling from `wo` (either side).
    #[inline]
    fn sample_m(&self, lobe: &SpecularLobe, wo: Vec3, u: Vec2) -> Vec3 {
        if self.widened {
            return self.widened_ndf(lobe, wo.z).sample_normal(u);
        }
        // Seen from inside, the visible normals are those visible from −wo (the
        // distributions are centrally symmetric).
        let up = if wo.z > 0.0 { wo } else { -wo };
        lobe.sample_normal(up, u)
    }

    /// Density of [`Self::sample_m`].
    #[inline]
    fn pdf_m(&self, lobe: &SpecularLobe, wo: Vec3, m: Vec3) -> f64 {
        if self.widened {
            return self.widened_ndf(lobe, wo.z).pdf_normal(m);
        }
        let up = if wo.z > 0.0 { wo } else { -wo };
        lobe.normal_pdf(up, m)
    }

    /// Reflection or refraction half-vector for the pair (a, b), oriented to +z, with the
    /// sidedness checks of WMLT07 eq. 7; `None` for an impossible configuration.
    #[inline]
    fn half_vector(&self, a: Vec3, b: Vec3) -> Option<Vec3> {
        let h = if a.z * b.z > 0.0 {
            a + b
        } else {
            let (na, _) = self.indices(a);
            let (nb, _) = self.indices(b);
            -(na * a + nb * b)
        };
        let mut h = h.normalize_or_zero();
        if h == Vec3::ZERO {
            return None;
        }
        if h.z < 0.0 {
            h = -h;
        }
        if h.z == 0.0 || a.dot(h) * a.z <= 0.0 || b.dot(h) * b.z <= 0.0 {
            return None;
        }
        Some(h)
    }

    /// f(i, o) with i the light direction [WMLT07 eqs. 20–21].
    fn value(&self, lobe: &SpecularLobe, i: Vec3, o: Vec3) -> Spectrum {
        let Some(h) = self.half_vector(i, o) else {
            return Spectrum::ZERO;
        };
        let d = lobe.ndf.d(h);
        if d == 0.0 {
            return Spectrum::ZERO;
        }
        // |i·n||o·n| underflows to 0 when both directions lie within ~1e-154 of the tangent
        // plane (the NaN sweep's grazing pairs); G underflows with it, and f would be 0/0.
        // Such pairs are the tangent plane itself, where `eval` already returns 0.
        let cos_io = (i.z * o.z).abs();
        if cos_io == 0.0 {
            return Spectrum::ZERO;
        }
        let g = lobe.masking.g(&lobe.ndf, i, o, h);
        let (ni, nt) = self.indices(i);
        let ih = i.dot(h);
        let f = fresnel_dielectric(ih.abs(), nt / ni);
        if i.z * o.z > 0.0 {
            self.reflect_tint * (f * d * g / (4.0 * cos_io))
        } else {
            let no = nt;
            let oh = o.dot(h);
            let denom = ni * ih + no * oh;
            if denom == 0.0 {
                return Spectrum::ZERO;
            }
            let v = (ih * oh).abs() / cos_io * no * no * (1.0 - f) * g * d / (denom * denom);
            self.transmit_tint * v
        }
    }
}

impl Bsdf for RoughDielectric {
    fn flags(&self) -> LobeFlags {
        if self.lobe.is_some() {
            LobeFlags::GLOSSY_REFLECTION | LobeFlags::GLOSSY_TRANSMISSION
        } else {
            LobeFlags::DELTA_REFLECTION | LobeFlags::DELTA_TRANSMISSION
        }
    }

    fn eval(&self, wo: Vec3, wi: Vec3, ctx: &BsdfContext, _: &mut dyn RandomSource) -> Spectrum {
        let Some(lobe) = &self.lobe else {
            return Spectrum::ZERO;
        };
        if wo.z == 0.0 || wi.z == 0.0 {
            return Spectrum::ZERO;
        }
        let (i, o) = match ctx.mode {
            TransportMode::Radiance => (wi, wo),
            TransportMode::Importance => (wo, wi),
        };
        guard(self.value(lobe, i, o), || {
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
        let (n_o, n_t) = self.indices(wo);
        let radiance_scale = |n_wi: f64| match ctx.mode {
            TransportMode::Radiance => (n_o / n_wi) * (n_o / n_wi),
            TransportMode::Importance => 1.0,
        };
        let Some(lobe) = &self.lobe else {
            // Smooth interface: two Dirac lobes chosen by F.
            let f = fresnel_dielectric(wo.z.abs(), n_t / n_o);
            let u = rng.next_f64();
            return if u < f {
                Some(BsdfSample {
                    wi: Vec3::new(-wo.x, -wo.y, wo.z),
                    weight: self.reflect_tint,
                    pdf: f,
                    lobe: LobeFlags::DELTA_REFLECTION,
                    eta: 1.0,
                })
            } else {
                let n = if wo.z > 0.0 { Vec3::Z } else { -Vec3::Z };
                let wi = refract(wo, n, n_o / n_t)?;
                Some(BsdfSample {
                    wi,
                    weight: self.transmit_tint * radiance_scale(n_t),
                    pdf: 1.0 - f,
                    lobe: LobeFlags::DELTA_TRANSMISSION,
                    eta: n_t / n_o,
                })
            };
        };
        let m = self.sample_m(lobe, wo, rng.next_2d());
        let c = wo.dot(m);
        if c * wo.z <= 0.0 {
            return None;
        }
        let pm = self.pdf_m(lobe, wo, m);
        if !(pm > 0.0) {
            return None;
        }
        let f = fresnel_dielectric(c.abs(), n_t / n_o);
        let d = lobe.ndf.d(m);
        // D G |o·m| / (|o·n| p_m) — WMLT07 eq. 41 for the paper's sampler.
        let base =
            |wi: Vec3| d * lobe.masking.g(&lobe.ndf, wo, wi, m) * c.abs() / (wo.z.abs() * pm);
        if rng.next_f64() < f {
            let wi = reflect(wo, m);
            if wi.z * wo.z <= 0.0 {
                return None;
            }
            let w = base(wi);
            Some(BsdfSample {
                wi,
                weight: self.reflect_tint * w,
                pdf: pm * f / (4.0 * c.abs()),
                lobe: LobeFlags::GLOSSY_REFLECTION,
                eta: 1.0,
            })
            .filter(|s| s.weight.is_finite())
        } else {
            let wi = refract(wo, m, n_o / n_t)?;
            if wi.z * wo.z >= 0.0 {
                return None;
            }
            let wim = wi.dot(m);
            let denom = n_o * c + n_t * wim;
            if denom == 0.0 {
                return None;
            }
            let w = base(wi) * radiance_scale(n_t);
            Some(BsdfSample {
                wi,
                weight: self.transmit_tint * w,
                pdf: pm * (1.0 - f) * n_t * n_t * wim.abs() / (denom * denom),
                lobe: LobeFlags::GLOSSY_TRANSMISSION,
                eta: n_t / n_o,
            })
            .filter(|s| s.weight.is_finite() && s.pdf > 0.0)
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, _: &BsdfContext) -> f64 {
        let Some(lobe) = &self.lobe else {
            return 0.0;
        };
        if wo.z == 0.0 || wi.z == 0.0 {
            return 0.0;
        }
        let Some(h) = self.half_vector(wo, wi) else {
            return 0.0;
        };
        let (n_o, n_t) = self.indices(wo);
        let c = wo.dot(h);
        let f = fresnel_dielectric(c.abs(), n_t / n_o);
        let pm = self.pdf_m(lobe, wo, h);
        let p = if wo.z * wi.z > 0.0 {
            pm * f / (4.0 * c.abs())
        } else {
            let wih = wi.dot(h);
            let denom = n_o * c + n_t * wih;
            if denom == 0.0 {
                return 0.0;
            }
            pm * (1.0 - f) * n_t * n_t * wih.abs() / (denom * denom)
        };
        guard(p, || {
            format!("{} pdf(wo = {wo:?}, wi = {wi:?})", self.describe())
        })
    }

    fn lobe_width(&self) -> f64 {
        self.lobe.as_ref().map_or(0.0, |l| l.typical_width())
    }

    fn relative_ior(&self) -> Option<f64> {
        Some(self.eta)
    }

    fn describe(&self) -> String {
        match &self.lobe {
            Some(l) => format!(
                "dielectric({}, masking={}, sampling={}, eta={})",
                l.ndf.describe(),
                l.masking.name(),
                if self.widened {
                    "widened"
                } else {
                    l.sampling().name()
                },
                fmt_num(self.eta)
            ),
            None => format!("dielectric(smooth, eta={})", fmt_num(self.eta)),
        }
    }
}
