//! The models that vectorize, over lanes: Lambert, the rough conductor and the rough
//! dielectric (WMLT07) and rough interfaced Lambertian (IL18, single scattering, stochastic
//! body) with GGX or Beckmann, separable Smith masking and visible-normal sampling — the
//! materials of the renderer's packet kernel. Each lane holds one shading
//! point's pair of directions in its local frame (radiance transport: `wo` toward the
//! camera, `wi` toward the light). Built from a material recipe by
//! `MaterialRecipe::lane_model`; any other recipe (smooth interfaces, multiple scattering,
//! compensation, other distributions or maskings, IL's other body evaluations and multiple
//! scattering, KSK01, glints) runs through its f64
//! [`Bsdf`](crate::Bsdf) lane by lane in the kernel.
//!
//! Two things differ from the f64 models on purpose, as Mitsuba's `roughdielectric` does:
//! - [`eval_pdf`](LaneBsdf::eval_pdf) returns the value and the density together, with the
//!   half vector, D, G and one Fresnel term computed once (the f64 dielectric takes Fresnel
//!   at i·h in `eval` and at o·h in `pdf`: the same number for a refraction pair);
//! - the sampling weight is G(wo, wi)/G1_v(wo) at the sampled normal, the exact quotient
//!   D·G·|o·m|/(|o·n| p_v(m)) of visible-normal sampling (for GGX and exact-G1 Beckmann,
//!   G1(wi, m)), where the f64 models evaluate the whole quotient.
//!
//! The tests compare every value, density and sample with the f64 models at the same random
//! numbers: 1e-9 relative in the f64 instantiation, 1e-3 in f32 lanes.

use super::lane_colors::{ColorSource, OwnColors};
use crate::bsdf::LobeFlags;
use crate::fresnel::conductor::fresnel_conductor_lanes;
use crate::fresnel::dielectric::fresnel_dielectric_lanes;
use crate::fresnel::Fresnel;
use crate::lanes::{channels, map_channels, LVec3, Mask, Real};
use crate::math::INV_PI;
use crate::microfacet::{sided_g1_lanes, Beckmann, Ggx, Ndf};
use crate::recipe::microfacet::with_roughness;
use crate::{ParamError, ParamResult};

/// A distribution the lane models support.
#[derive(Clone, Debug)]
pub enum LaneNdf {
    Ggx(Ggx),
    Beckmann(Beckmann),
}

impl LaneNdf {
    /// The lane form of a distribution, where it has one.
    pub fn from_ndf(ndf: &Ndf) -> Option<LaneNdf> {
        match ndf {
            Ndf::Ggx(g) => Some(LaneNdf::Ggx(*g)),
            Ndf::Beckmann(b) => Some(LaneNdf::Beckmann(*b)),
            _ => None,
        }
    }

    #[inline(always)]
    fn d<R: Real>(&self, m: LVec3<R>) -> R {
        match self {
            LaneNdf::Ggx(g) => g.d_lanes(m),
            LaneNdf::Beckmann(b) => b.d_lanes(m),
        }
    }

    /// G1(v) without the sidedness, both ways a visible-normal sampler needs it: the exact
    /// G1_v of the density [Heitz 2014, eq. 2] (exact even where the model's G1 is a fit),
    /// and the model's G1 over it (1 where the model is exact). One evaluation of G1 serves
    /// the density and the masking of the view's side, which the sample's weight
    /// G(i, o, m)/G1_v(o) of visible-normal sampling [Heitz & d'Eon 2014] reduces to for
    /// separable Smith masking.
    #[inline(always)]
    fn g1_visible_and_ratio<R: Real>(&self, v: LVec3<R>) -> (R, R) {
        match self {
            LaneNdf::Ggx(g) => (g.g1_unsided_lanes(v), R::one()),
            LaneNdf::Beckmann(b) => b.g1_visible_and_ratio_lanes(v),
        }
    }

    /// The model's G1(v) without the sidedness.
    #[inline(always)]
    fn g1_model<R: Real>(&self, v: LVec3<R>) -> R {
        match self {
            LaneNdf::Ggx(g) => g.g1_unsided_lanes(v),
            LaneNdf::Beckmann(b) => b.g1_model_lanes(v),
        }
    }

    /// The density of visible normals seen from v (v.z > 0): G1_v(v) (v·m) D(m) / v.z
    /// [Heitz 2014, eq. 2], with `g1v` = G1_v(v) from
    /// [`g1_visible_and_ratio`](Self::g1_visible_and_ratio).
    #[inline(always)]
    fn pdf_visible<R: Real>(v: LVec3<R>, m: LVec3<R>, d: R, g1v: R) -> R {
        let vm = v.dot(m);
        R::select(
            vm.le(R::zero()) | v.z.le(R::zero()) | d.eq(R::zero()),
            R::zero(),
            g1v * vm * d / v.z,
        )
    }

    #[inline(always)]
    fn sample_visible<R: Real>(&self, v: LVec3<R>, u0: R, u1: R) -> LVec3<R> {
        match self {
            LaneNdf::Ggx(g) => g.sample_visible_lanes(v, u0, u1),
            LaneNdf::Beckmann(b) => b.sample_visible_lanes(v, u0, u1),
        }
    }

    /// m drawn from D(m)|m·n| [WMLT07 eqs. 28–29, 35–36; IL18 eqs. 29–31].
    #[inline(always)]
    fn sample_normal<R: Real>(&self, u0: R, u1: R) -> LVec3<R> {
        match self {
            LaneNdf::Ggx(g) => g.sample_normal_lanes(u0, u1),
            LaneNdf::Beckmann(b) => b.sample_normal_lanes(u0, u1),
        }
    }

    /// G(i, o, m) with separable Smith masking [WMLT07 eq. 23].
    #[inline(always)]
    fn g<R: Real>(&self, i: LVec3<R>, o: LVec3<R>, m: LVec3<R>) -> R {
        self.g_with_o(i, o, m, self.g1_model(o))
    }

    /// [`g`](Self::g) with o's unsided model G1 already known (`g1o`, from
    /// [`g1_visible_and_ratio`](Self::g1_visible_and_ratio) as G1_v × ratio).
    #[inline(always)]
    fn g_with_o<R: Real>(&self, i: LVec3<R>, o: LVec3<R>, m: LVec3<R>, g1o: R) -> R {
        sided_g1_lanes(i, m, self.g1_model(i)) * sided_g1_lanes(o, m, g1o)
    }
}

/// A conductor's Fresnel term over lanes.
#[derive(Clone, Copy, Debug)]
pub enum LaneFresnel {
    One,
    Conductor { eta: [f64; 3], k: [f64; 3] },
    Schlick { f0: [f64; 3] },
}

impl LaneFresnel {
    /// The lane form of a conductor's Fresnel term, where it has one.
    pub fn from_fresnel(f: &Fresnel) -> Option<LaneFresnel> {
        match f {
            Fresnel::One => Some(LaneFresnel::One),
            Fresnel::Conductor { eta, k } => Some(LaneFresnel::Conductor { eta: eta.0, k: k.0 }),
            Fresnel::Schlick { f0 } => Some(LaneFresnel::Schlick { f0: f0.0 }),
            Fresnel::Dielectric { .. } => None,
        }
    }

    #[inline(always)]
    fn eval<R: Real>(&self, cos: R) -> [R; 3] {
        match self {
            LaneFresnel::One => [R::one(); 3],
            LaneFresnel::Conductor { eta, k } => {
                // Three direct calls, not a closure: LLVM inlines neither a closure this
                // large three times nor the function it lands in (see `lanes::channels`).
                [
                    fresnel_conductor_lanes(cos, eta[0], k[0]),
                    fresnel_conductor_lanes(cos, eta[1], k[1]),
                    fresnel_conductor_lanes(cos, eta[2], k[2]),
                ]
            }
            // F0 + (1 − F0)(1 − c)⁵ [Schlick 1994, eq. 15].
            LaneFresnel::Schlick { f0 } => {
                let m = (R::one() - cos.abs().min(R::one())).max(R::zero());
                let m5 = m * m * m * m * m;
                channels(|c| R::splat(f0[c]) + R::splat(1.0 - f0[c]) * m5)
            }
        }
    }
}

/// Where a stochastic lane model takes its further random numbers: the draws its f64 model
/// makes from the sample's free stream after the sampler's dimensions, one pair for each
/// lane of `lanes` (and none for the others, so that every lane's stream advances as the
/// f64 model's would).
pub trait LaneRandom<R: Real> {
    fn next_2d(&mut self, lanes: R::Mask) -> (R, R);
}

/// A model written over lanes.
#[derive(Clone, Debug)]
pub enum LaneBsdf {
    /// Two-sided Lambert: reflectance/π.
    Lambert { reflectance: [f64; 3] },
    /// Two-sided rough conductor [WMLT07 eq. 20].
    Conductor {
        ndf: LaneNdf,
        fresnel: LaneFresnel,
        tint: [f64; 3],
    },
    /// Rough dielectric, reflection and refraction [WMLT07 eqs. 20–21]; `eta` = η_inside /
    /// η_outside.
    Dielectric {
        ndf: LaneNdf,
        eta: f64,
        reflect_tint: [f64; 3],
        transmit_tint: [f64; 3],
    },
    /// Two-sided rough interfaced Lambertian, single scattering, with the body integral
    /// estimated by one microfacet per evaluation [IL18 eqs. 4, 13 and 28]
    /// (`models::il::InterfacedLambertian` with `evaluation = "stochastic"`).
    Il {
        ndf: LaneNdf,
        ni: f64,
        /// K_d/(π n_i² (1 − K_d r_i)) per channel.
        body: [f64; 3],
        /// The probability of sampling the specular lobe [IL18 §4.1].
        specular_probability: f64,
        /// The interface's external and internal diffuse reflectances r_e and r_i (what a
        /// textured K_d needs, `LaneColorParam::Kd`).
        re: f64,
        ri: f64,
    },
}

/// One sample per lane; lanes where `ok` is clear end their path.
#[derive(Clone, Copy, Debug)]
pub struct LaneSample<R: Real> {
    pub wi: LVec3<R>,
    /// f·|cos θ_i|/pdf, radiance scaling across refraction included.
    pub weight: [R; 3],
    pub pdf: R,
    /// η_t/η_o across a refraction, 1 on reflection.
    pub eta: R,
    pub transmitted: R::Mask,
    pub ok: R::Mask,
}

/// The sign that brings wo to the upper side (two-sided opaque models mirror both
/// directions in the surface, `math::to_upper_pair`).
#[inline(always)]
fn upper<R: Real>(wo: LVec3<R>) -> R {
    wo.z.sign_or_one()
}

/// `w` mirrored in the surface where `s` is −1.
#[inline(always)]
fn mirror<R: Real>(w: LVec3<R>, s: R) -> LVec3<R> {
    LVec3::new(w.x, w.y, w.z * s)
}

/// Malley's cosine-weighted hemisphere from Shirley–Chiu's concentric disk (the f64
/// `square_to_cosine_hemisphere`).
#[inline(always)]
fn cosine_hemisphere<R: Real>(u0: R, u1: R) -> LVec3<R> {
    let (x, y) = crate::math::warp::square_to_disk_concentric_lanes(u0, u1);
    let z = (R::one() - (x * x + y * y)).max(R::zero()).sqrt();
    LVec3::new(x, y, z)
}

impl LaneBsdf {
    /// The lobes (none of them delta).
    pub fn flags(&self) -> LobeFlags {
        match self {
            LaneBsdf::Lambert { .. } => LobeFlags::DIFFUSE_REFLECTION,
            LaneBsdf::Conductor { .. } => LobeFlags::GLOSSY_REFLECTION,
            LaneBsdf::Dielectric { .. } => {
                LobeFlags::GLOSSY_REFLECTION | LobeFlags::GLOSSY_TRANSMISSION
            }
            LaneBsdf::Il { .. } => LobeFlags::GLOSSY_REFLECTION | LobeFlags::DIFFUSE_REFLECTION,
        }
    }

    /// The lane form of a rough, single-scattering, stochastic interfaced Lambertian model
    /// whose lobe has the lane distribution `ndf`.
    pub fn il(ndf: LaneNdf, il: &crate::models::il::InterfacedLambertian) -> LaneBsdf {
        let (re, ri) = il.diffuse_reflectances();
        LaneBsdf::Il {
            ndf,
            ni: il.ni(),
            body: il.body_factor().0.map(|k| k * INV_PI),
            specular_probability: il.specular_probability(),
            re,
            ri,
        }
    }

    /// The model with the roughness parameter `key` (`alpha`, `alpha_u`, `alpha_v`) set to
    /// `v`, validated as the material table's value is (what a roughness texture drives).
    pub fn with_roughness(&self, key: &str, v: f64) -> ParamResult<LaneBsdf> {
        let mut m = self.clone();
        let ndf = match &mut m {
            LaneBsdf::Lambert { .. } => {
                return Err(ParamError::Invalid(format!(
                    "`{key}`: Lambert has no roughness"
                )))
            }
            LaneBsdf::Conductor { ndf, .. }
            | LaneBsdf::Dielectric { ndf, .. }
            | LaneBsdf::Il { ndf, .. } => ndf,
        };
        let general = match ndf {
            LaneNdf::Ggx(g) => Ndf::Ggx(*g),
            LaneNdf::Beckmann(b) => Ndf::Beckmann(*b),
        };
        *ndf = LaneNdf::from_ndf(&with_roughness(&general, key, v)?).ok_or_else(|| {
            ParamError::Invalid(format!("`{key}` changed the distribution's family"))
        })?;
        Ok(m)
    }

    /// Whether [`sample`](Self::sample) reads its lobe number `u_lobe` (the dielectric's
    /// choice between reflection and refraction, IL's between its two lobes); the one-lobe
    /// models ignore it, and the renderer leaves that dimension undrawn.
    pub fn reads_lobe_number(&self) -> bool {
        matches!(self, LaneBsdf::Dielectric { .. } | LaneBsdf::Il { .. })
    }

    /// The value f(wo, wi) (no cosine) and the density of sampling wi from wo; a stochastic
    /// model draws its further numbers from `rng`.
    ///
    /// `#[inline(always)]` so that it compiles with its caller's instruction set: a caller
    /// in a loop calls it through a function of its own
    /// ([`eval_pdf_out_of_line`](Self::eval_pdf_out_of_line), or one compiled for the
    /// caller's features as the render kernel's `model_calls` does), or LLVM's loop passes
    /// take minutes on the result.
    #[inline(always)]
    pub fn eval_pdf<R: Real>(
        &self,
        wo: LVec3<R>,
        wi: LVec3<R>,
        rng: &mut impl LaneRandom<R>,
    ) -> ([R; 3], R) {
        self.eval_pdf_with(&OwnColors, wo, wi, rng)
    }

    /// [`eval_pdf`](Self::eval_pdf) with the spectral parameters of `colors` (a texture's,
    /// per lane).
    #[inline(always)]
    pub fn eval_pdf_with<R: Real>(
        &self,
        colors: &impl ColorSource<R>,
        wo: LVec3<R>,
        wi: LVec3<R>,
        rng: &mut impl LaneRandom<R>,
    ) -> ([R; 3], R) {
        match self {
            LaneBsdf::Lambert { reflectance } => {
                let same = (wo.z * wi.z).gt(R::zero());
                let pdf = R::masked(same, wi.z.abs() * R::splat(INV_PI));
                let v = R::masked(same, R::splat(INV_PI));
                (map_channels(colors.tint(reflectance), |r| r * v), pdf)
            }
            LaneBsdf::Conductor { ndf, fresnel, tint } => {
                let tint = colors.tint(tint);
                let s = upper(wo);
                let (o, i) = (mirror(wo, s), mirror(wi, s));
                let h = (o + i).normalize();
                let cos_oh = o.dot(h);
                let ok = (wo.z * wi.z).gt(R::zero()) & h.z.gt(R::zero()) & cos_oh.gt(R::zero());
                let d = ndf.d(h);
                let (g1v, ratio) = ndf.g1_visible_and_ratio(o);
                let geom = d * ndf.g_with_o(i, o, h, g1v * ratio) / (R::splat(4.0) * o.z * i.z);
                let pdf = LaneNdf::pdf_visible(o, h, d, g1v) / (R::splat(4.0) * cos_oh);
                let f = fresnel.eval(cos_oh);
                let ok = ok & geom.gt(R::zero());
                let v = channels(|c| R::masked(ok, tint[c] * f[c] * geom));
                (v, R::masked(ok & pdf.is_finite(), pdf))
            }
            LaneBsdf::Dielectric {
                ndf,
                eta,
                reflect_tint,
                transmit_tint,
            } => Self::dielectric_eval_pdf(
                ndf,
                *eta,
                &colors.tint(reflect_tint),
                &colors.transmit_tint(transmit_tint),
                wo,
                wi,
            ),
            LaneBsdf::Il {
                ndf,
                ni,
                body,
                specular_probability,
                ..
            } => {
                let s = upper(wo);
                let (o, i) = (mirror(wo, s), mirror(wi, s));
                let same = (wo.z * wi.z).gt(R::zero());
                let ps = colors.specular_probability(*specular_probability);
                let (spec, pdf) =
                    Self::il_specular(ndf, *ni, ps, o, i, ndf.g1_visible_and_ratio(o));
                let (u0, u1) = rng.next_2d(same);
                let b = Self::il_body(ndf, *ni, o, i, u0, u1);
                let body = colors.tint(body);
                let f = channels(|c| R::masked(same, spec + body[c] * b));
                (f, R::masked(same, pdf))
            }
        }
    }

    #[inline(always)]
    fn dielectric_eval_pdf<R: Real>(
        ndf: &LaneNdf,
        eta: f64,
        reflect_tint: &[R; 3],
        transmit_tint: &[R; 3],
        wo: LVec3<R>,
        wi: LVec3<R>,
    ) -> ([R; 3], R) {
        let zero = R::zero();
        let refl = (wo.z * wi.z).gt(zero);
        let index = |w: LVec3<R>| R::select(w.z.gt(zero), R::one(), R::splat(eta));
        let (n_i, n_o) = (index(wi), index(wo));
        // The generalized half vector [WMLT07 eq. 16], on the upper side.
        let ht = -(wi.scale(n_i) + wo.scale(n_o));
        let h = LVec3::select(refl, wi + wo, ht).normalize();
        let h = LVec3::select(h.z.lt(zero), -h, h);
        let (ih, oh) = (wi.dot(h), wo.dot(h));
        let ok = h.z.gt(zero)
            & (ih * wi.z).gt(zero)
            & (oh * wo.z).gt(zero)
            & !wo.z.eq(zero)
            & !wi.z.eq(zero);
        let d = ndf.d(h);
        // G1 of wo serves the masking and the density (seen from ±wo: G1 is even in z).
        let up = wo.scale(wo.z.sign_or_one());
        let (g1v, ratio) = ndf.g1_visible_and_ratio(up);
        let g = ndf.g_with_o(wi, wo, h, g1v * ratio);
        // One Fresnel term, seen from wo's side (the same from wi's for a refraction pair).
        let n_t = R::select(wo.z.gt(zero), R::splat(eta), R::one());
        let f = fresnel_dielectric_lanes(oh.abs(), n_t / n_o);
        let cos_io = (wi.z * wo.z).abs();
        // WMLT07 eq. 20 (reflection) and eq. 21 with i the light direction (refraction).
        let fr = f * d * g / (R::splat(4.0) * cos_io);
        let denom_e = n_i * ih + n_o * oh;
        let ft =
            (ih * oh).abs() / cos_io * n_o * n_o * (R::one() - f) * g * d / (denom_e * denom_e);
        // Densities from wo: WMLT07 eqs. 14 and 17 with visible normals seen from ±wo.
        let pm = LaneNdf::pdf_visible(up, h, d, g1v);
        let pr = pm * f / (R::splat(4.0) * oh.abs());
        let denom_p = n_o * oh + n_t * ih;
        let pt = pm * (R::one() - f) * n_t * n_t * ih.abs() / (denom_p * denom_p);
        let value = R::select(refl, fr, ft);
        let pdf = R::select(refl, pr, pt);
        let ok = ok & value.is_finite() & pdf.is_finite();
        let v = channels(|c| {
            let tint = R::select(refl, reflect_tint[c], transmit_tint[c]);
            R::masked(ok, tint * value)
        });
        (v, R::masked(ok, pdf))
    }

    /// IL's specular value and its density for a pair in the upper hemisphere (0 where
    /// either is not above it): F(o·h) D G/(4 i_z o_z) [IL18 eq. 4], and the mixture of the
    /// visible-normal reflection and the cosine lobe [IL18 §4.1].
    #[inline(always)]
    fn il_specular<R: Real>(
        ndf: &LaneNdf,
        ni: f64,
        specular_probability: R,
        o: LVec3<R>,
        i: LVec3<R>,
        (g1v, ratio): (R, R),
    ) -> (R, R) {
        let zero = R::zero();
        let above = o.z.gt(zero) & i.z.gt(zero);
        let h = (o + i).normalize();
        let cos_oh = o.dot(h);
        let lobe = above & h.z.gt(zero) & cos_oh.gt(zero);
        let d = ndf.d(h);
        let spec = d * ndf.g_with_o(i, o, h, g1v * ratio) / (R::splat(4.0) * o.z * i.z)
            * fresnel_dielectric_lanes(cos_oh, R::splat(ni));
        let spec = R::select(lobe & spec.gt(zero), spec, zero);
        let spec_pdf = LaneNdf::pdf_visible(o, h, d, g1v) / (R::splat(4.0) * cos_oh);
        let spec_pdf = R::select(lobe & spec_pdf.is_finite(), spec_pdf, zero);
        let ps = specular_probability;
        let pdf = ps * spec_pdf + (R::one() - ps) * R::masked(above, i.z * R::splat(INV_PI));
        (spec, pdf)
    }

    /// IL's body integral for a pair in the upper hemisphere estimated with one microfacet m
    /// drawn from D(m) m_z by (u0, u1): T(i·m) T(o·m) G(i, o, m) (i·m)(o·m)/(i_z o_z m_z)
    /// [IL18 eqs. 13 and 28; D over its density D m_z], 0 where m faces away from either.
    #[inline(always)]
    fn il_body<R: Real>(ndf: &LaneNdf, ni: f64, o: LVec3<R>, i: LVec3<R>, u0: R, u1: R) -> R {
        let zero = R::zero();
        let m = ndf.sample_normal(u0, u1);
        let (im, om) = (i.dot(m), o.dot(m));
        let eta = R::splat(ni);
        let t = |c: R| R::one() - fresnel_dielectric_lanes(c, eta);
        let b = t(im) * t(om) * ndf.g(i, o, m) * im * om / (i.z * o.z * m.z);
        let facing = o.z.gt(zero) & i.z.gt(zero) & im.gt(zero) & om.gt(zero) & m.z.gt(zero);
        R::select(facing, b, zero)
    }

    /// Samples wi from wo with the lobe number `u_lobe` and the direction numbers
    /// (`u0`, `u1`) — the numbers the f64 model takes from its source in that order — and,
    /// for a stochastic model, further numbers from `rng`. Inlined like
    /// [`eval_pdf`](Self::eval_pdf), with the same caution for callers.
    #[inline(always)]
    pub fn sample<R: Real>(
        &self,
        wo: LVec3<R>,
        u_lobe: R,
        u0: R,
        u1: R,
        rng: &mut impl LaneRandom<R>,
    ) -> LaneSample<R> {
        self.sample_with(&OwnColors, wo, u_lobe, u0, u1, rng)
    }

    /// [`sample`](Self::sample) with the spectral parameters of `colors` (a texture's, per
    /// lane).
    #[inline(always)]
    pub fn sample_with<R: Real>(
        &self,
        colors: &impl ColorSource<R>,
        wo: LVec3<R>,
        u_lobe: R,
        u0: R,
        u1: R,
        rng: &mut impl LaneRandom<R>,
    ) -> LaneSample<R> {
        match self {
            LaneBsdf::Lambert { reflectance } => {
                let reflectance = colors.tint(reflectance);
                let s = upper(wo);
                let wi = cosine_hemisphere(u0, u1);
                let ok = !wo.z.eq(R::zero()) & wi.z.gt(R::zero());
                LaneSample {
                    pdf: wi.z * R::splat(INV_PI),
                    wi: mirror(wi, s),
                    weight: reflectance,
                    eta: R::one(),
                    transmitted: R::Mask::splat(false),
                    ok,
                }
            }
            LaneBsdf::Conductor { ndf, fresnel, tint } => {
                let tint = colors.tint(tint);
                let s = upper(wo);
                let o = mirror(wo, s);
                let m = ndf.sample_visible(o, u0, u1);
                let c = o.dot(m);
                let i = m.scale(R::splat(2.0) * c) - o;
                let d = ndf.d(m);
                let (g1v, ratio) = ndf.g1_visible_and_ratio(o);
                let pdf = LaneNdf::pdf_visible(o, m, d, g1v) / (R::splat(4.0) * c);
                // G(i, o, m)/G1_v(o) with o·m = c > 0 (the lanes kept below).
                let w = sided_g1_lanes(i, m, ndf.g1_model(i)) * ratio;
                let f = fresnel.eval(c);
                let ok = !wo.z.eq(R::zero())
                    & c.gt(R::zero())
                    & i.z.gt(R::zero())
                    & pdf.gt(R::zero())
                    & pdf.is_finite()
                    & w.is_finite();
                LaneSample {
                    wi: mirror(i, s),
                    weight: channels(|k| tint[k] * f[k] * w),
                    pdf,
                    eta: R::one(),
                    transmitted: R::Mask::splat(false),
                    ok,
                }
            }
            LaneBsdf::Dielectric {
                ndf,
                eta,
                reflect_tint,
                transmit_tint,
            } => Self::dielectric_sample(
                ndf,
                *eta,
                &colors.tint(reflect_tint),
                &colors.transmit_tint(transmit_tint),
                wo,
                u_lobe,
                u0,
                u1,
            ),
            LaneBsdf::Il {
                ndf,
                ni,
                body,
                specular_probability,
                ..
            } => {
                let ps = colors.specular_probability(*specular_probability);
                let body = colors.tint(body);
                // The specular lobe's visible-normal reflection or the cosine lobe, then the
                // value and density of the pair (the f64 model's order of draws).
                let s = upper(wo);
                let o = mirror(wo, s);
                let specular = u_lobe.lt(ps);
                let m = ndf.sample_visible(o, u0, u1);
                let c = o.dot(m);
                let reflected = m.scale(R::splat(2.0) * c) - o;
                let i = LVec3::select(specular, reflected, cosine_hemisphere(u0, u1));
                let g1o = ndf.g1_visible_and_ratio(o);
                let lobe_pdf = LaneNdf::pdf_visible(o, m, ndf.d(m), g1o.0) / (R::splat(4.0) * c);
                let lobe_ok = c.gt(R::zero()) & lobe_pdf.gt(R::zero()) & lobe_pdf.is_finite();
                let drawn = !wo.z.eq(R::zero()) & i.z.gt(R::zero()) & (!specular | lobe_ok);
                let (spec, pdf) = Self::il_specular(ndf, *ni, ps, o, i, g1o);
                let valued = drawn & pdf.gt(R::zero());
                let (b0, b1) = rng.next_2d(valued);
                let b = Self::il_body(ndf, *ni, o, i, b0, b1);
                let k = i.z / pdf;
                let weight: [R; 3] = channels(|ch| (spec + body[ch] * b) * k);
                let ok =
                    valued & weight[0].is_finite() & weight[1].is_finite() & weight[2].is_finite();
                LaneSample {
                    wi: mirror(i, s),
                    weight,
                    pdf,
                    eta: R::one(),
                    transmitted: R::Mask::splat(false),
                    ok,
                }
            }
        }
    }

    /// [`eval_pdf`](Self::eval_pdf) as a function of its own, for the lane type's baseline
    /// instruction set: what a caller in a loop calls (the tests, the render kernel's f64
    /// lanes and its fallback without AVX2).
    #[inline(never)]
    pub fn eval_pdf_out_of_line<R: Real>(
        &self,
        colors: &impl ColorSource<R>,
        wo: LVec3<R>,
        wi: LVec3<R>,
        rng: &mut impl LaneRandom<R>,
    ) -> ([R; 3], R) {
        self.eval_pdf_with(colors, wo, wi, rng)
    }

    /// [`sample`](Self::sample) as a function of its own, like
    /// [`eval_pdf_out_of_line`](Self::eval_pdf_out_of_line).
    #[inline(never)]
    pub fn sample_out_of_line<R: Real>(
        &self,
        colors: &impl ColorSource<R>,
        wo: LVec3<R>,
        u_lobe: R,
        u0: R,
        u1: R,
        rng: &mut impl LaneRandom<R>,
    ) -> LaneSample<R> {
        self.sample_with(colors, wo, u_lobe, u0, u1, rng)
    }

    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn dielectric_sample<R: Real>(
        ndf: &LaneNdf,
        eta: f64,
        reflect_tint: &[R; 3],
        transmit_tint: &[R; 3],
        wo: LVec3<R>,
        u_lobe: R,
        u0: R,
        u1: R,
    ) -> LaneSample<R> {
        let (zero, one) = (R::zero(), R::one());
        let outside = wo.z.gt(zero);
        let n_o = R::select(outside, one, R::splat(eta));
        let n_t = R::select(outside, R::splat(eta), one);
        let up = wo.scale(wo.z.sign_or_one());
        let m = ndf.sample_visible(up, u0, u1);
        let c = wo.dot(m);
        let d = ndf.d(m);
        let (g1v, ratio) = ndf.g1_visible_and_ratio(up);
        let pm = LaneNdf::pdf_visible(up, m, d, g1v);
        let f = fresnel_dielectric_lanes(c.abs(), n_t / n_o);
        let choose_r = u_lobe.lt(f);
        let wr = m.scale(R::splat(2.0) * c) - wo;
        // Refraction through m [WMLT07 eq. 40], relative index n_o/n_t.
        let e = n_o / n_t;
        let k = one + e * e * (c * c - one);
        let wt = m.scale(e * c - c.sign_or_one() * k.max(zero).sqrt()) - wo.scale(e);
        let wi = LVec3::select(choose_r, wr, wt);
        // G(wo, wi, m)/G1_v(wo) with (wo·m) wo_z > 0 (the lanes kept below).
        let base = sided_g1_lanes(wi, m, ndf.g1_model(wi)) * ratio;
        let wim = wi.dot(m);
        let denom = n_o * c + n_t * wim;
        let pr = pm * f / (R::splat(4.0) * c.abs());
        let pt = pm * (one - f) * n_t * n_t * wim.abs() / (denom * denom);
        let pdf = R::select(choose_r, pr, pt);
        let radiance_scale = e * e;
        let side = wi.z * wo.z;
        let ok = !wo.z.eq(zero)
            & (c * wo.z).gt(zero)
            & pm.gt(zero)
            & ((choose_r & side.gt(zero)) | (!choose_r & side.lt(zero) & k.ge(zero)))
            & pdf.gt(zero)
            & pdf.is_finite()
            & base.is_finite();
        let weight = channels(|ch| {
            R::select(
                choose_r,
                reflect_tint[ch] * base,
                transmit_tint[ch] * base * radiance_scale,
            )
        });
        LaneSample {
            wi,
            weight,
            pdf,
            eta: R::select(choose_r, one, n_t / n_o),
            transmitted: !choose_r,
            ok,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::F32x8;
    use crate::math::rng::{Pcg32, RandomSource};
    use crate::math::warp::square_to_uniform_sphere;
    use crate::math::{Vec2, Vec3};
    use crate::recipe::MaterialRecipe;
    use crate::{Bsdf, BsdfContext};

    /// A source that returns the lobe number and the direction numbers (in whichever order
    /// the f64 model draws them), then further pairs from `free` (a stochastic model's
    /// draws from the free stream); a second lobe number fails loudly.
    struct Fixed {
        dir: Option<Vec2>,
        lobe: Option<f64>,
        free: Pcg32,
    }
    impl RandomSource for Fixed {
        fn next_f64(&mut self) -> f64 {
            self.lobe.take().expect("one lobe number")
        }
        fn next_2d(&mut self) -> Vec2 {
            self.dir.take().unwrap_or_else(|| self.free.next_2d())
        }
    }

    /// The lane side of the free stream: one pair from the generator for each lane asked,
    /// in lane order (one lane here: the f64 instantiation).
    struct FreeLanes(Pcg32);
    impl LaneRandom<f64> for FreeLanes {
        fn next_2d(&mut self, lanes: bool) -> (f64, f64) {
            if lanes {
                let u = self.0.next_2d();
                (u.x, u.y)
            } else {
                (f64::NAN, f64::NAN)
            }
        }
    }

    /// Given numbers, whatever the lanes asked (the f32/f64 comparison draws them itself).
    struct Given<R>(R, R);
    impl<R: Real> LaneRandom<R> for Given<R> {
        fn next_2d(&mut self, _: R::Mask) -> (R, R) {
            (self.0, self.1)
        }
    }

    fn materials() -> Vec<toml::Table> {
        [
            r#"type = "lambert"
               reflectance = [0.2, 0.5, 0.8]"#,
            r#"type = "conductor"
               distribution = "ggx"
               alpha = 0.3
               material = "Au""#,
            r#"type = "conductor"
               distribution = "beckmann"
               alpha_u = 0.2
               alpha_v = 0.5
               eta = [0.2, 0.9, 1.1]
               k = [3.9, 2.4, 2.1]"#,
            r#"type = "conductor"
               distribution = "ggx"
               alpha = 0.6
               material = "Cu"
               fresnel = "schlick""#,
            r#"type = "dielectric"
               distribution = "ggx"
               alpha = 0.3
               ior = 1.5"#,
            r#"type = "dielectric"
               distribution = "beckmann"
               alpha = 0.45
               ior = 1.33
               specular_transmittance = [0.9, 0.8, 0.7]"#,
            r#"type = "dielectric"
               distribution = "ggx"
               alpha_u = 0.1
               alpha_v = 0.7
               ior = 0.66"#,
            r#"type = "il"
               kd = [0.7, 0.28, 0.1]
               ni = 1.5
               distribution = "beckmann"
               alpha = 0.3
               masking = "smith""#,
            r#"type = "il"
               kd = [0.9, 0.5, 0.2]
               ni = 2.0
               distribution = "ggx"
               alpha_u = 0.1
               alpha_v = 0.6
               masking = "smith""#,
        ]
        .iter()
        .map(|s| s.parse().unwrap())
        .collect()
    }

    fn models() -> Vec<(LaneBsdf, std::sync::Arc<dyn Bsdf>)> {
        materials()
            .iter()
            .map(|t| {
                let recipe = MaterialRecipe::parse(t, std::path::Path::new(".")).unwrap();
                let lane = recipe.lane_model().expect("a lane model");
                (lane, recipe.build().unwrap())
            })
            .collect()
    }

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-3)
    }

    fn random_dir(rng: &mut Pcg32) -> Vec3 {
        square_to_uniform_sphere(rng.next_2d())
    }

    #[test]
    fn f64_lanes_match_the_models_eval_and_pdf() {
        let ctx = BsdfContext::RADIANCE;
        let mut rng = Pcg32::new(7, 1);
        for (lane, model) in models() {
            for k in 0..4000 {
                let (wo, wi) = (random_dir(&mut rng), random_dir(&mut rng));
                // The stochastic IL body: both sides draw from equal streams.
                let free = Pcg32::new(k, 11);
                let (v, p) = lane.eval_pdf_out_of_line(
                    &OwnColors,
                    wo.into(),
                    wi.into(),
                    &mut FreeLanes(free.clone()),
                );
                let want = model.eval(wo, wi, &ctx, &mut free.clone());
                let want_pdf = model.pdf(wo, wi, &ctx);
                for c in 0..3 {
                    assert!(
                        close(v[c], want[c], 1e-9),
                        "{}: f {wo} {wi}: {v:?} vs {want:?}",
                        model.describe()
                    );
                }
                assert!(
                    close(p, want_pdf, 1e-9),
                    "{}: pdf {wo} {wi}: {p} vs {want_pdf}",
                    model.describe()
                );
            }
        }
    }

    #[test]
    fn f64_lanes_match_the_models_samples() {
        let ctx = BsdfContext::RADIANCE;
        let mut rng = Pcg32::new(8, 3);
        for (lane, model) in models() {
            let mut taken = 0;
            for k in 0..4000 {
                let wo = random_dir(&mut rng);
                let (ul, ud) = (rng.next_f64(), rng.next_2d());
                let free = Pcg32::new(k, 12);
                let s = lane.sample_out_of_line(
                    &OwnColors,
                    wo.into(),
                    ul,
                    ud.x,
                    ud.y,
                    &mut FreeLanes(free.clone()),
                );
                let mut src = Fixed {
                    dir: Some(ud),
                    lobe: Some(ul),
                    free,
                };
                let want = model.sample(wo, &ctx, &mut src);
                match want {
                    Some(w) if s.ok => {
                        taken += 1;
                        let wi: Vec3 = s.wi.into();
                        assert!(
                            (wi - w.wi).length() < 1e-9,
                            "{}: {wo}: {wi} vs {}",
                            model.describe(),
                            w.wi
                        );
                        assert!(
                            close(s.pdf, w.pdf, 1e-9),
                            "{}: pdf {} vs {}",
                            model.describe(),
                            s.pdf,
                            w.pdf
                        );
                        for c in 0..3 {
                            assert!(
                                close(s.weight[c], w.weight[c], 1e-7),
                                "{}: weight {:?} vs {:?}",
                                model.describe(),
                                s.weight,
                                w.weight
                            );
                        }
                        assert_eq!(s.transmitted, w.lobe.intersects(LobeFlags::TRANSMISSION));
                        assert!(close(s.eta, w.eta, 1e-12));
                    }
                    // A sample one side rejects and the other keeps must be a borderline
                    // one: a weight or density at the edge of zero.
                    Some(w) => assert!(
                        w.pdf < 1e-6 || w.weight.max_component() < 1e-6,
                        "{}: lanes rejected {w:?}",
                        model.describe()
                    ),
                    None => assert!(
                        !s.ok || s.pdf < 1e-6 || s.weight.iter().all(|v| *v < 1e-6),
                        "{}: lanes kept a sample the model rejects at {wo}",
                        model.describe()
                    ),
                }
            }
            assert!(
                taken > 1000,
                "{}: only {taken} samples compared",
                model.describe()
            );
        }
    }

    /// A model that says it does not read its lobe number samples the same direction and
    /// weight whatever that number is (the renderer then leaves its dimension undrawn).
    /// A roughness set on a lane model gives the model its recipe builds with that value,
    /// and a bad value is the recipe's error.
    #[test]
    fn a_roughness_equals_the_model_built_with_it() {
        for table in materials() {
            let recipe = MaterialRecipe::parse(&table, std::path::Path::new(".")).unwrap();
            let lane = recipe.lane_model().unwrap();
            for key in recipe.texturable_scalar_keys() {
                let set = lane.with_roughness(key, 0.42).unwrap();
                let mut recipe = recipe.clone();
                recipe.set_scalar(key, 0.42).unwrap();
                let expected = recipe.lane_model().unwrap();
                assert_eq!(format!("{set:?}"), format!("{expected:?}"), "{table} {key}");
                assert!(lane.with_roughness(key, -1.0).is_err());
                assert!(lane.with_roughness(key, f64::NAN).is_err());
            }
        }
        let lambert = MaterialRecipe::parse(&materials()[0], std::path::Path::new("."))
            .unwrap()
            .lane_model()
            .unwrap();
        assert!(lambert.with_roughness("alpha", 0.3).is_err());
    }

    #[test]
    fn one_lobe_models_ignore_the_lobe_number() {
        let mut rng = Pcg32::new(10, 2);
        let mut checked = 0;
        for (lane, _) in models() {
            if lane.reads_lobe_number() {
                continue;
            }
            for _ in 0..500 {
                let wo = LVec3::<f64>::from_fn(|_| random_dir(&mut rng));
                let (u0, u1) = (rng.next_f64(), rng.next_f64());
                let a = lane.sample_out_of_line(&OwnColors, wo, 0.0, u0, u1, &mut Given(0.3, 0.6));
                let b =
                    lane.sample_out_of_line(&OwnColors, wo, 0.999, u0, u1, &mut Given(0.3, 0.6));
                assert_eq!(a.ok, b.ok);
                if a.ok {
                    assert_eq!(a.wi.lane(0), b.wi.lane(0));
                    assert_eq!(a.weight, b.weight);
                    assert_eq!(a.pdf, b.pdf);
                }
                checked += 1;
            }
        }
        assert_eq!(checked, 4 * 500, "Lambert and the three conductors");
    }

    #[test]
    fn f32x8_lanes_match_f64_lanes() {
        let mut rng = Pcg32::new(9, 5);
        let (mut skipped, mut compared) = (0, 0);
        for (lane, model) in models() {
            for _ in 0..500 {
                let wo: [Vec3; 8] = std::array::from_fn(|_| random_dir(&mut rng));
                let wi: [Vec3; 8] = std::array::from_fn(|_| random_dir(&mut rng));
                let u: [[f64; 5]; 8] =
                    std::array::from_fn(|_| std::array::from_fn(|_| rng.next_f64()));
                let wo8 = LVec3::<F32x8>::from_fn(|i| wo[i]);
                let wi8 = LVec3::<F32x8>::from_fn(|i| wi[i]);
                let free8 = || Given(F32x8::from_fn(|i| u[i][3]), F32x8::from_fn(|i| u[i][4]));
                let (v8, p8) = lane.eval_pdf_out_of_line(&OwnColors, wo8, wi8, &mut free8());
                let s8 = lane.sample_out_of_line(
                    &OwnColors,
                    wo8,
                    F32x8::from_fn(|i| u[i][0]),
                    F32x8::from_fn(|i| u[i][1]),
                    F32x8::from_fn(|i| u[i][2]),
                    &mut free8(),
                );
                for i in 0..8 {
                    // The f64 reference at the f32 inputs, so that only the arithmetic differs.
                    let f32_in = |x: f64| x as f32 as f64;
                    let free = || Given(f32_in(u[i][3]), f32_in(u[i][4]));
                    let (wo_i, wi_i) = (wo8.lane(i), wi8.lane(i));
                    let (v, p) = lane.eval_pdf_out_of_line(
                        &OwnColors,
                        wo_i.into(),
                        wi_i.into(),
                        &mut free(),
                    );
                    // f32 arithmetic moves an ill-conditioned value by more than its rounding
                    // (grazing pairs, near-specular peaks, Fresnel at the critical angle,
                    // where 1 − F ∝ √(cos − cos_c)): compare where moving wi by 1e-6 moves
                    // the f64 value and density by less than 1e-4.
                    let (vp, pp) = lane.eval_pdf_out_of_line(
                        &OwnColors,
                        wo_i.into(),
                        (wi_i + Vec3::splat(1e-6)).normalize().into(),
                        &mut free(),
                    );
                    let steady = |a: f64, b: f64| (a - b).abs() <= 1e-4 * a.abs().max(1e-3);
                    let conditioned = steady(p, pp) && (0..3).all(|c| steady(v[c], vp[c]));
                    if !conditioned {
                        skipped += 1;
                    }
                    compared += 1;
                    if wo[i].z.abs() > 1e-2 && wi[i].z.abs() > 1e-2 && p < 1e3 && conditioned {
                        assert!(
                            close(p8.lane(i), p, 2e-3),
                            "{}: pdf {} vs {p}",
                            model.describe(),
                            p8.lane(i)
                        );
                        for c in 0..3 {
                            assert!(
                                close(v8[c].lane(i), v[c], 2e-3),
                                "{}: f {} vs {} at {wo_i}, {wi_i}",
                                model.describe(),
                                v8[c].lane(i),
                                v[c]
                            );
                        }
                    }
                    let s = lane.sample_out_of_line(
                        &OwnColors,
                        wo_i.into(),
                        f32_in(u[i][0]),
                        f32_in(u[i][1]),
                        f32_in(u[i][2]),
                        &mut free(),
                    );
                    let same_lobe = s.transmitted == s8.transmitted.lane(i);
                    if s.ok && s8.ok.lane(i) && same_lobe && wo[i].z.abs() > 1e-2 && s.pdf < 1e3 {
                        assert!(
                            (s8.wi.lane(i) - Vec3::from(s.wi)).length() < 2e-3,
                            "{}",
                            model.describe()
                        );
                    }
                }
            }
        }
        println!("f32x8 against f64: {skipped} of {compared} pairs ill-conditioned, not compared");
        assert!(skipped * 50 < compared, "{skipped} of {compared} skipped");
    }
}
