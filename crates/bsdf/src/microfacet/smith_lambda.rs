//! Smith Λ computed numerically from the distribution itself, for distributions without a
//! closed form and to verify the closed forms.
//!
//! IL18 eq. 19 gives G1(u) = (u·n) / ∫ D(m) max(0, u·m) dω_m, i.e.
//! Λ(u) = ∫ D(m) max(0, u·m) dω_m / (u·n) − 1. Because every normalized D satisfies the
//! projected-area identity ∫ D(m) (u·m) dω_m = u·n  [WMLT07 eq. 3], the same Λ is
//! Λ(u) = ∫ D(m) max(0, −u·m) dω_m / (u·n) — the projected area of the back-facing
//! microfacets — which keeps full relative precision where Λ is tiny (the difference form
//! loses it to cancellation). Both forms are provided; tests check that they agree.

use super::Distribution;
use crate::math::quadrature::integrate_adaptive;
use crate::math::{spherical_direction, Vec3, PI};

/// ∫_0^{2π} max(0, a cos φ + b) dφ for a ≥ 0 (a = sin θ_u sin θ_m, b = cos θ_u cos θ_m).
#[inline]
fn clamped_cosine_azimuth_integral(a: f64, b: f64) -> f64 {
    if b >= a {
        return 2.0 * PI * b;
    }
    if b <= -a {
        return 0.0;
    }
    let phi1 = (-b / a).acos();
    2.0 * (b * phi1 + a * (1.0 - (b / a) * (b / a)).max(0.0).sqrt())
}

/// Breakpoints 0, w, 2w, 4w, … up to π/2 so adaptive quadrature resolves narrow peaks.
fn theta_breakpoints(width: f64) -> Vec<f64> {
    let mut pts = vec![0.0];
    let mut w = (0.25 * width).max(1e-5);
    while w < 0.5 * PI {
        pts.push(w);
        w *= 2.0;
    }
    pts.push(0.5 * PI);
    pts
}

/// Isotropic D given as a function of θ_m: Λ(θ_u) by the back-facing form (1-D integral,
/// the azimuth integrated in closed form).
pub fn lambda_isotropic(d_of_theta: impl Fn(f64) -> f64, theta_u: f64) -> f64 {
    lambda_isotropic_cut(d_of_theta, theta_u, 0.0)
}

/// [`lambda_isotropic`] with the θ_m integral stopped `cutoff` radians short of the horizon
/// (used to exhibit the divergence of the Gaussian's Λ).
pub fn lambda_isotropic_cut(d_of_theta: impl Fn(f64) -> f64, theta_u: f64, cutoff: f64) -> f64 {
    if theta_u <= 0.0 {
        return 0.0;
    }
    if theta_u >= 0.5 * PI {
        return f64::INFINITY;
    }
    let (su, cu) = theta_u.sin_cos();
    // max(0, −u·m) over φ: the same closed form with b → −b.
    let f = |tm: f64| {
        let (sm, cm) = tm.sin_cos();
        d_of_theta(tm) * sm * clamped_cosine_azimuth_integral(su * sm, -cu * cm)
    };
    let lo = 0.5 * PI - theta_u;
    let hi = 0.5 * PI - cutoff;
    if hi <= lo {
        return 0.0;
    }
    integrate_adaptive(lo, hi, 1e-300, 1e-11, f) / cu
}

/// Isotropic D: the direct form of IL18 eq. 19, ∫ D max(0, u·m) dω / (u·n) − 1.
pub fn lambda_isotropic_direct(d_of_theta: impl Fn(f64) -> f64, theta_u: f64, width: f64) -> f64 {
    let (su, cu) = theta_u.sin_cos();
    let f = |tm: f64| {
        let (sm, cm) = tm.sin_cos();
        d_of_theta(tm) * sm * clamped_cosine_azimuth_integral(su * sm, cu * cm)
    };
    let pts = theta_breakpoints(width);
    let total: f64 = pts
        .windows(2)
        .map(|w| integrate_adaptive(w[0], w[1], 1e-300, 1e-12, f))
        .sum();
    total / cu - 1.0
}

/// Any (possibly anisotropic) distribution: Λ(u) by the back-facing form, as a 2-D
/// integral. For each azimuth with cos(φ_m − φ_u) < 0 the back-facing normals are those with
/// tan θ_m > cot θ_u / |cos(φ_m − φ_u)|.
pub fn lambda_numeric(dist: &impl Distribution, u: Vec3) -> f64 {
    let u = u.normalize();
    let cu = u.z.abs();
    if cu >= 1.0 {
        return 0.0;
    }
    if cu <= 0.0 {
        return f64::INFINITY;
    }
    let u = Vec3::new(u.x, u.y, cu);
    let su = (1.0 - cu * cu).sqrt();
    let phi_u = u.y.atan2(u.x);
    let inner = |phi: f64| {
        let cd = (phi - phi_u).cos();
        if cd >= 0.0 {
            return 0.0;
        }
        let t0 = (cu / (su * -cd)).atan();
        integrate_adaptive(t0, 0.5 * PI, 1e-300, 1e-10, |tm: f64| {
            let m = spherical_direction(tm, phi);
            let back = -u.dot(m);
            if back <= 0.0 {
                0.0
            } else {
                dist.d(m) * back * tm.sin()
            }
        })
    };
    let lo = phi_u + 0.5 * PI;
    integrate_adaptive(lo, lo + PI, 1e-300, 1e-9, inner) / cu
}

/// ∫ D(m) (v·m) dω_m over the upper hemisphere of normals (WMLT07 eq. 3; eq. 4 for v = n),
/// by nested adaptive quadrature with breakpoints sized to the distribution's width.
pub fn projected_area(dist: &impl Distribution, v: Vec3) -> f64 {
    let pts = theta_breakpoints(dist.typical_width());
    let f = |tm: f64| {
        let st = tm.sin();
        integrate_adaptive(0.0, 2.0 * PI, 1e-300, 1e-11, |phi: f64| {
            let m = spherical_direction(tm, phi);
            dist.d(m) * v.dot(m)
        }) * st
    };
    pts.windows(2)
        .map(|w| integrate_adaptive(w[0], w[1], 1e-300, 1e-11, f))
        .sum()
}

/// Isotropic version of [`projected_area`] with the azimuth in closed form:
/// ∫ D(θ_m) (v·m) dω = 2π cos θ_v ∫ D(θ_m) cos θ_m sin θ_m dθ_m.
pub fn projected_area_isotropic(d_of_theta: impl Fn(f64) -> f64, theta_v: f64, width: f64) -> f64 {
    let pts = theta_breakpoints(width);
    let f = |tm: f64| d_of_theta(tm) * tm.cos() * tm.sin();
    2.0 * PI
        * theta_v.cos()
        * pts
            .windows(2)
            .map(|w| integrate_adaptive(w[0], w[1], 1e-300, 1e-12, f))
            .sum::<f64>()
}

/// A tabulated isotropic Smith G1 = 1/(1 + Λ), built once per material from the numerical
/// Λ and interpolated with Catmull–Rom cubics. G1 is stored rather than Λ because it is
/// bounded and smooth up to the horizon, where Λ diverges. The grid is uniform in
/// y = a/(1 + a) ∈ [0, 1], a = cot θ / w, with w the distribution's slope width: half the
/// entries fall in the transition a < 1 whatever the roughness, and y = 1 (θ = 0) and
/// y = 0 (grazing) are both on the grid.
#[derive(Clone, Debug)]
pub struct LambdaTable {
    g1: Vec<f64>,
    width: f64,
}

impl LambdaTable {
    /// Number of intervals of the grid.
    pub const INTERVALS: usize = 1024;

    /// Tabulates Λ of an isotropic D given as a function of θ_m; `width` is its slope scale.
    pub fn build(d_of_theta: impl Fn(f64) -> f64 + Sync, width: f64) -> Self {
        use rayon::prelude::*;
        let n = Self::INTERVALS;
        let g1: Vec<f64> = (0..=n)
            .into_par_iter()
            .map(|k| {
                let y = k as f64 / n as f64;
                if k == 0 {
                    return 0.0;
                }
                if k == n {
                    return 1.0;
                }
                // y = c/(w s + c)  ⇒  tan θ = (1 − y)/(w y)... solved for θ.
                let theta = ((1.0 - y) / (width * y)).atan();
                1.0 / (1.0 + lambda_isotropic(&d_of_theta, theta))
            })
            .collect();
        LambdaTable { g1, width }
    }

    /// Interpolated G1 for a direction with |cos θ| = `cos_theta`.
    pub fn g1_of_cos(&self, cos_theta: f64) -> f64 {
        let c = cos_theta.abs().min(1.0);
        let s = (1.0 - c * c).max(0.0).sqrt();
        let y = c / (self.width * s + c).max(1e-300);
        let n = self.g1.len() - 1;
        let x = (y * n as f64).clamp(0.0, n as f64);
        let i = crate::math::cell_index(x, n);
        let t = x - i as f64;
        let p1 = self.g1[i];
        let p2 = self.g1[i + 1];
        let p0 = if i > 0 { self.g1[i - 1] } else { 2.0 * p1 - p2 };
        let p3 = if i + 2 <= n {
            self.g1[i + 2]
        } else {
            2.0 * p2 - p1
        };
        let t2 = t * t;
        let t3 = t2 * t;
        let v = 0.5
            * (2.0 * p1
                + (-p0 + p2) * t
                + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
                + (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * t3);
        v.clamp(0.0, 1.0)
    }

    /// Λ = 1/G1 − 1.
    pub fn lambda_of_cos(&self, cos_theta: f64) -> f64 {
        let g = self.g1_of_cos(cos_theta);
        if g <= 0.0 {
            f64::INFINITY
        } else {
            1.0 / g - 1.0
        }
    }

    /// Table size in bytes.
    pub fn size_bytes(&self) -> usize {
        self.g1.len() * std::mem::size_of::<f64>()
    }
}
