//! Rough dielectric with every order of scattering between microfacets
//! (`scattering = "multiple"`): the random walk on the Smith microsurface [HHdD16 §5,
//! dielectrics] of [`smith_microsurface`](super::smith_microsurface), crossing the interface
//! as often as the facets refract it. Each facet reflects with probability F (exact
//! dielectric Fresnel, WMLT07 eq. 22) and refracts otherwise [WMLT07 eqs. 39–40]; reflections
//! carry `specular_reflectance`, refractions `specular_transmittance`.
//!
//! The facet phase function is the visible-normal density of the incoming direction times
//! WMLT07's Jacobians: F D_wi(h)/(4 wi·h) for reflection [WMLT07 eq. 14],
//! (1 − F) D_wi(h) η_o² |wo·h| / (η_i wi·h + η_o wo·h)² for refraction [WMLT07 eq. 17], h the
//! half vector of WMLT07 eqs. 13 and 16; it is a probability density over the outgoing
//! direction, so the walk carries flux.
//!
//! - `eval`: WMLT07's single-scattering BSDF with the height-correlated Smith masking
//!   (exactly `scattering = "single"` with that masking) plus an unbiased estimate of the
//!   orders ≥ 2 by one walk with next-event estimation toward the other direction — the
//!   walk carries flux, so entered from the light direction `i` (radiance mode: `wi`;
//!   importance mode: `wo`) it estimates f(i, o) in WMLT07's convention, whose BTDF is not
//!   reciprocal (f(i,o)/η_o² = f(o,i)/η_i², ERRATA 11). The walk enters from the more masked
//!   of the two directions ([`Microsurface::walk_from_first`]: the low-variance choice); when
//!   that is `o` it estimates f(o, i), scaled by (η_o/η_i)².
//! - `sample`: the physical walk from `wo`, which simulates f(i = wo, o = wi) |wi·n|: its
//!   weight is the product of the tints met, times (η_o/η_i)² in radiance mode when it left
//!   on the other side (the radiance compression of the adjoint, as in
//!   [`RoughDielectric`]); for untinted glass, reflectance + transmittance is exactly 1 but
//!   for walks longer than [`MAX_ORDER`](super::smith_microsurface::MAX_ORDER).
//! - `pdf`: a proxy for multiple importance sampling ([`Bsdf::pdf_is_exact`] is false): the
//!   compensated dielectric's sampling density (see [`CompensatedDielectric`]) mixed with
//!   0.1 % of |cos θ|/2π over the sphere.

use super::compensated_dielectric::CompensatedDielectric;
use super::random_walk::{check_lobe, PROXY_COSINE_SHARE};
use super::smith_microsurface::{FacetScattering, HeightDistribution, Microsurface};
use crate::bsdf::{Bsdf, BsdfContext, BsdfSample, LobeFlags, TransportMode};
use crate::error::{ParamError, ParamResult};
use crate::finite::guard;
use crate::fresnel::fresnel_dielectric;
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::{reflect, refract, Vec3, TWO_PI};
use crate::models::rough_dielectric::RoughDielectric;

/// Dielectric facets between the outside (index 1) and the inside (index η).
#[derive(Clone, Debug)]
pub(super) struct DielectricFacets {
    eta: f64,
    reflect_tint: Spectrum,
    transmit_tint: Spectrum,
}

impl DielectricFacets {
    /// Untinted facets of relative index η (every event weight 1).
    pub(super) fn white(eta: f64) -> Self {
        DielectricFacets {
            eta,
            reflect_tint: Spectrum::ONE,
            transmit_tint: Spectrum::ONE,
        }
    }

    /// (index of the medium the light is in, index of the other).
    #[inline]
    fn indices(&self, inside: bool) -> (f64, f64) {
        if inside {
            (self.eta, 1.0)
        } else {
            (1.0, self.eta)
        }
    }
}

impl FacetScattering for DielectricFacets {
    #[inline]
    fn scatter(
        &self,
        wi: Vec3,
        m: Vec3,
        inside: bool,
        rng: &mut dyn RandomSource,
    ) -> Option<(Vec3, bool, Spectrum)> {
        let c = wi.dot(m);
        if c <= 0.0 {
            return None;
        }
        let (n1, n2) = self.indices(inside);
        let f = fresnel_dielectric(c, n2 / n1);
        if rng.next_f64() < f {
            Some((reflect(wi, m), false, self.reflect_tint))
        } else {
            Some((refract(wi, m, n1 / n2)?, true, self.transmit_tint))
        }
    }

    fn phase(&self, s: &Microsurface, wi: Vec3, wo: Vec3, inside: bool, crosses: bool) -> Spectrum {
        let (n1, n2) = self.indices(inside);
        if !crosses {
            let h = (wi + wo).normalize_or_zero();
            let c = wi.dot(h);
            if h.z <= 0.0 || c <= 0.0 {
                return Spectrum::ZERO;
            }
            let f = fresnel_dielectric(c, n2 / n1);
            return self.reflect_tint * (f * s.visible_density(wi, h) / (4.0 * c));
        }
        let mut h = -(n1 * wi + n2 * wo).normalize_or_zero();
        if h.z < 0.0 {
            h = -h;
        }
        let (c, co) = (wi.dot(h), wo.dot(h));
        if h.z <= 0.0 || c <= 0.0 || co >= 0.0 {
            return Spectrum::ZERO;
        }
        let denom = n1 * c + n2 * co;
        if denom == 0.0 {
            return Spectrum::ZERO;
        }
        let f = fresnel_dielectric(c, n2 / n1);
        let v = (1.0 - f) * s.visible_density(wi, h) * n2 * n2 * (-co) / (denom * denom);
        self.transmit_tint * v
    }
}

#[derive(Clone, Debug)]
pub struct MultipleScatteringDielectric {
    single: RoughDielectric,
    surface: Microsurface,
    facets: DielectricFacets,
    proxy: CompensatedDielectric,
}

impl MultipleScatteringDielectric {
    /// The multiple-scattering version of a rough dielectric, whose lobe must use the
    /// height-correlated Smith masking and visible-normal sampling.
    pub fn new(single: RoughDielectric, heights: HeightDistribution) -> ParamResult<Self> {
        let lobe = single.lobe().ok_or_else(|| {
            ParamError::Invalid("a smooth dielectric has no inter-reflections".into())
        })?;
        if single.widened() {
            return Err(ParamError::Invalid(
                "scattering = \"multiple\" samples by the random walk: `sampling` does not apply"
                    .into(),
            ));
        }
        check_lobe(lobe.masking, lobe.sampling())?;
        let surface = Microsurface::new(lobe.ndf.clone(), heights)?;
        let (reflect_tint, transmit_tint) = single.tints();
        let facets = DielectricFacets {
            eta: single.eta(),
            reflect_tint,
            transmit_tint,
        };
        let proxy = CompensatedDielectric::new(single.clone())?;
        Ok(MultipleScatteringDielectric {
            single,
            surface,
            facets,
            proxy,
        })
    }

    pub fn single(&self) -> &RoughDielectric {
        &self.single
    }

    pub fn surface(&self) -> &Microsurface {
        &self.surface
    }

    /// Unbiased estimate of the orders ≥ `min_order` of f(i, o) (WMLT07's convention, `i` the
    /// light direction, either side each).
    pub fn estimate_orders(
        &self,
        i: Vec3,
        o: Vec3,
        min_order: usize,
        rng: &mut dyn RandomSource,
    ) -> Spectrum {
        if o.z == 0.0 {
            return Spectrum::ZERO;
        }
        self.surface.estimate(&self.facets, i, o, min_order, rng) / o.z.abs()
    }

    /// Index of the medium on the side of `w`.
    #[inline]
    fn index(&self, w: Vec3) -> f64 {
        if w.z > 0.0 {
            1.0
        } else {
            self.single.eta()
        }
    }
}

impl Bsdf for MultipleScatteringDielectric {
    fn flags(&self) -> LobeFlags {
        LobeFlags::GLOSSY_REFLECTION | LobeFlags::GLOSSY_TRANSMISSION
    }

    fn is_stochastic(&self) -> bool {
        true
    }

    fn pdf_is_exact(&self) -> bool {
        false
    }

    fn eval(&self, wo: Vec3, wi: Vec3, ctx: &BsdfContext, rng: &mut dyn RandomSource) -> Spectrum {
        if wo.z == 0.0 || wi.z == 0.0 {
            return Spectrum::ZERO;
        }
        let (i, o) = match ctx.mode {
            TransportMode::Radiance => (wi, wo),
            TransportMode::Importance => (wo, wi),
        };
        // The walk enters from the more masked direction (`Microsurface::walk_from_first`, the
        // estimator's variance); entered from `o` it estimates f(o, i), and the generalized
        // reciprocity f(i, o)/η_o² = f(o, i)/η_i² (ERRATA 11) gives f(i, o).
        let higher = if self.surface.walk_from_first(i, o) {
            self.estimate_orders(i, o, 2, rng)
        } else {
            let r = self.index(o) / self.index(i);
            self.estimate_orders(o, i, 2, rng) * (r * r)
        };
        let v = self.single.eval(wo, wi, ctx, rng) + higher;
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
        let exit = self.surface.walk(&self.facets, wo, rng)?;
        let wi = exit.dir;
        if wi.z == 0.0 {
            return None;
        }
        let transmitted = wi.z * wo.z < 0.0;
        let (n_o, n_i) = (self.index(wo), self.index(wi));
        let mut weight = exit.weight;
        if transmitted && ctx.mode == TransportMode::Radiance {
            weight *= (n_o / n_i) * (n_o / n_i);
        }
        let pdf = self.pdf(wo, wi, ctx);
        (pdf > 0.0 && weight.is_finite()).then_some(BsdfSample {
            wi,
            weight,
            pdf,
            lobe: if transmitted {
                LobeFlags::GLOSSY_TRANSMISSION
            } else {
                LobeFlags::GLOSSY_REFLECTION
            },
            eta: n_i / n_o,
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, ctx: &BsdfContext) -> f64 {
        if wo.z == 0.0 || wi.z == 0.0 {
            return 0.0;
        }
        (1.0 - PROXY_COSINE_SHARE) * self.proxy.pdf(wo, wi, ctx)
            + PROXY_COSINE_SHARE * wi.z.abs() / TWO_PI
    }

    fn lobe_width(&self) -> f64 {
        self.single.lobe_width()
    }

    fn relative_ior(&self) -> Option<f64> {
        Some(self.single.eta())
    }

    fn describe(&self) -> String {
        let s = self.single.describe();
        format!(
            "{}, scattering=multiple, heights={})",
            s.strip_suffix(')').unwrap_or(&s),
            self.surface.heights().name()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::spherical_direction;
    use crate::microfacet::{Ggx, Ndf};
    use crate::validation::chi2::{chi2_test, Chi2Config};
    use crate::validation::SphereMap;

    #[test]
    fn expected_escapes_estimate_the_walks_higher_order_exits() {
        // `higher_order_exits` (expected escapes, Russian roulette) against the physical
        // walk's exits of order ≥ 2 counted per side: the same means within 4 standard
        // errors (GGX α = 1 and Beckmann α = 0.5, 70° from both sides; fixed seeds).
        use crate::math::rng::Pcg32;
        use crate::microfacet::Beckmann;
        let f = DielectricFacets::white(1.5);
        for ndf in [
            Ndf::Ggx(Ggx::isotropic(1.0).unwrap()),
            Ndf::Beckmann(Beckmann::isotropic(0.5).unwrap()),
        ] {
            let s = Microsurface::new(ndf, HeightDistribution::Uniform).unwrap();
            for side in [1.0, -1.0] {
                let w = spherical_direction(70f64.to_radians(), 0.3);
                let wi = Vec3::new(w.x, w.y, side * w.z);
                let n = 100_000;
                let mean_se = |xs: &[f64]| {
                    let m = xs.iter().sum::<f64>() / n as f64;
                    let v = xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1) as f64;
                    (m, (v / n as f64).sqrt())
                };
                let mut rng = Pcg32::new(11, 1);
                let (mut own, mut other) = (vec![0.0; n], vec![0.0; n]);
                for k in 0..n {
                    if let Some(e) = s.walk(&f, wi, &mut rng) {
                        if e.order >= 2 {
                            if e.dir.z * wi.z > 0.0 {
                                own[k] = 1.0;
                            } else {
                                other[k] = 1.0;
                            }
                        }
                    }
                }
                let mut rng = Pcg32::new(12, 1);
                let (mut own_x, mut other_x) = (vec![0.0; n], vec![0.0; n]);
                for k in 0..n {
                    let (a, b) = s.higher_order_exits(&f, wi, &mut rng).unwrap_or((0.0, 0.0));
                    own_x[k] = a;
                    other_x[k] = b;
                }
                for (name, x, y) in [("own side", &own, &own_x), ("other side", &other, &other_x)] {
                    let ((m1, e1), (m2, e2)) = (mean_se(x), mean_se(y));
                    let z = (m1 - m2) / e1.hypot(e2);
                    println!(
                        "{} side {side} {name}: walk {m1:.5} ± {e1:.1e}, expected escapes {m2:.5} ± {e2:.1e} ({z:+.2} σ)",
                        s.ndf().kind_name()
                    );
                    assert!(z.abs() < 4.0, "{name}: {m1} vs {m2} ({z} σ)");
                    assert!(e2 < e1, "expected escapes reduce the variance");
                }
            }
        }
    }

    #[test]
    fn facet_scattering_samples_its_phase_function() {
        let s = Microsurface::new(
            Ndf::Ggx(Ggx::new(0.7, 0.4).unwrap()),
            HeightDistribution::Uniform,
        )
        .unwrap();
        let f = DielectricFacets {
            eta: 1.5,
            reflect_tint: Spectrum::ONE,
            transmit_tint: Spectrum::ONE,
        };
        let cfg = Chi2Config {
            samples: 200_000,
            ..Chi2Config::default()
        };
        for inside in [false, true] {
            for theta in [0.3, 1.2, 1.8, 2.6] {
                let wi = spherical_direction(theta, 0.7);
                for crossing in [false, true] {
                    let out = chi2_test(
                        &SphereMap::standard(),
                        &cfg,
                        |r| {
                            let m = s.sample_visible(wi, r)?;
                            let (o, c, _) = f.scatter(wi, m, inside, r)?;
                            (c == crossing).then_some(o.normalize())
                        },
                        |o| f.phase(&s, wi, o, inside, crossing).average(),
                    );
                    println!(
                        "inside {inside} θ {theta} crossing {crossing}: {}",
                        out.summary()
                    );
                    assert!(
                        out.passes(1e-4),
                        "inside {inside} θ {theta} crossing {crossing}: {}",
                        out.summary()
                    );
                }
            }
        }
    }
}
