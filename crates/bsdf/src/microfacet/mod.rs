//! The microfacet core: normal distributions D, their Smith Λ and G1, samplers with their
//! densities, masking-shadowing choices, and the shared specular microfacet lobe.
//!
//! Conventions (shared with every model): directions are unit vectors in the local shading
//! frame, z = macrosurface normal n, pointing away from the surface. A distribution's
//! normals m lie in the upper hemisphere (D(m) = 0 when m·n ≤ 0) and D is normalized by
//! projected area, ∫ D(m) (m·n) dω_m = 1  [WMLT07 eq. 4].

pub mod beckmann;
pub mod gaussian;
pub mod ggx;
pub mod half_vector_density;
pub mod integral;
pub mod masking;
pub mod phong;
pub mod smith_lambda;
pub mod specular_lobe;

pub use beckmann::{Beckmann, BeckmannG1};
pub use gaussian::Gaussian;
pub use ggx::Ggx;
pub use masking::Masking;
pub use phong::{Phong, PhongG1};

use crate::lanes::{LVec3, Mask, Real};
use crate::math::{Vec2, Vec3};

/// Roughness below which a model treats its surface as perfectly smooth (delta lobes).
pub const SMOOTH_ALPHA: f64 = 1e-4;

/// A microfacet normal distribution with its Smith masking and samplers.
///
/// `sample_normal`/`pdf_normal` are the papers' scheme (D(m)|m·n| for Beckmann, GGX and
/// Phong; the GGX proposal of TSBRM eqs. 35–38 for the Gaussian). `sample_visible`/
/// `pdf_visible` sample the distribution of visible normals D_v(m) = G1(v,m) max(0, v·m)
/// D(m) / (v·n) (Heitz 2018) where the distribution supports it; elsewhere they fall back to
/// `sample_normal`/`pdf_normal`, so a caller can always ask for them.
pub trait Distribution: Send + Sync {
    /// D(m), in 1/sr.
    fn d(&self, m: Vec3) -> f64;

    /// Smith Λ(v) for a direction on either side (only |cos θ_v| matters)  [WMLT07 eq. 48].
    fn lambda(&self, v: Vec3) -> f64;

    /// Smith monodirectional shadowing G1(v, m) = χ⁺((v·m)/(v·n)) / (1 + Λ(v))  [WMLT07 eq. 51].
    #[inline]
    fn g1(&self, v: Vec3, m: Vec3) -> f64 {
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        1.0 / (1.0 + self.lambda(v))
    }

    /// Draws a microfacet normal with density [`Distribution::pdf_normal`].
    fn sample_normal(&self, u: Vec2) -> Vec3;

    /// Density (solid angle of m) of `sample_normal`.
    fn pdf_normal(&self, m: Vec3) -> f64;

    /// True when `sample_visible` samples visible normals exactly.
    fn has_visible_sampling(&self) -> bool {
        false
    }

    /// Draws a normal visible from `v` (v·n > 0), with density `pdf_visible(v, ·)`.
    fn sample_visible(&self, _v: Vec3, u: Vec2) -> Vec3 {
        self.sample_normal(u)
    }

    /// Density of `sample_visible` for the view direction `v`.
    fn pdf_visible(&self, _v: Vec3, m: Vec3) -> f64 {
        self.pdf_normal(m)
    }

    /// The same density as `sample_visible`, through a map from u that is smooth over the
    /// whole unit square: for fixed-rule quadratures over u (the albedo tables' fixed
    /// entries), where the sampler's own map may be faster but singular somewhere (GGX's
    /// spherical caps at c = −v).
    fn sample_visible_smooth(&self, v: Vec3, u: Vec2) -> Vec3 {
        self.sample_visible(v, u)
    }

    /// A representative slope-space width (α, or √2 σ for the Gaussian), used to size
    /// numerical integration and validation bins.
    fn typical_width(&self) -> f64;

    /// Short human-readable description (`beckmann(0.3 x 0.3)`).
    fn describe(&self) -> String;
}

/// Visible-normal density D_v(m) = G1(v, m) max(0, v·m) D(m) / (v·n) for a given Λ(v).
#[inline]
pub(crate) fn visible_density(lambda_v: f64, v: Vec3, m: Vec3, d: f64) -> f64 {
    let vm = v.dot(m);
    if vm <= 0.0 || v.z <= 0.0 || d == 0.0 {
        return 0.0;
    }
    vm * d / ((1.0 + lambda_v) * v.z)
}

/// Microfacet normal from slopes (x̃, ỹ): m ∝ (−x̃, −ỹ, 1).
#[inline]
pub(crate) fn normal_from_slopes(sx: f64, sy: f64) -> Vec3 {
    normal_from_slopes_lanes(sx, sy).into()
}

/// `g1`, an unsided G1 of v, where v sees the front of m, else 0 (WMLT07 eq. 7's χ⁺): the
/// sidedness of every lane G1.
#[inline(always)]
pub(crate) fn sided_g1_lanes<R: Real>(v: LVec3<R>, m: LVec3<R>, g1: R) -> R {
    R::select((v.dot(m) * v.z).le(R::zero()), R::zero(), g1)
}

/// [`normal_from_slopes`] over lanes.
#[inline(always)]
pub(crate) fn normal_from_slopes_lanes<R: Real>(sx: R, sy: R) -> LVec3<R> {
    let q = R::one() + sx * sx + sy * sy;
    let inv = R::one() / q.sqrt();
    let m = LVec3::new(-sx * inv, -sy * inv, inv);
    // 1/√q is 0 or not finite exactly where q is +∞ or NaN (q ≥ 1 otherwise): one compare,
    // which vectorizes where `is_finite` on the result would not.
    let flat = !q.lt(R::splat(f64::INFINITY));
    if flat.none() {
        return m;
    }
    // Slopes so large the normal is numerically in the plane: keep it just above it.
    let l = (sx * sx + sy * sy).sqrt();
    let edge = LVec3::new(-sx / l, -sy / l, R::splat(R::TINY)).normalize();
    LVec3::select(flat, edge, m)
}

/// Any distribution of the core, dispatched statically (models hold this by value).
#[derive(Clone, Debug)]
pub enum Ndf {
    Beckmann(Beckmann),
    Ggx(Ggx),
    Gaussian(Gaussian),
    Phong(Phong),
}

macro_rules! dispatch {
    ($self:ident, $d:ident => $e:expr) => {
        match $self {
            Ndf::Beckmann($d) => $e,
            Ndf::Ggx($d) => $e,
            Ndf::Gaussian($d) => $e,
            Ndf::Phong($d) => $e,
        }
    };
}

impl Ndf {
    /// The distribution's name as used in material files.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Ndf::Beckmann(_) => "beckmann",
            Ndf::Ggx(_) => "ggx",
            Ndf::Gaussian(_) => "gaussian",
            Ndf::Phong(_) => "phong",
        }
    }

    /// The same distribution with every width multiplied by `s` (Beckmann and GGX only;
    /// used by WMLT07's widened sampling α† and by the validation of scaled variants).
    pub fn scaled(&self, s: f64) -> Option<Ndf> {
        match self {
            Ndf::Beckmann(b) => Some(Ndf::Beckmann(b.scaled(s))),
            Ndf::Ggx(g) => Some(Ndf::Ggx(g.scaled(s))),
            _ => None,
        }
    }

    /// True for distributions with a closed-form Smith Λ usable with Smith masking.
    pub fn supports_smith(&self) -> bool {
        !matches!(self, Ndf::Gaussian(_))
    }

    /// True when α_x ≠ α_y.
    pub fn is_anisotropic(&self) -> bool {
        match self {
            Ndf::Beckmann(b) => b.alpha_x() != b.alpha_y(),
            Ndf::Ggx(g) => g.alpha_x() != g.alpha_y(),
            _ => false,
        }
    }
}

impl Distribution for Ndf {
    #[inline]
    fn d(&self, m: Vec3) -> f64 {
        dispatch!(self, d => d.d(m))
    }
    #[inline]
    fn lambda(&self, v: Vec3) -> f64 {
        dispatch!(self, d => d.lambda(v))
    }
    #[inline]
    fn g1(&self, v: Vec3, m: Vec3) -> f64 {
        dispatch!(self, d => d.g1(v, m))
    }
    #[inline]
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        dispatch!(self, d => d.sample_normal(u))
    }
    #[inline]
    fn pdf_normal(&self, m: Vec3) -> f64 {
        dispatch!(self, d => d.pdf_normal(m))
    }
    #[inline]
    fn has_visible_sampling(&self) -> bool {
        dispatch!(self, d => d.has_visible_sampling())
    }
    #[inline]
    fn sample_visible(&self, v: Vec3, u: Vec2) -> Vec3 {
        dispatch!(self, d => d.sample_visible(v, u))
    }
    #[inline]
    fn pdf_visible(&self, v: Vec3, m: Vec3) -> f64 {
        dispatch!(self, d => d.pdf_visible(v, m))
    }
    fn sample_visible_smooth(&self, v: Vec3, u: Vec2) -> Vec3 {
        dispatch!(self, d => d.sample_visible_smooth(v, u))
    }
    fn typical_width(&self) -> f64 {
        dispatch!(self, d => d.typical_width())
    }
    fn describe(&self) -> String {
        dispatch!(self, d => d.describe())
    }
}
