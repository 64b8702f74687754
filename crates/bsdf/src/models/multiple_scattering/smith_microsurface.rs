//! The Smith microsurface as a random medium: the light transport on which the
//! multiple-scattering conductor and dielectric are built (Heitz, Hanika, d'Eon & Dachsbacher
//! 2016, "Multiple-scattering microfacet BSDFs with the Smith model", ACM TOG 35(4) — cited
//! HHdD16 below; see `docs/references.md`). It is not one of the five papers facette
//! implements, so the results used here are restated and derived in this header and cited
//! by section.
//!
//! **Statistics** [HHdD16 §3–4]. The Smith microsurface has uncorrelated heights and slopes:
//! heights h with density P1 and distribution function C1, normals with the distribution D of
//! the microfacet core (Beckmann or GGX, anisotropic), and the Smith Λ of D. Writing the
//! signed Λ of a direction w as Λ(w) for w·n > 0 and −1 − Λ(−w) for w·n < 0:
//!
//! - a ray leaving height h upward in direction w escapes with probability
//!   G1(w, h) = C1(h)^Λ(w) (Smith's height-dependent masking);
//! - otherwise its next intersection has C1(h′) = C1(h) (1 − U)^{−1/Λ(w)}, U uniform on the
//!   event "intersects"; a downward ray always intersects, at C1(h′) = C1(h) U^{1/(1 + Λ(−w))}
//!   — both are the inversion of P(no intersection between h and h′) = (C1(h)/C1(h′))^Λ(w)
//!   [HHdD16 §4, the free-path distribution in height];
//! - the facet hit has a normal drawn from the visible normals of the direction the ray
//!   comes from, D_w(m) = ⟨w, m⟩ D(m) / A(w), A(w) = ∫ ⟨w, m⟩ D(m) dω_m = (1 + Λ(w)) (w·n)
//!   with the signed Λ — valid above and below the horizon [HHdD16 §4, the phase function's
//!   normal distribution]; the facet's optics (a [`FacetScattering`]) then reflect or refract.
//!
//! Light entering from direction `i` starts at h = +∞ (C1 = 1). The walk's first vertex
//! reproduces the single-scattering BRDF with the height-correlated Smith masking exactly:
//! E[p(i → o) G1(o, h₁)] = D G₂ / (4 |i·n|) with G₂ = 1/(1 + Λ(i) + Λ(o)) for reflection and
//! (1 + Λ(i)) B(1 + Λ(i), 1 + Λ(o)) ⋯ for refraction, i.e. WMLT07 eqs. 20–21 with
//! [`Masking::SmithCorrelated`](crate::microfacet::Masking) — the models replace that vertex
//! by the shared specular lobe's closed form and estimate only the orders ≥ 2.
//!
//! **Estimators** [HHdD16 §5–6]. [`Microsurface::walk`] is the physical walk (the BSDF's
//! sampler): its exit direction has density f(i, o)|o·n| / (albedo) and it carries the
//! product of the event weights. [`Microsurface::estimate`] is the unbiased evaluation: the
//! same walk, with next-event estimation toward `o` at every vertex — the phase function
//! p(w → o) times the probability G1(o, h) that `o` escapes from that height — whose
//! expectation is f(i, o)|o·n|.
//!
//! **Sides.** A dielectric walk crosses the interface: below it, the microsurface seen from
//! inside is the same random surface mirrored through the tangent plane (both height
//! distributions are symmetric and D is even in the slopes), so each side is handled in its
//! own frame — z mirrored and heights negated for the inside.
//!
//! **Heights.** The BSDF does not depend on the height distribution [HHdD16 §4]: only C1(h)
//! enters the walk. Both distributions of the paper are provided (uniform on [−1, 1], the
//! default, and the standard Gaussian); the tests check that they give the same BSDF.

use crate::error::{ParamError, ParamResult};
use crate::finite::guard;
use crate::math::rng::RandomSource;
use crate::math::special::{erfc, erfinv};
use crate::math::spectrum::Spectrum;
use crate::math::{Vec3, SQRT_PI};
use crate::microfacet::{normal_from_slopes, BeckmannG1, Distribution, Ndf};
use std::f64::consts::SQRT_2;

/// Longest walk followed (vertices). Walks longer than this are abandoned: their energy is
/// lost, a bias the tests measure (below 1e-5 of the albedo up to α = 1.5; see
/// `docs/materials.md`).
pub const MAX_ORDER: usize = 256;

/// Copies of the remainder of an evaluation walk that crosses the interface away from the
/// side of the direction it estimates toward ([`Microsurface::estimate_with`]): the crossing
/// next-event terms of such walks are the heavy tail of the dielectric's estimator (see
/// `docs/materials.md`, "GGX glass at grazing").
pub const SPLIT_AT_CROSSING: usize = 8;

/// The distribution of microsurface heights [HHdD16 §4].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum HeightDistribution {
    /// P1 = ½ on [−1, 1].
    Uniform,
    /// The standard normal density.
    Gaussian,
}

impl HeightDistribution {
    pub const NAMES: &'static [&'static str] = &["uniform", "gaussian"];

    pub fn parse(s: &str) -> ParamResult<Self> {
        match s {
            "uniform" => Ok(HeightDistribution::Uniform),
            "gaussian" => Ok(HeightDistribution::Gaussian),
            other => Err(ParamError::UnknownChoice {
                what: "height_distribution".into(),
                given: other.into(),
                valid: Self::NAMES.join(", "),
            }),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            HeightDistribution::Uniform => "uniform",
            HeightDistribution::Gaussian => "gaussian",
        }
    }

    /// C1(h), the fraction of the microsurface below height h; C1(+∞) = 1.
    #[inline]
    pub fn c1(&self, h: f64) -> f64 {
        match self {
            HeightDistribution::Uniform => (0.5 * (h + 1.0)).clamp(0.0, 1.0),
            HeightDistribution::Gaussian => 0.5 * erfc(-h / SQRT_2),
        }
    }

    /// C1⁻¹(c) for c ∈ [0, 1].
    #[inline]
    pub fn inv_c1(&self, c: f64) -> f64 {
        match self {
            HeightDistribution::Uniform => (2.0 * c - 1.0).clamp(-1.0, 1.0),
            // Kept off ±1 (C1 within 1e-16 of 0 or 1): heights of ±∞ would freeze the walk.
            HeightDistribution::Gaussian => {
                SQRT_2 * erfinv((2.0 * c - 1.0).clamp(-1.0 + 2e-16, 1.0))
            }
        }
    }
}

/// The optics of one facet. Directions are in the frame of the side the light travels in
/// (that side's normal is +z, so the facet normal `m` has m.z > 0); `wi` points from the
/// facet back toward where the light came from, with wi·m > 0.
pub trait FacetScattering {
    /// Draws the facet event: the outgoing propagation direction (same frame), whether it
    /// crossed the interface, and the event's weight.
    fn scatter(
        &self,
        wi: Vec3,
        m: Vec3,
        inside: bool,
        rng: &mut dyn RandomSource,
    ) -> Option<(Vec3, bool, Spectrum)>;

    /// The phase function times the event weight: the density, in the solid angle of `wo`,
    /// of leaving toward `wo` after hitting a facet drawn from the visible normals of `wi`.
    /// `crosses` says whether `wo` lies in the other medium (then wo·n < 0 in this frame).
    fn phase(
        &self,
        surface: &Microsurface,
        wi: Vec3,
        wo: Vec3,
        inside: bool,
        crosses: bool,
    ) -> Spectrum;
}

/// Where a physical walk leaves the microsurface.
#[derive(Clone, Copy, Debug)]
pub struct WalkExit {
    /// Exit direction in the shading frame (z < 0: it left into the inside medium).
    pub dir: Vec3,
    /// Product of the event weights.
    pub weight: Spectrum,
    /// Number of facet interactions (≥ 1).
    pub order: usize,
}

/// A Smith microsurface: its normal distribution (Beckmann with the exact Λ, or GGX) and
/// its height distribution.
#[derive(Clone, Debug)]
pub struct Microsurface {
    ndf: Ndf,
    heights: HeightDistribution,
}

/// The frame of a side: the inside is the mirror image through the tangent plane.
#[inline]
fn to_side(v: Vec3, inside: bool) -> Vec3 {
    if inside {
        Vec3::new(v.x, v.y, -v.z)
    } else {
        v
    }
}

impl Microsurface {
    /// Beckmann (with the exact Smith Λ) or GGX: the distributions whose visible normals can
    /// be sampled from below the horizon.
    pub fn new(ndf: Ndf, heights: HeightDistribution) -> ParamResult<Self> {
        match &ndf {
            Ndf::Ggx(_) => {}
            Ndf::Beckmann(b) if b.g1_form() == BeckmannG1::Exact => {}
            Ndf::Beckmann(_) => {
                return Err(ParamError::Invalid(
                    "scattering = \"multiple\" needs the exact Beckmann Λ (g1 = \"exact\"): the \
                     random walk's free paths are defined by Λ itself (HHdD16 §4)"
                        .into(),
                ))
            }
            other => {
                return Err(ParamError::Invalid(format!(
                    "scattering = \"multiple\" is defined for the beckmann and ggx \
                     distributions (got {})",
                    other.kind_name()
                )))
            }
        }
        Ok(Microsurface { ndf, heights })
    }

    pub fn ndf(&self) -> &Ndf {
        &self.ndf
    }

    pub fn heights(&self) -> HeightDistribution {
        self.heights
    }

    /// α_w sin θ_w: the slope width of D seen along the azimuth of `w`, times sin θ_w.
    #[inline]
    fn projected_slope(&self, w: Vec3) -> f64 {
        let (ax, ay) = match &self.ndf {
            Ndf::Beckmann(b) => (b.alpha_x(), b.alpha_y()),
            Ndf::Ggx(g) => (g.alpha_x(), g.alpha_y()),
            _ => (1.0, 1.0),
        };
        (ax * ax * w.x * w.x + ay * ay * w.y * w.y).sqrt()
    }

    /// A(w) = ∫ ⟨w, m⟩ D(m) dω_m = (1 + Λ(w)) (w·n) with the signed Λ, for any direction:
    /// the projected area of the microsurface seen from w (from below the horizon: the
    /// back-facing microfacets' share).
    pub fn projected_area(&self, w: Vec3) -> f64 {
        let z = w.z;
        let s = self.projected_slope(w);
        match &self.ndf {
            Ndf::Ggx(_) => {
                // (z + √(z² + s²))/2, written without cancellation below the horizon.
                let r = (z * z + s * s).sqrt();
                if z >= 0.0 {
                    0.5 * (z + r)
                } else if s > 0.0 {
                    0.5 * s * s / (r - z)
                } else {
                    0.0
                }
            }
            _ => {
                if z > 0.0 {
                    z * (1.0 + self.ndf.lambda(w))
                } else if z < 0.0 {
                    let l = self.ndf.lambda(w);
                    if l.is_finite() {
                        -z * l
                    } else {
                        s / (2.0 * SQRT_PI)
                    }
                } else {
                    s / (2.0 * SQRT_PI)
                }
            }
        }
    }

    /// D_w(m) = max(0, w·m) D(m) / A(w), for w on either side of the horizon.
    #[inline]
    pub fn visible_density(&self, w: Vec3, m: Vec3) -> f64 {
        let wm = w.dot(m);
        if wm <= 0.0 || m.z <= 0.0 {
            return 0.0;
        }
        let a = self.projected_area(w);
        if !(a > 0.0) {
            return 0.0;
        }
        guard(wm * self.ndf.d(m) / a, || {
            format!(
                "visible density of {} at w = {w:?}, m = {m:?}",
                self.ndf.describe()
            )
        })
    }

    /// Draws a normal from D_w for any direction w (the core's samplers above the horizon;
    /// below it, GGX's spherical-cap construction and an exact rejection sampler of the
    /// Beckmann slope marginal). `None` when nothing is visible from w (straight down).
    pub fn sample_visible(&self, w: Vec3, rng: &mut dyn RandomSource) -> Option<Vec3> {
        let m = if w.z > 0.0 {
            self.ndf.sample_visible(w, rng.next_2d())
        } else {
            match &self.ndf {
                Ndf::Ggx(g) => {
                    sample_ggx_visible_below(g.alpha_x(), g.alpha_y(), w, rng.next_2d())?
                }
                Ndf::Beckmann(b) => {
                    sample_beckmann_visible_below(b.alpha_x(), b.alpha_y(), w, rng)?
                }
                _ => return None,
            }
        };
        (m.is_finite() && m.z > 0.0 && w.dot(m) > 0.0).then_some(m)
    }

    /// G1(w, h) = C1(h)^Λ(w): the probability that a ray leaving height h upward along w
    /// (w·n > 0 in its side's frame) escapes.
    #[inline]
    pub fn escape_probability(&self, w: Vec3, h: f64) -> f64 {
        if w.z <= 0.0 {
            return 0.0;
        }
        let l = self.ndf.lambda(w);
        if l == 0.0 {
            return 1.0;
        }
        self.heights.c1(h).powf(l)
    }

    /// The height of the next intersection of a ray leaving height `h` along `w` (side
    /// frame), or `None` when it escapes; `u` uniform in [0, 1).
    #[inline]
    pub fn next_height(&self, w: Vec3, h: f64, u: f64) -> Option<f64> {
        let c = self.heights.c1(h);
        let l = self.ndf.lambda(w);
        let c_next = if w.z > 0.0 {
            if l == 0.0 || u >= 1.0 - c.powf(l) {
                return None;
            }
            (c / (1.0 - u).powf(1.0 / l)).min(1.0)
        } else if w.z < 0.0 {
            c * (1.0 - u).powf(1.0 / (1.0 + l))
        } else {
            // In the tangent plane: Λ = ∞, the next facet is at the same height.
            return Some(h);
        };
        Some(self.heights.inv_c1(c_next))
    }

    /// The physical random walk of light entering from `wi` (shading frame, either side):
    /// where and with which weight it leaves; `None` when it exceeds [`MAX_ORDER`] vertices
    /// or meets a numerically degenerate configuration.
    pub fn walk(
        &self,
        facets: &impl FacetScattering,
        wi: Vec3,
        rng: &mut dyn RandomSource,
    ) -> Option<WalkExit> {
        if wi.z == 0.0 {
            return None;
        }
        let mut inside = wi.z < 0.0;
        let mut h = f64::INFINITY;
        let mut dir = -wi;
        let mut weight = Spectrum::ONE;
        for order in 0..MAX_ORDER {
            let d = to_side(dir, inside);
            match self.next_height(d, h, rng.next_f64()) {
                None => return (order > 0).then_some(WalkExit { dir, weight, order }),
                Some(next) => h = next,
            }
            let (out, crossed, w) = self.scatter(facets, -d, inside, rng)?;
            weight *= w;
            dir = to_side(out, inside);
            if crossed {
                inside = !inside;
                h = -h;
            }
            if weight.is_black() {
                return None;
            }
        }
        None
    }

    /// Where the orders ≥ 2 of light entering from `wi` leave, as expected flux: (leaving
    /// on the side of `wi`, leaving on the other side) for one walk — an unbiased estimate
    /// of the walk's reflectance and transmittance of orders ≥ 2 (for facets whose event
    /// weights are 1, as untinted glass). The physical walk of [`walk`](Self::walk) with
    /// its escape events replaced by their expectation [HHdD16 §4: the escape probability
    /// G1(w, h) = C1(h)^Λ(w), eq. of the height of the next intersection]: after each vertex
    /// the probability of escaping along the scattered direction is tallied on that
    /// direction's side (from the second vertex on: first-vertex escapes are the single
    /// scattering) and the walk continues, with the remaining probability, to a next
    /// intersection drawn conditioned on a hit (Russian roulette once under 1/20 of the
    /// entering flux). Fresnel's choice at each facet stays sampled. `None` for a direction
    /// in the tangent plane.
    pub fn higher_order_exits(
        &self,
        facets: &impl FacetScattering,
        wi: Vec3,
        rng: &mut dyn RandomSource,
    ) -> Option<(f64, f64)> {
        if wi.z == 0.0 {
            return None;
        }
        let start_inside = wi.z < 0.0;
        let mut inside = start_inside;
        let mut h = f64::INFINITY;
        let mut dir = -wi;
        let mut alive = 1.0;
        let (mut own, mut other) = (0.0, 0.0);
        for order in 0..MAX_ORDER {
            let d = to_side(dir, inside);
            let u = rng.next_f64();
            let next = if order == 0 {
                self.next_height(d, h, u)
            } else {
                let e = self.escape_probability(d, h);
                if order >= 2 {
                    if inside == start_inside {
                        own += alive * e;
                    } else {
                        other += alive * e;
                    }
                }
                alive *= 1.0 - e;
                // Russian roulette below 1/20 of the entering flux (unbiased: survivors
                // carry 1/20), so that walks almost sure to have left stop early.
                if alive < 0.05 {
                    if !(rng.next_f64() * 0.05 < alive) {
                        break;
                    }
                    alive = 0.05;
                }
                // A hit: u drawn on [0, 1 − e), next_height's range of intersections.
                self.next_height(d, h, u * (1.0 - e))
            };
            match next {
                Some(n) => h = n,
                None => break,
            }
            // A degenerate facet event ends the walk, as in `walk`: the flux still in the
            // microsurface is lost, what escaped before stays tallied.
            let Some((out, crossed, _)) = self.scatter(facets, -d, inside, rng) else {
                break;
            };
            dir = to_side(out, inside);
            if crossed {
                inside = !inside;
                h = -h;
            }
        }
        Some((own, other))
    }

    /// One facet event at the current vertex: a visible normal of `wi`, then the facet's
    /// optics.
    #[inline]
    fn scatter(
        &self,
        facets: &impl FacetScattering,
        wi: Vec3,
        inside: bool,
        rng: &mut dyn RandomSource,
    ) -> Option<(Vec3, bool, Spectrum)> {
        let m = self.sample_visible(wi, rng)?;
        let (out, crossed, w) = facets.scatter(wi, m, inside, rng)?;
        out.is_finite().then_some((out, crossed, w))
    }

    /// Whether the evaluation walk between `a` and `b` (same side, either z sign) should
    /// start from `a`: from the more masked direction (the larger Λ; ties broken by a fixed
    /// order of the coordinates), with next-event estimation toward the less masked one.
    ///
    /// Both choices are unbiased (the BSDF is reciprocal), but their variances differ by
    /// orders of magnitude: the rare factor of the next-event estimate is the masking
    /// G1(o, h) = C1(h)^Λ(o), near 0 for a grazing `o` unless the walk reaches the top of the
    /// microsurface, whereas a walk entering from the grazing direction starts there. For
    /// Beckmann α = 0.5 (`examples`-style measurement in `tests/suite/multiple_scattering.rs` and
    /// docs/materials.md) the walk from the steeper direction underestimated orders ≥ 2 by
    /// factors up to 15 at 10⁵ estimates, single estimates reaching 10⁴–10⁵ × the mean. The
    /// rule depends on the unordered pair only, so the eval estimate of f(a, b) and of
    /// f(b, a) is the same random variable: reciprocal in distribution, not only in
    /// expectation.
    pub fn walk_from_first(&self, a: Vec3, b: Vec3) -> bool {
        let key = |w: Vec3| {
            let w = Vec3::new(w.x, w.y, w.z.abs());
            (self.ndf.lambda(w), -w.z, w.x, w.y)
        };
        let (ka, kb) = (key(a), key(b));
        ka.partial_cmp(&kb) != Some(std::cmp::Ordering::Less)
    }

    /// E[1{hit} G1(o, h′)]: the probability that a ray leaving height `h` along `d` (side
    /// frame) meets the microsurface again, at a height h′ from which `o` (same side, o·n > 0)
    /// escapes — the expectation over the free path of the masking factor of the next
    /// vertex's next-event estimate. With c = C1(h) and y = C1(h′) [HHdD16 §4's free-path
    /// law, the `next_height` inversion]: upward, y has the density Λ_d c^{Λ_d} y^{−Λ_d−1} on
    /// [c, 1] and E = Λ_d (c^{Λ_d} − c^{Λ_o}) / (Λ_o − Λ_d); downward, y has the density
    /// (1 + Λ′) y^{Λ′} / c^{1+Λ′} on [0, c] (Λ′ = Λ(−d)) and E = (1 + Λ′) c^{Λ_o} / (1 + Λ′ + Λ_o);
    /// in the tangent plane h′ = h and E = c^{Λ_o}.
    pub fn expected_next_escape(&self, d: Vec3, h: f64, o: Vec3) -> f64 {
        if o.z <= 0.0 {
            return 0.0;
        }
        let c = self.heights.c1(h);
        if !(c > 0.0) {
            return 0.0;
        }
        let lo = self.ndf.lambda(o);
        let ld = self.ndf.lambda(d);
        if d.z > 0.0 {
            if ld == 0.0 || c >= 1.0 {
                return 0.0;
            }
            // Λ_d c^{Λ_d} (−ln c) · (1 − e^{δ ln c}) / (−δ ln c), δ = Λ_o − Λ_d, written with
            // expm1 so that it stays accurate when Λ_o ≈ Λ_d or both are tiny: with
            // φ(x) = (e^x − 1)/x and x = δ ln c, E = Λ_d (−ln c) c^{Λ_d} φ(x). For x > 0
            // (Λ_d > Λ_o) φ(x) grows like e^x while c^{Λ_d} shrinks: a nearly horizontal
            // upward d (Λ_d ~ 10⁴) made them ∞ and 0, and E NaN instead of ≈ 1 − c^{Λ_d}.
            // The same value is c^{Λ_o} φ(−x) in place of c^{Λ_d} φ(x) (both are
            // (c^{Λ_d} − c^{Λ_o})/x), whose factors stay in [0, 1].
            let l = c.ln();
            let x = (lo - ld) * l;
            let phi = |x: f64| if x == 0.0 { 1.0 } else { x.exp_m1() / x };
            let e = if x > 0.0 {
                ld * (lo * l).exp() * (-l) * phi(-x)
            } else {
                ld * (ld * l).exp() * (-l) * phi(x)
            };
            guard(e, || {
                format!("expected next escape along d = {d:?} from C1 = {c} toward o = {o:?}")
            })
            .clamp(0.0, 1.0)
        } else if d.z < 0.0 {
            if !ld.is_finite() {
                return c.powf(lo);
            }
            (1.0 + ld) / (1.0 + ld + lo) * c.powf(lo)
        } else {
            c.powf(lo)
        }
    }

    /// Unbiased estimate of the orders ≥ `min_order` of f(i, o) |o·n| for light entering from
    /// `i` and leaving toward `o` (shading frame, either side each): the walk from `i` with
    /// next-event estimation toward `o` at every vertex of order ≥ `min_order`.
    ///
    /// For a vertex on the side of `o` (reflection toward `o`) the masking factor G1(o, h′) of
    /// the next-event estimate is replaced by its expectation over the free path that leads to
    /// that vertex ([`Self::expected_next_escape`]; the phase function does not depend on the
    /// height): the same expectation, but a bounded one. As printed [HHdD16 §6] the estimate
    /// divides by the projected area A(w) = Λ(−w)|w·n| of a ray travelling upward, reached
    /// with a probability ∝ Λ(−w): for Beckmann, whose Λ decays like e^{−cot²θ/α²}, its
    /// variance is huge (unbounded as the view approaches the normal) and finite samples
    /// fall short of the mean — a non-reciprocity of several percent at tens of "standard
    /// errors" (measured in `tests/suite/multiple_scattering.rs`). Vertices across the interface
    /// (refraction toward `o`) keep the sampled height.
    ///
    /// Where the walk first crosses the interface away from the side of `o`, its remainder is
    /// split into [`SPLIT_AT_CROSSING`] copies of 1/[`SPLIT_AT_CROSSING`] the throughput
    /// (particle splitting, unbiased): the next-event terms refracting back toward a grazing
    /// `o` from a walk travelling nearly horizontally on the other side are the rare, large
    /// part of the dielectric's estimator (GGX α = 0.7 glass at 85° from inside: the top
    /// 0.01 % of estimates carried 16 % of the mean; `docs/materials.md`).
    pub fn estimate(
        &self,
        facets: &impl FacetScattering,
        i: Vec3,
        o: Vec3,
        min_order: usize,
        rng: &mut dyn RandomSource,
    ) -> Spectrum {
        self.estimate_with(facets, i, o, min_order, true, rng)
    }

    /// [`Self::estimate`] with the choice of the masking factor of same-side next-event
    /// estimates: its expectation over the free path (`expected_masking`, the default) or
    /// G1(o, h′) at the sampled height h′ (HHdD16's estimator as printed; kept to measure the
    /// difference).
    pub fn estimate_with(
        &self,
        facets: &impl FacetScattering,
        i: Vec3,
        o: Vec3,
        min_order: usize,
        expected_masking: bool,
        rng: &mut dyn RandomSource,
    ) -> Spectrum {
        if i.z == 0.0 || o.z == 0.0 {
            return Spectrum::ZERO;
        }
        let start = WalkState {
            inside: i.z < 0.0,
            h: f64::INFINITY,
            dir: -i,
            throughput: Spectrum::ONE,
            order: 1,
        };
        let sum = self.estimate_from(facets, o, min_order, expected_masking, start, true, rng);
        guard(sum, || {
            format!(
                "walk estimate of {} from i = {i:?} toward o = {o:?}",
                self.ndf.describe()
            )
        })
    }

    /// The next-event terms of the walk from `state` on (the loop of [`Self::estimate_with`]).
    /// When `split` holds, the first time the walk crosses the interface away from the side
    /// of `o` its remainder is followed [`SPLIT_AT_CROSSING`] times, each copy carrying
    /// 1/[`SPLIT_AT_CROSSING`] of the throughput (particle splitting: unbiased, the copies
    /// do not split again).
    #[allow(clippy::too_many_arguments)]
    fn estimate_from(
        &self,
        facets: &impl FacetScattering,
        o: Vec3,
        min_order: usize,
        expected_masking: bool,
        state: WalkState,
        split: bool,
        rng: &mut dyn RandomSource,
    ) -> Spectrum {
        let o_inside = o.z < 0.0;
        let WalkState {
            mut inside,
            mut h,
            mut dir,
            mut throughput,
            order: first,
        } = state;
        let mut sum = Spectrum::ZERO;
        for order in first..=MAX_ORDER {
            let d = to_side(dir, inside);
            let wi = -d;
            let crosses = o_inside != inside;
            let nee = order >= min_order;
            if nee && expected_masking && !crosses {
                let o_side = to_side(o, inside);
                let e = self.expected_next_escape(d, h, o_side);
                if e > 0.0 {
                    let p = facets.phase(self, wi, o_side, inside, false);
                    sum += guard(throughput * p * e, || {
                        format!("walk next-event term at order {order}, toward o = {o:?}")
                    });
                }
            }
            match self.next_height(d, h, rng.next_f64()) {
                None => break,
                Some(next) => h = next,
            }
            if nee && (crosses || !expected_masking) {
                let p = facets.phase(self, wi, to_side(o, inside), inside, crosses);
                if !p.is_black() {
                    // o escapes from this height, on its own side.
                    let h_o = if crosses { -h } else { h };
                    let g = self.escape_probability(to_side(o, o_inside), h_o);
                    sum += throughput * p * g;
                }
            }
            let Some((out, crossed, w)) = self.scatter(facets, wi, inside, rng) else {
                break;
            };
            throughput *= w;
            dir = to_side(out, inside);
            if crossed {
                inside = !inside;
                h = -h;
            }
            if throughput.is_black() {
                break;
            }
            if split && crossed && inside != o_inside && order < MAX_ORDER {
                let copy = WalkState {
                    inside,
                    h,
                    dir,
                    throughput: throughput / SPLIT_AT_CROSSING as f64,
                    order: order + 1,
                };
                for _ in 0..SPLIT_AT_CROSSING {
                    sum += self.estimate_from(
                        facets,
                        o,
                        min_order,
                        expected_masking,
                        copy,
                        false,
                        rng,
                    );
                }
                break;
            }
        }
        sum
    }
}

/// Where an evaluation walk stands before its vertex of order `order`: the side it travels
/// in, the height it left (+∞ before the first vertex), its propagation direction (shading
/// frame) and throughput.
#[derive(Clone, Copy, Debug)]
struct WalkState {
    inside: bool,
    h: f64,
    dir: Vec3,
    throughput: Spectrum,
    order: usize,
}

/// Visible GGX normals for a direction at or below the horizon (w.z ≤ 0), by the
/// spherical-cap construction (Dupuy & Benyoub 2023, "Sampling visible GGX normals with
/// spherical caps"): in the configuration stretched to unit roughness, D is uniform over the
/// hemisphere of normals, and h = w + c with c uniform on the unit sphere gives normalize(h)
/// the density ∝ max(0, w·m) (c is the mirror image of w about m, dω_c = 4 (w·m) dω_m);
/// restricting c to c.z ≥ −w.z keeps exactly the normals of the upper hemisphere. Unlike the
/// projected-hemisphere method it holds for directions below the horizon.
fn sample_ggx_visible_below(ax: f64, ay: f64, w: Vec3, u: crate::math::Vec2) -> Option<Vec3> {
    let ws = Vec3::new(ax * w.x, ay * w.y, w.z).normalize_or_zero();
    if ws == Vec3::ZERO || ws.z <= -1.0 + 1e-12 {
        return None;
    }
    let z = -ws.z + (1.0 + ws.z) * u.x;
    let h: Vec3 = crate::microfacet::ggx::spherical_cap_halfway::<f64>(ws.into(), z, u.y).into();
    let m = Vec3::new(ax * h.x, ay * h.y, h.z.max(0.0)).normalize_or_zero();
    (m != Vec3::ZERO).then_some(m)
}

/// Visible Beckmann normals for a direction at or below the horizon (w.z ≤ 0). In the
/// configuration stretched to unit roughness, with the view's azimuth along +x and
/// k = cot θ ≤ 0, the visible slopes have the density ∝ (k − x̃) e^{−x̃² − ỹ²} on x̃ < k (the
/// projected area cos θ − x̃ sin θ of a facet of slope x̃); ỹ is an independent Gaussian and
/// t = −x̃ > a = −k has the density ∝ (t − a) e^{−t²}, drawn exactly by rejection.
fn sample_beckmann_visible_below(
    ax: f64,
    ay: f64,
    w: Vec3,
    rng: &mut dyn RandomSource,
) -> Option<Vec3> {
    let ws = Vec3::new(ax * w.x, ay * w.y, w.z);
    let rxy = (ws.x * ws.x + ws.y * ws.y).sqrt();
    if !(rxy > 0.0) {
        return None;
    }
    let a = -ws.z / rxy;
    let t = sample_slope_tail(a, rng)?;
    let (sx, sy) = (-t, erfinv(2.0 * rng.next_f64() - 1.0));
    if !sy.is_finite() {
        return None;
    }
    let (cp, sp) = (ws.x / rxy, ws.y / rxy);
    let rx = cp * sx - sp * sy;
    let ry = sp * sx + cp * sy;
    Some(normal_from_slopes(rx * ax, ry * ay))
}

/// Draws t > a ≥ 0 from the density ∝ (t − a) e^{−t²}. With r = t − a the target is
/// ∝ r e^{−r²} e^{−2ar}: for a ≤ 0.7 the proposal r e^{−r²} (r = √(−ln U)) is accepted with
/// probability e^{−2ar}; beyond, the proposal r e^{−2ar} (a Gamma(2, 2a) variate) is accepted
/// with probability e^{−r²}. Either acceptance rate stays above 1/4.
fn sample_slope_tail(a: f64, rng: &mut dyn RandomSource) -> Option<f64> {
    if !(a >= 0.0 && a.is_finite()) {
        return None;
    }
    for _ in 0..1000 {
        let r = if a <= 0.7 {
            let r = (-(1.0 - rng.next_f64()).ln()).sqrt();
            if rng.next_f64() >= (-2.0 * a * r).exp() {
                continue;
            }
            r
        } else {
            let u = (1.0 - rng.next_f64()) * (1.0 - rng.next_f64());
            let r = -u.ln() / (2.0 * a);
            if rng.next_f64() >= (-r * r).exp() {
                continue;
            }
            r
        };
        return Some(a + r);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rng::Pcg32;
    use crate::math::spherical_direction;
    use crate::microfacet::{Beckmann, Ggx};
    use crate::validation::chi2::{chi2_test, Chi2Config};
    use crate::validation::SphereMap;
    use std::f64::consts::FRAC_PI_2;

    fn surfaces() -> Vec<Microsurface> {
        vec![
            Microsurface::new(
                Ndf::Ggx(Ggx::new(0.6, 0.25).unwrap()),
                HeightDistribution::Uniform,
            )
            .unwrap(),
            Microsurface::new(
                Ndf::Beckmann(Beckmann::new(0.3, 0.9).unwrap()),
                HeightDistribution::Gaussian,
            )
            .unwrap(),
        ]
    }

    #[test]
    fn projected_area_matches_the_signed_lambda_and_integrates_the_visible_normals() {
        for s in surfaces() {
            // (Farther below the horizon the visible normals crowd at the horizon and this
            // quadrature misses them; the chi-square test below covers those directions.)
            for theta in [0.3f64, 1.2, 1.5, FRAC_PI_2 - 1e-4, 1.65, 2.2] {
                let w = spherical_direction(theta, 0.7);
                let a = s.projected_area(w);
                // A(w) − A(−w) = w·n  (the projected-area identity, WMLT07 eq. 3).
                let diff = a - s.projected_area(-w);
                assert!((diff - w.z).abs() < 1e-9, "{theta}: {diff} vs {}", w.z);
                // ∫ D_w(m) dω_m = 1 by quadrature over the hemisphere of normals.
                let total = crate::math::quadrature::integrate_adaptive(
                    0.0,
                    0.5 * std::f64::consts::PI,
                    1e-12,
                    1e-7,
                    |tm: f64| {
                        crate::math::quadrature::integrate_adaptive(
                            0.0,
                            std::f64::consts::TAU,
                            1e-12,
                            1e-8,
                            |pm: f64| s.visible_density(w, spherical_direction(tm, pm)),
                        ) * tm.sin()
                    },
                );
                assert!((total - 1.0).abs() < 2e-4, "{theta}: ∫ D_w = {total}");
            }
        }
    }

    #[test]
    fn visible_normals_below_the_horizon_pass_chi_square() {
        let cfg = Chi2Config {
            samples: 200_000,
            ..Chi2Config::default()
        };
        for s in surfaces() {
            for theta in [FRAC_PI_2 - 3e-8, 1.9, 2.6, 3.0] {
                let w = spherical_direction(theta, 2.1);
                let out = chi2_test(
                    &SphereMap::standard(),
                    &cfg,
                    |r| s.sample_visible(w, r),
                    |m| s.visible_density(w, m),
                );
                assert!(out.passes(1e-3), "{:?} θ={theta}: {}", s.ndf, out.summary());
                assert!((out.pdf_integral - 1.0).abs() < 2e-3, "{}", out.summary());
            }
        }
    }

    #[test]
    fn visible_normals_near_grazing_pass_chi_square() {
        // The walk draws visible normals of grazing directions often (after each bounce).
        let cfg = Chi2Config {
            samples: 200_000,
            ..Chi2Config::default()
        };
        for s in surfaces() {
            for theta in [1.2f64, 1.4, 1.5, 1.56] {
                let w = spherical_direction(theta, 2.1);
                let out = chi2_test(
                    &SphereMap::standard(),
                    &cfg,
                    |r| s.sample_visible(w, r),
                    |m| s.visible_density(w, m),
                );
                println!("{:?} θ={theta}: {}", s.ndf, out.summary());
                assert!(out.passes(1e-3), "{:?} θ={theta}: {}", s.ndf, out.summary());
            }
        }
    }

    #[test]
    fn expected_next_escape_is_finite_for_a_grazing_upward_path() {
        // d barely above the horizon (Λ_d ≈ 6·10³ for GGX α = 0.8) toward the normal
        // (Λ_o = 0): E = 1 − c^{Λ_d} ≈ 1. The first closed form gave 0 · ∞ = NaN here.
        let s = Microsurface::new(
            Ndf::Ggx(Ggx::isotropic(0.8).unwrap()),
            HeightDistribution::Uniform,
        )
        .unwrap();
        let d = Vec3::new(-0.683, 0.730, 6.4e-5).normalize();
        let o = Vec3::new(0.0, 0.0, 1.0);
        for h in [-0.5, 0.0, 0.3] {
            let e = s.expected_next_escape(d, h, o);
            let c: f64 = s.heights().c1(h);
            let exact = 1.0 - c.powf(s.ndf().lambda(d));
            assert!((e - exact).abs() < 1e-12, "h = {h}: {e} vs {exact}");
        }
    }

    #[test]
    fn expected_next_escape_matches_sampled_free_paths() {
        // E[1{hit} G1(o, h′)] in closed form against the sampled next height, upward and
        // downward, both height distributions, Beckmann and GGX.
        for s in surfaces() {
            for hd in [HeightDistribution::Uniform, HeightDistribution::Gaussian] {
                let s = Microsurface::new(s.ndf.clone(), hd).unwrap();
                let o = spherical_direction(1.3, 0.2);
                for (k, (theta, h)) in
                    [(0.2, 0.3), (1.0, -0.5), (1.5, 0.9), (2.0, 0.1), (2.9, -0.2)]
                        .into_iter()
                        .enumerate()
                {
                    let d = spherical_direction(theta, 1.7);
                    let mut rng = Pcg32::new(17, k as u64);
                    let n = 400_000;
                    let mut sum = 0.0;
                    let mut sum2 = 0.0;
                    for _ in 0..n {
                        if let Some(h2) = s.next_height(d, h, rng.next_f64()) {
                            let g = s.escape_probability(o, h2);
                            sum += g;
                            sum2 += g * g;
                        }
                    }
                    let mean = sum / n as f64;
                    let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
                    let e = s.expected_next_escape(d, h, o);
                    println!("{:?} {hd:?} θ_d = {theta}: sampled {mean:.5} ± {se:.1e}, closed form {e:.5}", s.ndf);
                    assert!((mean - e).abs() < 4.0 * se + 1e-12, "{mean} vs {e}");
                }
            }
        }
    }

    #[test]
    fn the_evaluation_walk_direction_depends_on_the_pair_only() {
        let mut rng = Pcg32::new(5, 5);
        for s in surfaces() {
            for _ in 0..2000 {
                let a = crate::math::warp::square_to_uniform_sphere(rng.next_2d());
                let b = crate::math::warp::square_to_uniform_sphere(rng.next_2d());
                let b = Vec3::new(b.x, b.y, b.z.abs().copysign(a.z));
                assert_ne!(
                    s.walk_from_first(a, b),
                    s.walk_from_first(b, a),
                    "{a:?} {b:?}"
                );
                // From the more masked direction (the more grazing one when isotropic).
                let first = if s.walk_from_first(a, b) { a } else { b };
                let other = if s.walk_from_first(a, b) { b } else { a };
                assert!(s.ndf.lambda(first) >= s.ndf.lambda(other));
            }
            let a = spherical_direction(0.7, 0.3);
            assert!(s.walk_from_first(a, a));
        }
    }

    #[test]
    fn heights_invert_and_escape_matches_the_free_path_law() {
        for hd in [HeightDistribution::Uniform, HeightDistribution::Gaussian] {
            for c in [1e-6, 0.01, 0.3, 0.5, 0.9, 0.999] {
                let h = hd.inv_c1(c);
                assert!((hd.c1(h) - c).abs() < 1e-12, "{hd:?} {c}");
            }
        }
        // The fraction of upward rays that escape from height h is C1(h)^Λ.
        let s = &surfaces()[0];
        let w = spherical_direction(1.2, 0.4);
        let h = 0.2;
        let mut rng = Pcg32::new(3, 1);
        let n = 200_000;
        let escaped = (0..n)
            .filter(|_| s.next_height(w, h, rng.next_f64()).is_none())
            .count() as f64
            / n as f64;
        let g = s.escape_probability(w, h);
        assert!(
            (escaped - g).abs() < 4.0 * (g * (1.0 - g) / n as f64).sqrt(),
            "{escaped} vs {g}"
        );
    }
}
