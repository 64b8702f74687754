//! The Beckmann distribution, anisotropic  [WMLT07 eqs. 25–29; IL18 eqs. 16, 20, 29–30].
//!
//! | parameter | meaning | range |
//! |---|---|---|
//! | `alpha_x`, `alpha_y` | RMS slope along the tangent x / bitangent y axis (unitless) | (0, 10] |
//! | G1 form | exact erf-based Λ (default) or WMLT07's rational G1 (eq. 27) | — |
//!
//! IL18 eq. 16 calls the widths σ_x, σ_y; they are WMLT07's α_b (ERRATA 6).

use super::{normal_from_slopes, visible_density, Distribution};
use crate::error::{check_range, Bounds, ParamResult};
use crate::math::special::{erf, erfc, erfinv};
use crate::math::{fmt_num, Vec2, Vec3, PI, SQRT_PI, TWO_PI};

/// How G1 is evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BeckmannG1 {
    /// Λ = (erf(a) − 1)/2 + e^{−a²}/(2a√π)  [IL18 eq. 20; WMLT07 eq. 26].
    Exact,
    /// WMLT07's rational approximation of G1 (eq. 27), claimed relative error < 0.35 %.
    Rational,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Beckmann {
    ax: f64,
    ay: f64,
    g1_form: BeckmannG1,
}

impl Beckmann {
    /// Anisotropic Beckmann; both widths in (0, 10].
    pub fn new(alpha_x: f64, alpha_y: f64) -> ParamResult<Self> {
        check_range("alpha_u", alpha_x, 0.0, 10.0, Bounds::OpenClosed)?;
        check_range("alpha_v", alpha_y, 0.0, 10.0, Bounds::OpenClosed)?;
        Ok(Beckmann {
            ax: alpha_x,
            ay: alpha_y,
            g1_form: BeckmannG1::Exact,
        })
    }

    pub fn isotropic(alpha: f64) -> ParamResult<Self> {
        check_range("alpha", alpha, 0.0, 10.0, Bounds::OpenClosed)?;
        Self::new(alpha, alpha)
    }

    pub fn with_g1(mut self, form: BeckmannG1) -> Self {
        self.g1_form = form;
        self
    }

    pub fn alpha_x(&self) -> f64 {
        self.ax
    }

    pub fn alpha_y(&self) -> f64 {
        self.ay
    }

    pub fn g1_form(&self) -> BeckmannG1 {
        self.g1_form
    }

    /// Same distribution with both widths scaled by `s > 0` (WMLT07 §5.3's α†).
    pub fn scaled(&self, s: f64) -> Self {
        Beckmann {
            ax: self.ax * s,
            ay: self.ay * s,
            g1_form: self.g1_form,
        }
    }

    /// a = 1 / (α_v tan θ_v) with α_v² = α_x² cos² φ_v + α_y² sin² φ_v  [IL18 eq. 20].
    #[inline]
    fn a_of(&self, v: Vec3) -> f64 {
        let s2 = self.ax * self.ax * v.x * v.x + self.ay * self.ay * v.y * v.y;
        if s2 <= 0.0 {
            return f64::INFINITY;
        }
        v.z.abs() / s2.sqrt()
    }

    /// Exact Smith Λ: −erfc(a)/2 + e^{−a²}/(2a√π), written with erfc so that it keeps
    /// its relative precision when Λ is small  [IL18 eq. 20].
    #[inline]
    pub fn lambda_exact(&self, v: Vec3) -> f64 {
        lambda_of_a(self.a_of(v))
    }

    /// WMLT07 eq. 27: G1 ≈ (3.535a + 2.181a²)/(1 + 2.276a + 2.577a²) for a < 1.6, else 1.
    /// As printed the rational overshoots 1 slightly just below a = 1.6 (by up to 6e-5);
    /// it is clamped so that G1 ≤ 1 (WMLT07 eq. 5).
    #[inline]
    pub fn g1_rational_of_a(a: f64) -> f64 {
        if a >= 1.6 {
            1.0
        } else {
            ((3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a)).min(1.0)
        }
    }

    /// Λ implied by the rational G1 (Λ = 1/G1 − 1).
    #[inline]
    pub fn lambda_rational(&self, v: Vec3) -> f64 {
        let g = Self::g1_rational_of_a(self.a_of(v));
        if g <= 0.0 {
            f64::INFINITY
        } else {
            1.0 / g - 1.0
        }
    }
}

/// Beckmann Λ as a function of a  [IL18 eq. 20].
#[inline]
pub fn lambda_of_a(a: f64) -> f64 {
    if a == f64::INFINITY || a > 26.0 {
        return 0.0;
    }
    if a <= 0.0 {
        return f64::INFINITY;
    }
    let l = (-a * a).exp() / (2.0 * a * SQRT_PI) - 0.5 * erfc(a);
    l.max(0.0)
}

/// Exact Beckmann G1 as a function of a: 2 / (1 + erf(a) + e^{−a²}/(a√π))  [WMLT07 eq. 26].
#[inline]
pub fn g1_exact_of_a(a: f64) -> f64 {
    1.0 / (1.0 + lambda_of_a(a))
}

/// Samples the slopes (x̃, ỹ) of visible normals of the unit-width isotropic Beckmann
/// distribution seen at cos θ = `cos_theta` (Heitz & d'Eon 2014): x̃ by inverting the
/// conditional CDF C(x̃) ∝ cot θ (1 + erf x̃) + e^{−x̃²}/√π with a safeguarded Newton
/// iteration in the erf domain, ỹ from the Gaussian.
fn sample_visible_slopes_unit(cos_theta: f64, u: Vec2) -> (f64, f64) {
    let ux = u.x.clamp(1e-12, 1.0 - 1e-12);
    let uy = u.y.clamp(1e-12, 1.0 - 1e-12);
    if cos_theta > 0.999_999 {
        // Normal incidence: visible normals are distributed like D(m)|m·n|.
        let r = (-(1.0 - ux).ln()).sqrt();
        let (s, c) = (TWO_PI * uy).sin_cos();
        return (r * c, r * s);
    }
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let tan_theta = sin_theta / cos_theta;
    let cot_theta = cos_theta / sin_theta;
    // Everything is parameterized by b = erf(x̃) ∈ (−1, erf(cot θ)].
    let mut lo = -1.0;
    let mut hi = erf(cot_theta);
    let norm = 1.0 / (1.0 + hi + tan_theta * (-cot_theta * cot_theta).exp() / SQRT_PI);
    // Initial guess from Jakob's fitted approximation of the inverse CDF (Mitsuba, 2014).
    let theta = cos_theta.acos();
    let fit = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
    let mut b = hi - (1.0 + hi) * (1.0 - ux).powf(fit);
    for _ in 0..40 {
        if !(b > lo && b < hi) {
            b = 0.5 * (lo + hi);
        }
        let x = erfinv(b);
        let value = norm * (1.0 + b + tan_theta * (-x * x).exp() / SQRT_PI) - ux;
        if value.abs() < 1e-12 {
            break;
        }
        if value > 0.0 {
            hi = b;
        } else {
            lo = b;
        }
        let deriv = norm * (1.0 - x * tan_theta);
        let next = b - value / deriv;
        if hi - lo < 1e-15 {
            break;
        }
        b = next;
    }
    let sx = erfinv(b.clamp(-1.0 + 1e-16, 1.0 - 1e-16));
    let sy = erfinv(2.0 * uy - 1.0);
    (sx, sy)
}

impl Distribution for Beckmann {
    /// D(m) = exp(−(x²/α_x² + y²/α_y²)/z²) / (π α_x α_y z⁴)  [IL18 eq. 16; WMLT07 eq. 25].
    #[inline]
    fn d(&self, m: Vec3) -> f64 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let z2 = m.z * m.z;
        let cos4 = z2 * z2;
        if cos4 < 1e-300 {
            return 0.0;
        }
        let e = (m.x * m.x / (self.ax * self.ax) + m.y * m.y / (self.ay * self.ay)) / z2;
        (-e).exp() / (PI * self.ax * self.ay * cos4)
    }

    #[inline]
    fn lambda(&self, v: Vec3) -> f64 {
        match self.g1_form {
            BeckmannG1::Exact => self.lambda_exact(v),
            BeckmannG1::Rational => self.lambda_rational(v),
        }
    }

    #[inline]
    fn g1(&self, v: Vec3, m: Vec3) -> f64 {
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        match self.g1_form {
            BeckmannG1::Exact => 1.0 / (1.0 + self.lambda_exact(v)),
            BeckmannG1::Rational => Self::g1_rational_of_a(self.a_of(v)),
        }
    }

    /// Samples D(m)|m·n|: slopes r(cos 2πξ2, sin 2πξ2) with r = √(−ln(1−ξ1)), stretched by
    /// (α_x, α_y). This is IL18 eqs. 29–30 (and WMLT07 eqs. 28–29 when isotropic) written
    /// in slope space, which avoids the quadrant bookkeeping of the arctan in eq. 29.
    #[inline]
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        let r = (-(1.0 - u.x).ln()).sqrt();
        let (s, c) = (TWO_PI * u.y).sin_cos();
        normal_from_slopes(r * c * self.ax, r * s * self.ay)
    }

    /// p(m) = D(m) |m·n|  [WMLT07 eq. 24].
    #[inline]
    fn pdf_normal(&self, m: Vec3) -> f64 {
        self.d(m) * m.z.max(0.0)
    }

    fn has_visible_sampling(&self) -> bool {
        true
    }

    /// Visible normals: stretch the view to unit roughness, sample slopes, rotate and
    /// unstretch (Heitz & d'Eon 2014).
    fn sample_visible(&self, v: Vec3, u: Vec2) -> Vec3 {
        let vs = Vec3::new(self.ax * v.x, self.ay * v.y, v.z.max(1e-12)).normalize();
        let (sx, sy) = sample_visible_slopes_unit(vs.z, u);
        let r = (vs.x * vs.x + vs.y * vs.y).sqrt();
        let (cp, sp) = if r > 1e-14 {
            (vs.x / r, vs.y / r)
        } else {
            (1.0, 0.0)
        };
        let rx = cp * sx - sp * sy;
        let ry = sp * sx + cp * sy;
        normal_from_slopes(rx * self.ax, ry * self.ay)
    }

    /// D_v(m) with the exact Λ, whatever G1 form the model evaluates.
    #[inline]
    fn pdf_visible(&self, v: Vec3, m: Vec3) -> f64 {
        visible_density(self.lambda_exact(v), v, m, self.d(m))
    }

    fn typical_width(&self) -> f64 {
        (self.ax * self.ay).sqrt()
    }

    fn describe(&self) -> String {
        let g = match self.g1_form {
            BeckmannG1::Exact => "",
            BeckmannG1::Rational => ", rational G1",
        };
        if self.ax == self.ay {
            format!("beckmann(alpha={}{g})", fmt_num(self.ax))
        } else {
            format!(
                "beckmann(alpha_u={}, alpha_v={}{g})",
                fmt_num(self.ax),
                fmt_num(self.ay)
            )
        }
    }
}
