//! Math helpers shared by every part of the library: vectors and the local shading frame,
//! the spectrum type, a bit-stable random number generator, special functions, quadrature
//! and sampling warps.
//!
//! Precision: the library computes in `f64` throughout. Rendering does not need it, but the
//! lab (tabulation, fitting, validation) does, and on x86-64 scalar `f64` arithmetic costs
//! the same as `f32`; one type keeps every code path identical between the renderer and
//! the checks that prove it.

pub mod adaptive_quadrature;
pub mod complex;
pub mod cosine_lobe;
pub mod nested_quadrature;
pub mod quadrature;
pub mod rng;
pub mod sin_cos;
pub mod special;
pub mod spectrum;
pub mod warp;

pub use glam::{DVec2 as Vec2, DVec3 as Vec3};

/// ⌊x⌋ as an index into `cells` cells, clamped to [0, cells − 1] (NaN → 0): a table
/// lookup's interval. Through `i64`, not `x.floor() as usize`: on baseline x86-64 (no
/// `roundsd`) `floor` is a library call and a float-to-`usize` cast a dozen instructions of
/// saturation, while a truncating `i64` conversion of x ≥ 0 is ⌊x⌋ in a few.
#[inline(always)]
pub fn cell_index(x: f64, cells: usize) -> usize {
    (x.max(0.0) as i64 as usize).min(cells - 1)
}

pub const PI: f64 = std::f64::consts::PI;
pub const INV_PI: f64 = std::f64::consts::FRAC_1_PI;
pub const TWO_PI: f64 = 2.0 * PI;
pub const SQRT_PI: f64 = 1.772_453_850_905_516;

/// cos θ of a direction in the local frame (z is the shading normal).
#[inline]
pub fn cos_theta(v: Vec3) -> f64 {
    v.z
}

/// sin² θ, clamped to [0, 1].
#[inline]
pub fn sin2_theta(v: Vec3) -> f64 {
    (1.0 - v.z * v.z).max(0.0)
}

/// tan² θ; infinite at the horizon.
#[inline]
pub fn tan2_theta(v: Vec3) -> f64 {
    sin2_theta(v) / (v.z * v.z)
}

/// Direction from spherical angles (radians), φ measured from the tangent x axis.
#[inline]
pub fn spherical_direction(theta: f64, phi: f64) -> Vec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vec3::new(st * cp, st * sp, ct)
}

/// Spherical angles (θ ∈ [0, π], φ ∈ [0, 2π)) of a unit direction.
#[inline]
pub fn spherical_angles(v: Vec3) -> (f64, f64) {
    let theta = v.z.clamp(-1.0, 1.0).acos();
    let mut phi = v.y.atan2(v.x);
    if phi < 0.0 {
        phi += TWO_PI;
    }
    (theta, phi)
}

/// Mirror reflection of `v` about the unit normal `n`: 2 (v·n) n − v  [WMLT07 eq. 39].
#[inline]
pub fn reflect(v: Vec3, n: Vec3) -> Vec3 {
    2.0 * v.dot(n) * n - v
}

/// Refraction of `v` (pointing away from the surface, on the side `n` points to) through
/// the microsurface normal `n` with relative index `eta = η_v / η_t`  [WMLT07 eq. 40].
/// Returns `None` on total internal reflection.
#[inline]
pub fn refract(v: Vec3, n: Vec3, eta: f64) -> Option<Vec3> {
    let c = v.dot(n);
    let sign = if c >= 0.0 { 1.0 } else { -1.0 };
    let k = 1.0 + eta * eta * (c * c - 1.0);
    if k < 0.0 {
        return None;
    }
    Some((eta * c - sign * k.sqrt()) * n - eta * v)
}

/// An orthonormal frame (s, t, n); converts between world and local coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub s: Vec3,
    pub t: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// Frame around a unit normal, tangents chosen by Duff et al.'s branchless construction
    /// (one source with the lanes' [`LFrame::from_normal`](crate::lanes::LFrame)).
    pub fn from_normal(n: Vec3) -> Self {
        crate::lanes::LFrame::<f64>::from_normal(n.into()).into()
    }

    /// Frame with a given normal and a preferred tangent direction (Gram–Schmidt), Duff's
    /// where the tangent is (nearly) parallel to the normal.
    pub fn from_normal_tangent(n: Vec3, tangent: Vec3) -> Self {
        crate::lanes::LFrame::<f64>::from_normal_tangent(n.into(), tangent.into()).into()
    }

    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

impl From<crate::lanes::LFrame<f64>> for Frame {
    #[inline(always)]
    fn from(f: crate::lanes::LFrame<f64>) -> Self {
        Frame {
            s: f.s.into(),
            t: f.t.into(),
            n: f.n.into(),
        }
    }
}

/// Compact number formatting for descriptions: up to 6 significant digits, no trailing
/// zeros (`0.3`, `198`, `1.5e-5`).
pub fn fmt_num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let a = x.abs();
    if !(1e-4..1e6).contains(&a) {
        return format!("{x:.5e}");
    }
    let digits = (5 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Finite-and-normalized check used by debug assertions and the NaN sweeps.
#[inline]
pub fn is_unit(v: Vec3) -> bool {
    v.is_finite() && (v.length_squared() - 1.0).abs() < 1e-6
}

/// Mirror image through the tangent plane.
#[inline]
pub fn flip(v: Vec3) -> Vec3 {
    Vec3::new(v.x, v.y, -v.z)
}

/// A pair of directions seen from the upper hemisphere: unchanged when `wo` is above the
/// surface, both mirrored through the tangent plane when it is below; `None` when the two
/// are on opposite sides (or in the tangent plane). The geometry of
/// [`TwoSided`](crate::two_sided::TwoSided).
#[inline]
pub fn to_upper_pair(wo: Vec3, wi: Vec3) -> Option<(Vec3, Vec3)> {
    if wo.z * wi.z <= 0.0 {
        return None;
    }
    if wo.z > 0.0 {
        Some((wo, wi))
    } else {
        Some((flip(wo), flip(wi)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_index_is_the_clamped_floor() {
        for x in [
            -3.5,
            -0.0,
            0.0,
            0.3,
            1.0,
            2.999,
            3.0,
            7.5,
            1e30,
            f64::INFINITY,
        ] {
            let expect = (x.floor().max(0.0) as usize).min(4);
            assert_eq!(cell_index(x, 5), expect, "{x}");
        }
        assert_eq!(cell_index(f64::NAN, 5), 0);
        assert_eq!(cell_index(f64::NEG_INFINITY, 5), 0);
    }

    #[test]
    fn frame_is_orthonormal_for_all_normals() {
        for &n in &[
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.3, -0.4, 0.866).normalize(),
            Vec3::new(-1e-9, 0.0, -1.0).normalize(),
        ] {
            let f = Frame::from_normal(n);
            assert!((f.s.dot(f.t)).abs() < 1e-12);
            assert!((f.s.dot(f.n)).abs() < 1e-12);
            assert!((f.s.length() - 1.0).abs() < 1e-12);
            let v = Vec3::new(0.2, 0.5, -0.7).normalize();
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-12);
        }
    }

    #[test]
    fn refraction_obeys_snell_and_reflection_is_involutive() {
        let wo = spherical_direction(0.6, 1.0);
        let wt = refract(wo, Vec3::Z, 1.0 / 1.5).unwrap();
        let s_o = sin2_theta(wo).sqrt();
        let s_t = sin2_theta(wt).sqrt();
        assert!((s_o - 1.5 * s_t).abs() < 1e-12);
        assert!(wt.z < 0.0);
        let back = refract(wt, Vec3::Z, 1.5).unwrap();
        assert!((back - wo).length() < 1e-12);
        let r = reflect(wo, Vec3::Z);
        assert!((reflect(r, Vec3::Z) - wo).length() < 1e-12);
    }

    #[test]
    fn total_internal_reflection_is_reported() {
        // Inside glass (η = 1.5) at 60°, beyond the critical angle of 41.8°.
        let v = spherical_direction(60f64.to_radians(), 0.3);
        assert!(refract(v, Vec3::Z, 1.5).is_none());
    }

    #[test]
    fn numbers_format_compactly() {
        assert_eq!(fmt_num(197.99999999999997), "198");
        assert_eq!(fmt_num(0.3), "0.3");
        assert_eq!(fmt_num(1.5), "1.5");
        assert_eq!(fmt_num(19998.0), "19998");
    }

    #[test]
    fn spherical_roundtrip() {
        let (t, p) = spherical_angles(spherical_direction(1.1, 4.0));
        assert!((t - 1.1).abs() < 1e-12 && (p - 4.0).abs() < 1e-12);
    }
}
