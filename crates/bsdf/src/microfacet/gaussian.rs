//! The Gaussian distribution of normal angles (Oren–Nayar, Simonot)
//! [IL18 eq. 14; TSBRM eqs. 9–12].
//!
//! D(m) = C exp(−θ_m²/2σ²) / |m·n|, σ in radians, with 1/C = 2π ∫_0^{π/2} exp(−θ²/2σ²)
//! sin θ dθ. TSBRM eq. 13's rational fit of C is unusable as printed (its denominator
//! coefficients are missing, ERRATA 8), so C is computed once per material by adaptive
//! Gauss–Kronrod quadrature to ~1e-13 relative.
//!
//! There is no closed-form sampler; as TSBRM eqs. 35–38 and IL18 §4.1 propose, normals are
//! drawn from the isotropic GGX proposal with width σ̃ = √2 σ and `pdf_normal` is that
//! proposal's density D_GGX(m)|m·n| — models weight by D/pdf, so estimates stay unbiased.
//!
//! **No Smith masking.** The factor 1/|m·n| makes the microsurface area ∫ D dω infinite
//! (a logarithmic divergence at θ_m → π/2), and with it the Smith Λ of IL18 eq. 19: the
//! back-facing projected area grows like C e^{−π²/8σ²} ln(1/ε) when the integral is cut
//! ε from the horizon (for σ = 1 at θ_u = 60°: Λ = 1.17, 2.40, 3.63, 4.86 for ε = 1e-2,
//! 1e-4, 1e-6, 1e-8). The papers only pair the Gaussian with the V-cavity
//! (Torrance–Sparrow) masking, which is well defined; facette rejects Smith masking for it
//! with an error that says so, and `lambda` reports +∞ (G1 = 0).

use super::{ggx::Ggx, Distribution};
use crate::checks::{check_range, Bounds};
use crate::error::ParamResult;
use crate::math::quadrature::integrate_adaptive;
use crate::math::{fmt_num, Vec2, Vec3, PI};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gaussian {
    sigma: f64,
    c: f64,
    proposal: Ggx,
}

impl Gaussian {
    /// σ in radians, in (0, π/2). C comes from [`normalization_table`] (cheap enough to
    /// build a Gaussian per shading point, e.g. for a roughness texture).
    pub fn new(sigma: f64) -> ParamResult<Self> {
        check_range("sigma", sigma, 0.0, 0.5 * PI, Bounds::Open)?;
        Ok(Gaussian {
            sigma,
            c: normalization_table().c(sigma),
            proposal: Ggx::isotropic_unchecked(std::f64::consts::SQRT_2 * sigma),
        })
    }

    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// The normalization C [TSBRM eqs. 10–11], by quadrature (ERRATA 8).
    pub fn normalization(sigma: f64) -> f64 {
        let s2 = 2.0 * sigma * sigma;
        let f = |t: f64| (-t * t / s2).exp() * t.sin();
        // Split at a few σ so the adaptive rule sees the peak even for tiny σ.
        let mut pts = vec![0.0];
        for k in [1.0, 2.0, 4.0, 8.0] {
            if k * sigma < 0.5 * PI {
                pts.push(k * sigma);
            }
        }
        pts.push(0.5 * PI);
        let inv: f64 = pts
            .windows(2)
            .map(|w| integrate_adaptive(w[0], w[1], 1e-300, 1e-14, f))
            .sum();
        1.0 / (2.0 * PI * inv)
    }

    /// The stored C.
    pub fn c(&self) -> f64 {
        self.c
    }

    /// The GGX proposal used for sampling (width √2 σ).
    pub fn proposal(&self) -> &Ggx {
        &self.proposal
    }

    /// D as a function of θ_m (for tabulation and verification).
    #[inline]
    pub fn d_theta(&self, theta: f64) -> f64 {
        if !(0.0..0.5 * PI).contains(&theta) {
            return 0.0;
        }
        self.c * (-theta * theta / (2.0 * self.sigma * self.sigma)).exp() / theta.cos()
    }
}

/// C(σ) tabulated once from [`Gaussian::normalization`] as g(σ) = 2πσ² C(σ) — smooth and
/// equal to 1 at σ = 0 — on 4097 nodes over [0, π/2], Catmull–Rom interpolation; the tests
/// measure its error against the quadrature (< 1e-12 relative).
pub struct NormalizationTable {
    g: Vec<f64>,
    step: f64,
}

impl NormalizationTable {
    const INTERVALS: usize = 4096;

    fn build() -> Self {
        use rayon::prelude::*;
        let n = Self::INTERVALS;
        let step = 0.5 * PI / n as f64;
        let g = (0..=n + 1)
            .into_par_iter()
            .map(|k| {
                let s = (k as f64 * step).min(0.5 * PI - 1e-9);
                if k == 0 {
                    1.0
                } else {
                    2.0 * PI * s * s * Gaussian::normalization(s)
                }
            })
            .collect();
        NormalizationTable { g, step }
    }

    /// C(σ) for σ ∈ (0, π/2).
    pub fn c(&self, sigma: f64) -> f64 {
        let x = sigma / self.step;
        let i = crate::math::cell_index(x, Self::INTERVALS);
        let t = x - i as f64;
        let p1 = self.g[i];
        let p2 = self.g[i + 1];
        let p0 = if i > 0 { self.g[i - 1] } else { 2.0 * p1 - p2 };
        let p3 = self.g[i + 2];
        let (t2, t3) = (t * t, t * t * t);
        let g = 0.5
            * (2.0 * p1
                + (-p0 + p2) * t
                + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
                + (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * t3);
        g / (2.0 * PI * sigma * sigma)
    }
}

/// The shared C(σ) table.
pub fn normalization_table() -> &'static NormalizationTable {
    static TABLE: std::sync::OnceLock<NormalizationTable> = std::sync::OnceLock::new();
    TABLE.get_or_init(NormalizationTable::build)
}

impl Distribution for Gaussian {
    /// D(m) = C exp(−θ_m²/2σ²) / cos θ_m  [IL18 eq. 14].
    #[inline]
    fn d(&self, m: Vec3) -> f64 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let st = (m.x * m.x + m.y * m.y).sqrt();
        let theta = st.atan2(m.z);
        self.c * (-theta * theta / (2.0 * self.sigma * self.sigma)).exp() / m.z
    }

    /// +∞: the Gaussian's Smith Λ diverges (see the module documentation).
    #[inline]
    fn lambda(&self, v: Vec3) -> f64 {
        if v.z.abs() >= 1.0 {
            0.0
        } else {
            f64::INFINITY
        }
    }

    /// GGX proposal with σ̃ = √2 σ  [TSBRM eqs. 35–38].
    #[inline]
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        self.proposal.sample_normal(u)
    }

    /// Density of the GGX proposal, D_GGX(m)|m·n| (the denominator of TSBRM eq. 37).
    #[inline]
    fn pdf_normal(&self, m: Vec3) -> f64 {
        self.proposal.pdf_normal(m)
    }

    fn typical_width(&self) -> f64 {
        std::f64::consts::SQRT_2 * self.sigma
    }

    fn describe(&self) -> String {
        format!("gaussian(sigma={})", fmt_num(self.sigma))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalization_table_matches_the_quadrature() {
        let t = normalization_table();
        let mut worst: f64 = 0.0;
        for k in 1..2000 {
            let s = k as f64 * 0.000_785; // up to ≈ 1.57
            if s >= 0.5 * PI {
                break;
            }
            let exact = Gaussian::normalization(s);
            worst = worst.max(((t.c(s) - exact) / exact).abs());
        }
        assert!(worst < 1e-10, "{worst:e}");
    }
}
