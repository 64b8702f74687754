//! The Phong distribution  [WMLT07 eqs. 30–32].
//!
//! D(m) = (α_p + 2)/(2π) cos^{α_p} θ_m. Its Smith integral has no closed form; WMLT07
//! recommends its Beckmann rational G1 (eq. 27) with a = √(0.5 α_p + 1)/tan θ_v, which is
//! the default here. `PhongG1::Numeric` instead tabulates the exact Smith Λ of this D from
//! IL18 eq. 19 (see [`super::smith_lambda::LambdaTable`]); the gap between the two is
//! measured by the validation suite. WMLT07's correspondence with Beckmann is
//! α_p = 2 α_b⁻² − 2.

use super::beckmann::Beckmann;
use super::smith_lambda::LambdaTable;
use super::Distribution;
use crate::checks::{check_range, Bounds};
use crate::error::ParamResult;
use crate::math::{fmt_num, Vec2, Vec3, PI, TWO_PI};
use std::sync::Arc;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhongG1 {
    /// WMLT07's recommendation: Beckmann's rational G1 with a = √(0.5α_p + 1)/tan θ.
    Rational,
    /// Exact Smith G1 of the Phong D, tabulated numerically per material.
    Numeric,
}

#[derive(Clone, Debug)]
pub struct Phong {
    exponent: f64,
    g1_form: PhongG1,
    table: Option<Arc<LambdaTable>>,
}

impl Phong {
    /// Exponent α_p ≥ 0.
    pub fn new(exponent: f64) -> ParamResult<Self> {
        check_range("exponent", exponent, 0.0, 1e7, Bounds::Closed)?;
        Ok(Phong {
            exponent,
            g1_form: PhongG1::Rational,
            table: None,
        })
    }

    /// Phong matched to a Beckmann width: α_p = 2/α_b² − 2  [WMLT07 §5.2]; α_b ∈ (0, 1].
    pub fn from_beckmann_alpha(alpha: f64) -> ParamResult<Self> {
        check_range("alpha", alpha, 0.0, 1.0, Bounds::OpenClosed)?;
        Self::new(2.0 / (alpha * alpha) - 2.0)
    }

    pub fn with_g1(mut self, form: PhongG1) -> Self {
        self.g1_form = form;
        self.table = match form {
            PhongG1::Rational => None,
            PhongG1::Numeric => {
                let n = self.exponent;
                Some(Arc::new(LambdaTable::build(
                    move |t: f64| (n + 2.0) / (2.0 * PI) * t.cos().max(0.0).powf(n),
                    self.typical_width(),
                )))
            }
        };
        self
    }

    pub fn exponent(&self) -> f64 {
        self.exponent
    }

    pub fn g1_form(&self) -> PhongG1 {
        self.g1_form
    }

    /// D as a function of θ_m.
    pub fn d_theta(&self, theta: f64) -> f64 {
        (self.exponent + 2.0) / (2.0 * PI) * theta.cos().max(0.0).powf(self.exponent)
    }

    /// Λ from WMLT07's recommended rational G1.
    pub fn lambda_rational(&self, v: Vec3) -> f64 {
        let z = v.z.abs();
        let s = (1.0 - z * z).max(0.0).sqrt();
        if s == 0.0 {
            return 0.0;
        }
        let a = (0.5 * self.exponent + 1.0).sqrt() * z / s;
        let g = Beckmann::g1_rational_of_a(a);
        if g <= 0.0 {
            f64::INFINITY
        } else {
            1.0 / g - 1.0
        }
    }
}

impl Distribution for Phong {
    /// D(m) = (α_p + 2)/(2π) cos^{α_p} θ_m  [WMLT07 eq. 30].
    #[inline]
    fn d(&self, m: Vec3) -> f64 {
        if m.z <= 0.0 {
            return 0.0;
        }
        (self.exponent + 2.0) / (2.0 * PI) * m.z.powf(self.exponent)
    }

    fn lambda(&self, v: Vec3) -> f64 {
        match (&self.g1_form, &self.table) {
            (PhongG1::Numeric, Some(t)) => t.lambda_of_cos(v.z),
            _ => self.lambda_rational(v),
        }
    }

    /// cos θ_m = ξ1^{1/(α_p+2)}, φ_m = 2πξ2  [WMLT07 eqs. 31–32].
    #[inline]
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        let ct = u.x.powf(1.0 / (self.exponent + 2.0));
        let st = (1.0 - ct * ct).max(0.0).sqrt();
        let (s, c) = (TWO_PI * u.y).sin_cos();
        Vec3::new(st * c, st * s, ct)
    }

    #[inline]
    fn pdf_normal(&self, m: Vec3) -> f64 {
        self.d(m) * m.z.max(0.0)
    }

    fn typical_width(&self) -> f64 {
        (2.0 / (self.exponent + 2.0)).sqrt()
    }

    fn describe(&self) -> String {
        match self.g1_form {
            PhongG1::Rational => format!("phong(exponent={})", fmt_num(self.exponent)),
            PhongG1::Numeric => format!("phong(exponent={}, numeric G1)", fmt_num(self.exponent)),
        }
    }
}
