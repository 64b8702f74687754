//! The P-BRDF of a footprint  [CCM19 eq. 7]:
//!
//!   f_P(o, i) = F(o·h) G2(P, h, o, i) D_P(h) / (4 A_P(o) A_P(i))
//!             = F(o·h) χ⁺(o·h) χ⁺(i·h) D_P(h) / (4 I_P(o) I_P(i)),
//!
//! the second form after the projected areas cancel (see [`super::patch_masking`]), with a
//! conductor (or F = 1) Fresnel term and a reflectance multiplier. Written for the upper
//! hemisphere like every opaque model of the library ([`crate::two_sided::TwoSided`] makes it
//! two-sided). Reciprocal (symmetric in o and i).
//!
//! **Sampling**: a lobe of the footprint, then a slope of that lobe ([`PatchNdf`]), mirrored:
//! pdf(i) = D_P(h) cos θ_h / (4 o·h)  [WMLT07 eqs. 14, 38; CCM19 §5], the density the
//! sampler has — not an approximation of it.
//!
//! **The density reported for MIS** (`mis_pdf`, [`MisPdf`]). The sampler's density needs
//! D_P at the sample's half vector — a query of every lobe of the footprint whose support
//! holds it, where the sample has just found a glint: measured, that query was two thirds of
//! a render's time (metallic paint, 16 spp, perf). The sample's weight does not need it (D_P
//! cancels, [`super::patch_reflection`]), only a MIS weight at the next hit does. So:
//!
//! - where the caller does not read the sample's density
//!   ([`BsdfContext::skip_sample_pdf`]: a renderer with delta lights only, or without MIS),
//!   the sample skips the query and reports cos θ_i / π (`filtered`: its proxy, as always);
//! - `mis_pdf = "exact"` (default): otherwise the sampler's own density;
//! - `mis_pdf = "filtered"`: `sample` and `pdf` both report the proxy, the density of the
//!   footprint's *filtered* lobe — the Gaussian with the mean and covariance of P22_P, the
//!   lobe of CCM19 §4.2.2 — mixed with a small cosine term so that it is positive wherever
//!   the sampler lands:
//!
//!   p̂(i) = (1 − ε) D̂(h) cos θ_h / (4 o·h) + ε cos θ_i / π,  ε = [`MIS_COSINE_SHARE`],
//!
//!   and [`Bsdf::pdf_is_exact`](crate::bsdf::Bsdf::pdf_is_exact) is false. MIS stays
//!   unbiased with any positive density that `sample` and `pdf` report alike
//!   [Veach 1997, §9.2.2], but the proxy does not see the glints: where it is below the
//!   sampler's density, light sampling takes a larger share of a glint's peak, where it is
//!   the worse strategy (measured in docs/glints.md: faster, and noisier under a wide light).
//!
//! [`GlintBsdf::sampler_pdf`] gives the sampler's density either way (the chi-square tests).
//!
//! [`BsdfContext::skip_sample_pdf`]: crate::bsdf::BsdfContext::skip_sample_pdf
//!
//! **Energy.** ∫ f_P I_P(i) dω_i ≤ 1: the P-BRDF conserves energy for the cosine I_P(i)
//! (the patch's visible projected area). A renderer multiplies by cos θ_i instead; the
//! two agree on average but differ for a footprint whose mean slope is not zero, where the
//! albedo w.r.t. cos θ_i can exceed 1 (measured in the tests and docs/glints.md).

use super::footprint::{Footprint, FootprintQuery};
use super::lobe::LobeF64;
use super::patch_masking::{MaskingMode, PatchMasking};
use super::patch_ndf::PatchNdf;
use super::patch_reflection::{self, PatchReflection};
use super::surface::GlintSurface;
use crate::bsdf::{BsdfContext, BsdfSample, LobeFlags};
use crate::error::{ParamError, ParamResult};
use crate::fresnel::Fresnel;
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::{fmt_num, Vec3, PI};
use crate::two_sided::OpaqueBsdf;
use std::sync::{Arc, Mutex, OnceLock};

/// Share of the cosine term in the filtered MIS density (module notes): small enough that
/// the filtered lobe shapes the MIS weights, large enough that the density is positive
/// where a narrow lobe far from the footprint's mean lands.
pub const MIS_COSINE_SHARE: f64 = 0.05;

/// The density a glint BSDF reports for multiple importance sampling (module notes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MisPdf {
    /// The sampler's own density: one P-NDF query per sample.
    Exact,
    /// The footprint's filtered lobe mixed with a cosine term: no query.
    Filtered,
}

impl MisPdf {
    pub const NAMES: &'static [&'static str] = &["exact", "filtered"];

    pub fn parse(s: &str) -> ParamResult<Self> {
        match s {
            "filtered" => Ok(MisPdf::Filtered),
            "exact" => Ok(MisPdf::Exact),
            other => Err(ParamError::UnknownChoice {
                what: "glint mis_pdf".into(),
                given: other.into(),
                valid: Self::NAMES.join(", "),
            }),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            MisPdf::Exact => "exact",
            MisPdf::Filtered => "filtered",
        }
    }
}

/// Material parameters besides the surface and the footprint.
#[derive(Clone, Debug)]
pub struct GlintParams {
    pub fresnel: Fresnel,
    pub tint: Spectrum,
    pub masking: MaskingMode,
    /// Budget of the exact masking sum (0 = unlimited).
    pub masking_lobes: usize,
    /// The density reported for MIS.
    pub mis_pdf: MisPdf,
}

/// The P-BRDF for one footprint (built per shading point; the surface is shared).
pub struct GlintBsdf {
    surface: Arc<GlintSurface>,
    query: FootprintQuery,
    masking: PatchMasking,
    fresnel: Fresnel,
    tint: Spectrum,
    footprint: Footprint,
    /// The footprint's filtered lobe: the proxy density (module notes), made when first
    /// asked for (an exact-masking footprint's lobes are summed once more).
    filtered: OnceLock<LobeF64>,
    /// The density reported for MIS.
    mis_pdf: MisPdf,
    /// I_P of the last `wo`: the integrator asks for the same view direction many times.
    cache: Mutex<Option<(Vec3, f64)>>,
    /// D_P of the last half vector: a light sample's `eval` and `pdf` ask for the same one
    /// (each query sums the footprint's lobes, the cost of this material).
    last_d: Mutex<Option<(Vec3, f64)>>,
}

impl GlintBsdf {
    pub fn new(surface: Arc<GlintSurface>, footprint: Footprint, params: &GlintParams) -> Self {
        let footprint = footprint.sanitized();
        let query = surface.query(footprint);
        let masking = PatchMasking::new(params.masking, &surface, &query, params.masking_lobes);
        GlintBsdf {
            surface,
            query,
            masking,
            filtered: OnceLock::new(),
            mis_pdf: params.mis_pdf,
            fresnel: params.fresnel,
            tint: params.tint,
            footprint,
            cache: Mutex::new(None),
            last_d: Mutex::new(None),
        }
    }

    pub fn ndf(&self) -> PatchNdf<'_> {
        PatchNdf::new(&self.surface, &self.query)
    }

    pub fn masking(&self) -> &PatchMasking {
        &self.masking
    }

    pub fn query(&self) -> &FootprintQuery {
        &self.query
    }

    pub fn surface(&self) -> &GlintSurface {
        &self.surface
    }

    /// The density with which `sample` draws `wi` (upper hemisphere), whatever `pdf`
    /// reports (module notes).
    pub fn sampler_pdf(&self, wo: Vec3, wi: Vec3) -> f64 {
        patch_reflection::sampler_pdf(self, wo, wi)
    }

    /// The density reported for MIS.
    pub fn mis_pdf(&self) -> MisPdf {
        self.mis_pdf
    }

    /// I_P(v) for v in the upper hemisphere, remembering the last answer.
    fn visible_area(&self, v: Vec3) -> f64 {
        if let Ok(mut c) = self.cache.try_lock() {
            if let Some((w, a)) = *c {
                if w == v {
                    return a;
                }
            }
            let a = self.masking.visible_projected_area(v);
            *c = Some((v, a));
            return a;
        }
        self.masking.visible_projected_area(v)
    }
}

impl PatchReflection for GlintBsdf {
    /// D_P(h)  [CCM19 eq. 9], remembering the last answer.
    fn d(&self, h: Vec3) -> f64 {
        if let Ok(mut c) = self.last_d.try_lock() {
            if let Some((m, d)) = *c {
                if m == h {
                    return d;
                }
            }
            let d = self.ndf().d(h);
            *c = Some((h, d));
            return d;
        }
        self.ndf().d(h)
    }

    fn sample_normal(&self, rng: &mut dyn RandomSource) -> Option<Vec3> {
        self.ndf().sample_normal(rng)
    }

    fn view_area(&self, o: Vec3) -> f64 {
        self.visible_area(o)
    }

    fn light_area(&self, i: Vec3) -> f64 {
        self.masking.visible_projected_area(i)
    }

    fn fresnel(&self) -> &Fresnel {
        &self.fresnel
    }

    fn tint(&self) -> Spectrum {
        self.tint
    }

    /// With `mis_pdf = "filtered"`: p̂(i) = (1 − ε) D̂(h) cos θ_h / (4 o·h) + ε cos θ_i / π
    /// (module notes).
    #[inline]
    fn proxy_pdf(&self, o: Vec3, i: Vec3, h: Vec3) -> Option<f64> {
        if self.mis_pdf != MisPdf::Filtered {
            return None;
        }
        let filtered = self.filtered.get_or_init(|| self.masking.filtered_lobe());
        let lobe = filtered.d_untruncated(h) * h.z / (4.0 * o.dot(h));
        Some((1.0 - MIS_COSINE_SHARE) * lobe + MIS_COSINE_SHARE * i.z.max(0.0) / PI)
    }
}

impl OpaqueBsdf for GlintBsdf {
    fn flags(&self) -> LobeFlags {
        LobeFlags::GLOSSY_REFLECTION
    }

    fn eval(&self, wo: Vec3, wi: Vec3, _: &BsdfContext, _: &mut dyn RandomSource) -> Spectrum {
        patch_reflection::eval(self, wo, wi)
    }

    fn sample(
        &self,
        wo: Vec3,
        ctx: &BsdfContext,
        rng: &mut dyn RandomSource,
    ) -> Option<BsdfSample> {
        patch_reflection::sample(self, wo, !ctx.skip_sample_pdf, rng)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, _: &BsdfContext) -> f64 {
        patch_reflection::pdf(self, wo, wi)
    }

    fn pdf_is_exact(&self) -> bool {
        self.mis_pdf == MisPdf::Exact
    }

    /// The RMS slope of the footprint's distribution (at least 0.15, so the validation
    /// harness tests the whole hemisphere: the patch NDF has many separated peaks).
    fn lobe_width(&self) -> f64 {
        let l = self.masking.filtered_lobe();
        let spread = (l.mean[0].powi(2) + l.mean[1].powi(2) + l.cov[0] + l.cov[2]).sqrt();
        spread.max(0.15)
    }

    fn describe(&self) -> String {
        let fres = match &self.fresnel {
            Fresnel::Conductor { eta, k } => format!("eta={:?}, k={:?}", eta.0, k.0),
            Fresnel::One => "F=1".into(),
            other => format!("{other:?}"),
        };
        let c = self.footprint.cov;
        format!(
            "glint({}, footprint centre ({}, {}) texels, cov [{}, {}, {}] texels², masking={} (level {}, {} lobes), mis_pdf={}, {fres})",
            self.surface.label(),
            fmt_num(self.footprint.center.x),
            fmt_num(self.footprint.center.y),
            fmt_num(c[0]),
            fmt_num(c[1]),
            fmt_num(c[2]),
            self.masking.mode().name(),
            self.masking.level(),
            self.masking.lobe_count(),
            self.mis_pdf().name()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rng::Pcg32;
    use crate::math::Vec2;
    use crate::models::glint::{generate, NormalMapKind};

    fn bsdf(kind: NormalMapKind, masking: MaskingMode, mis_pdf: MisPdf) -> GlintBsdf {
        let map = generate(kind, 32, 4).unwrap();
        let surface = Arc::new(GlintSurface::build(map, 0.03, "test").unwrap());
        let params = GlintParams {
            fresnel: Fresnel::One,
            tint: Spectrum::splat(0.9),
            masking,
            masking_lobes: 0,
            mis_pdf,
        };
        GlintBsdf::new(
            surface,
            Footprint::isotropic(Vec2::new(11.3, 7.8), 1.5),
            &params,
        )
    }

    /// The reported density changes, nothing else: the same random numbers give the same
    /// directions and weights in both modes and contexts; each weight is f cos θ_i over the
    /// sampler's density (D cancelled, so equal to rounding); the filtered mode reports its
    /// proxy in the sample and in `pdf` alike, the exact mode the sampler's density — or
    /// cos θ_i / π in a sample where the context says the density is not read.
    #[test]
    fn the_filtered_mis_density_changes_only_the_reported_pdf() {
        let ctx = BsdfContext::RADIANCE;
        let unread = BsdfContext::RADIANCE.without_sample_pdf();
        let wo = Vec3::new(0.45, -0.2, 0.87).normalize();
        for kind in [NormalMapKind::Scratched, NormalMapKind::Flakes] {
            for masking in [MaskingMode::Exact, MaskingMode::Approx] {
                let f = bsdf(kind, masking, MisPdf::Filtered);
                let e = bsdf(kind, masking, MisPdf::Exact);
                assert!(!f.pdf_is_exact() && e.pdf_is_exact());
                let mut r = [(); 4].map(|_| Pcg32::new(5, 1));
                let mut accepted = 0;
                for _ in 0..2000 {
                    let sf = f.sample(wo, &ctx, &mut r[0]);
                    let se = e.sample(wo, &ctx, &mut r[1]);
                    let su = e.sample(wo, &unread, &mut r[2]);
                    let (Some(sf), Some(se), Some(su)) = (sf, se, su) else {
                        assert!(sf.is_none() && se.is_none() && su.is_none());
                        assert!(f.sample(wo, &unread, &mut r[3]).is_none());
                        continue;
                    };
                    accepted += 1;
                    assert_eq!(sf.wi, se.wi);
                    assert_eq!(sf.weight, se.weight);
                    assert_eq!((su.wi, su.weight), (sf.wi, sf.weight));
                    assert_eq!(su.pdf, su.wi.z / PI);
                    // The filtered mode reports its proxy in every context.
                    let sfu = f.sample(wo, &unread, &mut r[3]).expect("same draws as sf");
                    assert_eq!((sfu.wi, sfu.pdf), (sf.wi, sf.pdf));
                    let exact = f.sampler_pdf(wo, sf.wi);
                    assert!(
                        (se.pdf - exact).abs() <= 1e-12 * exact,
                        "{} {exact}",
                        se.pdf
                    );
                    assert_eq!(sf.pdf, f.pdf(wo, sf.wi, &ctx));
                    assert!(sf.pdf > 0.0 && sf.pdf.is_finite());
                    let mut r = Pcg32::new(0, 0);
                    let expect = f.eval(wo, sf.wi, &ctx, &mut r) * (sf.wi.z / exact);
                    for c in 0..3 {
                        let (a, b) = (sf.weight[c], expect[c]);
                        assert!((a - b).abs() <= 1e-9 * b.abs(), "{a} vs {b}");
                    }
                }
                assert!(accepted > 1500, "{accepted}");
            }
        }
    }

    /// The proxy is positive over the whole upper hemisphere (also far from the footprint's
    /// lobes, and at grazing angles) and finite.
    #[test]
    fn the_filtered_mis_density_is_positive_and_finite_everywhere() {
        let ctx = BsdfContext::RADIANCE;
        let f = bsdf(
            NormalMapKind::Scratched,
            MaskingMode::Approx,
            MisPdf::Filtered,
        );
        let wo = Vec3::new(0.3, 0.1, 0.95).normalize();
        for t in 0..=60 {
            for p in 0..32 {
                let theta = (t as f64 / 60.0) * 0.5 * PI * (1.0 - 1e-9);
                let wi = crate::math::spherical_direction(theta, p as f64 * 2.0 * PI / 32.0);
                let v = f.pdf(wo, wi, &ctx);
                assert!(v > 0.0 && v.is_finite(), "{wi:?}: {v}");
            }
        }
        let horizon = Vec3::new(1.0, 0.0, 1e-170).normalize();
        assert!(f.pdf(horizon, horizon, &ctx).is_finite());
    }
}
