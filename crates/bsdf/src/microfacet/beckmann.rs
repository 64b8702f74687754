//! The Beckmann distribution, anisotropic  [WMLT07 eqs. 25–29; IL18 eqs. 16, 20, 29–30].
//!
//! | parameter | meaning | range |
//! |---|---|---|
//! | `alpha_x`, `alpha_y` | RMS slope along the tangent x / bitangent y axis (unitless) | (0, 10] |
//! | G1 form | exact erf-based Λ (default) or WMLT07's rational G1 (eq. 27) | — |
//!
//! IL18 eq. 16 calls the widths σ_x, σ_y; they are WMLT07's α_b (ERRATA 6).

use super::{normal_from_slopes, Distribution};
use crate::checks::check_alpha;
use crate::error::ParamResult;
use crate::math::special::{erf, erfc, erfinv, erfinv_approx};
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
    // Precomputed so that D costs one division and one exponential.
    ax2: f64,
    ay2: f64,
    inv_ax2: f64,
    inv_ay2: f64,
    norm: f64,
}

impl Beckmann {
    /// Anisotropic Beckmann; both widths in (0, 10].
    pub fn new(alpha_x: f64, alpha_y: f64) -> ParamResult<Self> {
        check_alpha("alpha_u", alpha_x)?;
        check_alpha("alpha_v", alpha_y)?;
        Ok(Self::from_checked(alpha_x, alpha_y))
    }

    /// Anisotropic Beckmann from widths the caller has already checked (a material recipe
    /// checks them once, with the smooth limit).
    pub(crate) fn from_checked(alpha_x: f64, alpha_y: f64) -> Self {
        Self::from_alphas(alpha_x, alpha_y, BeckmannG1::Exact)
    }

    fn from_alphas(ax: f64, ay: f64, g1_form: BeckmannG1) -> Self {
        Beckmann {
            ax,
            ay,
            g1_form,
            ax2: ax * ax,
            ay2: ay * ay,
            inv_ax2: 1.0 / (ax * ax),
            inv_ay2: 1.0 / (ay * ay),
            norm: 1.0 / (PI * ax * ay),
        }
    }

    pub fn isotropic(alpha: f64) -> ParamResult<Self> {
        check_alpha("alpha", alpha)?;
        Ok(Self::from_checked(alpha, alpha))
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
        Self::from_alphas(self.ax * s, self.ay * s, self.g1_form)
    }

    /// a = 1 / (α_v tan θ_v) with α_v² = α_x² cos² φ_v + α_y² sin² φ_v  [IL18 eq. 20].
    #[inline]
    fn a_of(&self, v: Vec3) -> f64 {
        let s2 = self.ax2 * v.x * v.x + self.ay2 * v.y * v.y;
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

    /// Exact G1 = 1/(1 + Λ) through [`g1_exact_table`]: y = a/(1 + a) = z/(z + √s²) costs
    /// one square root and one division.
    #[inline]
    pub fn g1_exact_fast(&self, v: Vec3) -> f64 {
        let s2 = self.ax2 * v.x * v.x + self.ay2 * v.y * v.y;
        let z = v.z.abs();
        if s2 <= 0.0 {
            return 1.0;
        }
        g1_exact_table().eval(z / (z + s2.sqrt()))
    }

    /// WMLT07 eq. 27 written with a = z/r (z = |cos θ|, r = α_v sin θ): one square root and
    /// one division.
    #[inline]
    fn g1_rational_fast(&self, v: Vec3) -> f64 {
        let r2 = self.ax2 * v.x * v.x + self.ay2 * v.y * v.y;
        let z = v.z.abs();
        if z * z >= 2.56 * r2 {
            return 1.0;
        }
        let r = r2.sqrt();
        ((3.535 * z * r + 2.181 * z * z) / (r2 + 2.276 * z * r + 2.577 * z * z)).min(1.0)
    }
}

/// The exact Beckmann G1(a) = 1/(1 + Λ(a)) tabulated once, at first use, from the erf form
/// of IL18 eq. 20, with its exact derivative, on a grid uniform in y = a/(1 + a) ∈ [0, 1]
/// (4096 intervals), evaluated by cubic Hermite interpolation. Λ depends on a alone, so one
/// table serves every roughness and anisotropy; the tests measure its largest deviation from
/// the closed form (below 1e-12).
pub struct G1Table {
    /// (G1, dG1/dy · h) at each node, interleaved so a lookup touches one cache line.
    nodes: Vec<[f64; 2]>,
}

impl G1Table {
    const INTERVALS: usize = 4096;

    fn build() -> Self {
        let n = Self::INTERVALS;
        let nodes = (0..=n)
            .map(|k| {
                let y = k as f64 / n as f64;
                let (g, dg_dy) = if k == 0 {
                    // G1 ≈ 2a√π near a = 0 and da/dy = 1 there.
                    (0.0, 2.0 * SQRT_PI)
                } else if k == n {
                    (1.0, 0.0)
                } else {
                    let a = y / (1.0 - y);
                    let l = lambda_of_a(a);
                    let g = 1.0 / (1.0 + l);
                    // dΛ/da = −e^{−a²}/(2a²√π); dG1/da = −Λ'/(1+Λ)²; da/dy = 1/(1−y)².
                    let dl = -(-a * a).exp() / (2.0 * a * a * SQRT_PI);
                    (g, -dl * g * g / ((1.0 - y) * (1.0 - y)))
                };
                [g, dg_dy / n as f64] // slope per unit of the cell coordinate
            })
            .collect();
        G1Table { nodes }
    }

    /// G1 at y = a/(1 + a).
    #[inline]
    pub fn eval(&self, y: f64) -> f64 {
        let n = Self::INTERVALS;
        let x = (y * n as f64).clamp(0.0, n as f64);
        let i = (x as usize).min(n - 1);
        let t = x - i as f64;
        let ([p0, m0], [p1, m1]) = (self.nodes[i], self.nodes[i + 1]);
        let t2 = t * t;
        let t3 = t2 * t;
        let v = (2.0 * t3 - 3.0 * t2 + 1.0) * p0
            + (t3 - 2.0 * t2 + t) * m0
            + (-2.0 * t3 + 3.0 * t2) * p1
            + (t3 - t2) * m1;
        v.clamp(0.0, 1.0)
    }
}

/// The shared exact-G1 table.
pub fn g1_exact_table() -> &'static G1Table {
    static TABLE: std::sync::OnceLock<G1Table> = std::sync::OnceLock::new();
    TABLE.get_or_init(G1Table::build)
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
/// distribution seen at cos θ = `cos_theta` (Heitz & d'Eon 2014). The x̃ marginal has the
/// CDF P(x̃) ∝ 1 + erf(x̃) + tan θ e^{−x̃²}/√π on x̃ < cot θ; it is inverted in x̃ from Jakob's
/// fitted initial guess (2014, as in Mitsuba)
/// to 1e-12 (Halley steps, safeguarded by bisection). ỹ is the independent Gaussian slope.
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
    let erf_cot = erf(cot_theta);
    let norm = 1.0 / (1.0 + erf_cot + tan_theta * (-cot_theta * cot_theta).exp() / SQRT_PI);
    // Initial guess in the erf domain: b = erf(cot θ) − (1 + erf(cot θ)) (1 − u)^fit.
    let theta = cos_theta.acos();
    let fit = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
    let b = (erf_cot - (1.0 + erf_cot) * (1.0 - ux).powf(fit)).clamp(-1.0 + 1e-15, erf_cot);
    let mut x = erfinv_approx(b).min(cot_theta);
    let (mut lo, mut hi) = (-40.0, cot_theta);
    for _ in 0..60 {
        let ex = (-x * x).exp();
        let value = norm * (1.0 + erf(x) + tan_theta * ex / SQRT_PI) - ux;
        // The CDF is computed to ~1e-16: a residual at that level is converged.
        if value.abs() <= 4e-16 {
            break;
        }
        if value > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        // Halley's step (cubic convergence): V' = c e^{−x²}(1 − x tan θ),
        // V'' = c e^{−x²}(−2x(1 − x tan θ) − tan θ), c = 2 norm/√π.
        let c = norm * (2.0 / SQRT_PI) * ex;
        let d1 = c * (1.0 - x * tan_theta);
        let d2 = c * (-2.0 * x * (1.0 - x * tan_theta) - tan_theta);
        let mut next = x - 2.0 * value * d1 / (2.0 * d1 * d1 - value * d2);
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        let done = (next - x).abs() <= 1e-12 * (1.0 + x.abs()) || hi - lo <= 1e-14;
        x = next;
        if done {
            break;
        }
    }
    (x, erfinv(2.0 * uy - 1.0))
}

impl Distribution for Beckmann {
    /// D(m) = exp(−(x²/α_x² + y²/α_y²)/z²) / (π α_x α_y z⁴)  [IL18 eq. 16; WMLT07 eq. 25].
    #[inline]
    fn d(&self, m: Vec3) -> f64 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let z2 = m.z * m.z;
        if z2 * z2 < 1e-300 {
            return 0.0;
        }
        let inv_z2 = 1.0 / z2;
        let e = (m.x * m.x * self.inv_ax2 + m.y * m.y * self.inv_ay2) * inv_z2;
        self.norm * (-e).exp() * inv_z2 * inv_z2
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
            BeckmannG1::Exact => self.g1_exact_fast(v),
            BeckmannG1::Rational => self.g1_rational_fast(v),
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
        let vm = v.dot(m);
        if vm <= 0.0 || v.z <= 0.0 {
            return 0.0;
        }
        self.g1_exact_fast(v) * vm * self.d(m) / v.z
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn g1_table_matches_the_closed_form() {
        let t = g1_exact_table();
        let mut worst: f64 = 0.0;
        for k in 0..200_000 {
            let a = 1e-4 * (1.0001f64).powi(k); // 1e-4 … ~5e4
            if a > 60.0 {
                break;
            }
            let exact = g1_exact_of_a(a);
            let tab = t.eval(a / (1.0 + a));
            worst = worst.max((tab - exact).abs() / exact);
        }
        assert!(worst < 1e-12, "max relative error {worst:e}");
    }

    #[test]
    fn rational_form_matches_eq_27() {
        let b = Beckmann::isotropic(0.4)
            .unwrap()
            .with_g1(BeckmannG1::Rational);
        for k in 1..89 {
            let v = crate::math::spherical_direction((k as f64).to_radians(), 0.3);
            let a = v.z / (0.4 * (1.0 - v.z * v.z).sqrt());
            let direct = Beckmann::g1_rational_of_a(a);
            assert!((b.g1(v, Vec3::Z) - direct).abs() < 1e-14, "{k}");
        }
    }
}
