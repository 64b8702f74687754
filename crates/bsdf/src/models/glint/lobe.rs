//! One lobe of the mixture: a non-centred, correlated (anisotropic, non axis-aligned)
//! Beckmann distribution, i.e. a 2-D Gaussian of microfacet slopes
//! P22(m̃) = exp(−½ (m̃ − μ)ᵀ Σ⁻¹ (m̃ − μ)) / (2π √|Σ|)  [CCM19 eq. 4], with
//! D(m) = P22(m̃) / cos⁴θ_m  [CCM19 eq. 2], and its closed-form masking terms.
//!
//! **Masking (ERRATA 15).** CCM19 eq. 13 needs, for each lobe, the integral
//! I(v) = ∫ ⟨v, m⟩ D(m) dω_m (the visible projected area, the denominator of CCM19 eq. 11 /
//! IL18 eq. 19). In slope space dω_m = cos³θ_m dm̃ and ⟨v, m⟩/cos θ_m = (v_z − v_⊥·m̃)⁺
//! with v_⊥ = (v_x, v_y), so
//!
//!   I(v) = E[(v_z − v_⊥·m̃)⁺],  m̃ ~ N(μ, Σ).
//!
//! The scalar X = v_z − v_⊥·m̃ is Gaussian with mean d = v_z − v_⊥·μ and variance
//! s² = v_⊥ᵀ Σ v_⊥ (the slope mean and covariance projected on the azimuth of v), hence
//!
//!   I(v) = d Φ(d/s) + s φ(d/s).
//!
//! The lobe's projected area is A(v) = (v_z − v_⊥·μ)⁺ = ⟨ω̄_n, v⟩/(ω̄_n·ω_g) with ω̄_n the
//! mean normal  [CCM19 eq. 17, one term], and Λ = I/A − 1  [CCM19 eq. 13]. With ν = d/s and
//! a = ν/√2 this is Λ = e^{−a²}/(2a√π) − erfc(a)/2: the Beckmann Λ  [IL18 eq. 20] in the
//! shifted, scaled variable a = (cot θ_v − μ_t)/(√2 σ_t), where μ_t and σ_t are the mean and
//! standard deviation of the slope along the azimuth of v. For a centred isotropic lobe of
//! width α = √2 σ it reduces to IL18 eq. 20 exactly. When the mean facet faces away from v
//! (d ≤ 0) A = 0 and Λ = ∞, but the product A(1 + Λ) = I stays finite: the models use I.
//!
//! **Truncation.** The mixture's evaluation skips lobes whose Mahalanobis distance to the
//! query slope exceeds [`CUTOFF_R2`] (the paper's 99 % boxes, §5, made stricter). To keep the
//! density a density and the sampler exact, a lobe *is* the Gaussian truncated to
//! (m̃ − μ)ᵀΣ⁻¹(m̃ − μ) ≤ [`CUTOFF_R2`] and renormalized by 1/(1 − e^{−R²/2}); its sampler draws
//! the Mahalanobis radius from the truncated Rayleigh law. The masking integral uses the
//! untruncated Gaussian (the difference is below e^{−8} = 3.4e-4 of I).

use crate::math::special::erfc;
use crate::math::{Vec2, Vec3, PI, TWO_PI};
use crate::microfacet::beckmann::lambda_of_a;

/// Squared Mahalanobis radius beyond which a Gaussian (a lobe in slope space, or a seed
/// weight in position) is treated as zero: e^{−R²/2} = 3.4e-4 of the mass lies outside.
pub const CUTOFF_R2: f64 = 16.0;

/// 1/(1 − e^{−R²/2}): the normalization of a 2-D Gaussian truncated at [`CUTOFF_R2`].
pub const TRUNCATED_NORM: f64 = 1.000_335_5;

/// A lobe as stored: the slope mean and the inverse covariance (a, b, c) with
/// Σ⁻¹ = [[a, b], [b, c]] — five `f32` (20 bytes), the paper's "5 scalars per NDF" (§5.1.2).
/// The inverse is stored rather than Σ because evaluating P22 is the hot path.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[repr(C)]
pub struct SlopeLobe {
    pub mean: [f32; 2],
    pub inv_cov: [f32; 3],
}

/// A lobe in `f64` with both its covariance and its inverse: what the masking terms and the
/// sampler work with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LobeF64 {
    pub mean: [f64; 2],
    /// Σ = [[xx, xy], [xy, yy]] as (xx, xy, yy).
    pub cov: [f64; 3],
}

impl SlopeLobe {
    /// The lobe of slope mean `mean` and covariance `cov` = (σ_x², c_xy, σ_y²)  [CCM19
    /// eq. 5 with ERRATA 14: c_xy is the covariance, not its square]. The covariance must be
    /// positive definite (callers add the roughness floor first).
    pub fn from_moments(mean: [f64; 2], cov: [f64; 3]) -> SlopeLobe {
        let det = cov[0] * cov[2] - cov[1] * cov[1];
        SlopeLobe {
            mean: [mean[0] as f32, mean[1] as f32],
            inv_cov: [
                (cov[2] / det) as f32,
                (-cov[1] / det) as f32,
                (cov[0] / det) as f32,
            ],
        }
    }

    /// Squared Mahalanobis distance of the slope `s` from the mean.
    #[inline]
    pub fn mahalanobis2(&self, s: [f32; 2]) -> f32 {
        let dx = s[0] - self.mean[0];
        let dy = s[1] - self.mean[1];
        let [a, b, c] = self.inv_cov;
        a * dx * dx + 2.0 * b * dx * dy + c * dy * dy
    }

    /// √|Σ⁻¹| / (2π) · 1/(1 − e^{−R²/2}): the truncated Gaussian's peak value.
    #[inline]
    pub fn peak(&self) -> f64 {
        let [a, b, c] = self.inv_cov;
        let det = (a as f64) * (c as f64) - (b as f64) * (b as f64);
        det.max(0.0).sqrt() * (TRUNCATED_NORM / TWO_PI)
    }

    /// The truncated P22 at slope `s`  [CCM19 eq. 4].
    #[inline]
    pub fn p22(&self, s: [f32; 2]) -> f64 {
        let q = self.mahalanobis2(s);
        if !(q <= CUTOFF_R2 as f32) {
            return 0.0;
        }
        self.peak() * (-0.5 * q as f64).exp()
    }

    /// The half-widths of the slope box holding the truncated lobe: R·(σ_x, σ_y).
    pub fn slope_half_extent(&self) -> [f64; 2] {
        let f = self.to_f64();
        let r = CUTOFF_R2.sqrt();
        [r * f.cov[0].sqrt(), r * f.cov[2].sqrt()]
    }

    pub fn to_f64(&self) -> LobeF64 {
        let [a, b, c] = self.inv_cov.map(|x| x as f64);
        let det = a * c - b * b;
        LobeF64 {
            mean: [self.mean[0] as f64, self.mean[1] as f64],
            cov: [c / det, -b / det, a / det],
        }
    }
}

/// Standard normal cumulative distribution Φ(x).
#[inline]
pub fn normal_cdf(x: f64) -> f64 {
    0.5 * erfc(-x * std::f64::consts::FRAC_1_SQRT_2)
}

/// Standard normal density φ(x).
#[inline]
pub fn normal_pdf(x: f64) -> f64 {
    (-0.5 * x * x).exp() * (1.0 / (TWO_PI).sqrt())
}

/// E[X⁺] for X ~ N(d, s²): d Φ(d/s) + s φ(d/s) (d⁺ when s = 0). Written so that it keeps
/// its relative precision on both sides: for d > 0 as d (1 + Λ(a)) with the Beckmann Λ of
/// a = d/(√2 s), which is small and accurate; for d ≤ 0 from the erfc tail.
#[inline]
pub fn expected_positive_part(d: f64, s: f64) -> f64 {
    if !(s > 0.0) {
        return d.max(0.0);
    }
    let nu = d / s;
    if nu > 0.0 {
        d * (1.0 + lambda_of_a(nu * std::f64::consts::FRAC_1_SQRT_2))
    } else {
        (s * normal_pdf(nu) + d * normal_cdf(nu)).max(0.0)
    }
}

impl LobeF64 {
    /// Inverse covariance (a, b, c).
    pub fn inverse(&self) -> [f64; 3] {
        let [xx, xy, yy] = self.cov;
        let det = xx * yy - xy * xy;
        [yy / det, -xy / det, xx / det]
    }

    /// d = v_z − v_⊥·μ and s = √(v_⊥ᵀ Σ v_⊥): the mean and standard deviation of
    /// v_z − v_⊥·m̃ (see the module notes).
    #[inline]
    pub fn projected_moments(&self, v: Vec3) -> (f64, f64) {
        let d = v.z - v.x * self.mean[0] - v.y * self.mean[1];
        let [xx, xy, yy] = self.cov;
        let s2 = v.x * v.x * xx + 2.0 * v.x * v.y * xy + v.y * v.y * yy;
        (d, s2.max(0.0).sqrt())
    }

    /// A(v) = (v_z − v_⊥·μ)⁺: the projected area of the lobe's mean facet per unit of
    /// geometric area  [CCM19 eq. 17, one term].
    #[inline]
    pub fn projected_area(&self, v: Vec3) -> f64 {
        self.projected_moments(v).0.max(0.0)
    }

    /// I(v) = ∫ ⟨v, m⟩ D(m) dω_m = A(v) (1 + Λ(v))  [CCM19 eqs. 12–13; IL18 eq. 19], in
    /// closed form (module notes).
    #[inline]
    pub fn visible_projected_area(&self, v: Vec3) -> f64 {
        let (d, s) = self.projected_moments(v);
        expected_positive_part(d, s)
    }

    /// Smith Λ(v) of the lobe: the Beckmann Λ of IL18 eq. 20 with
    /// a = (v_z − v_⊥·μ)/(√2 √(v_⊥ᵀΣv_⊥))  (ERRATA 15); ∞ when the mean facet is back-facing.
    #[inline]
    pub fn lambda(&self, v: Vec3) -> f64 {
        let (d, s) = self.projected_moments(v);
        if d <= 0.0 {
            return f64::INFINITY;
        }
        if s <= 0.0 {
            return 0.0;
        }
        lambda_of_a(d / (s * std::f64::consts::SQRT_2))
    }

    /// Untruncated P22 at slope `s` (for numerical checks).
    pub fn p22_untruncated(&self, s: [f64; 2]) -> f64 {
        let [a, b, c] = self.inverse();
        let dx = s[0] - self.mean[0];
        let dy = s[1] - self.mean[1];
        let q = a * dx * dx + 2.0 * b * dx * dy + c * dy * dy;
        (a * c - b * b).max(0.0).sqrt() / TWO_PI * (-0.5 * q).exp()
    }

    /// Untruncated D(m) = P22(m̃)/cos⁴θ_m  [CCM19 eq. 2] (numerical checks, and the glint
    /// material's MIS proxy); 0 at and below the horizon, where cos⁴θ_m underflows.
    pub fn d_untruncated(&self, m: Vec3) -> f64 {
        let z2 = m.z * m.z;
        if !(m.z > 0.0) || z2 * z2 < 1e-300 {
            return 0.0;
        }
        let s = [-m.x / m.z, -m.y / m.z];
        self.p22_untruncated(s) / (z2 * z2)
    }

    /// Lower-triangular Cholesky factor L (Σ = L Lᵀ) as (l11, l21, l22); robust to a
    /// semi-definite Σ.
    #[inline]
    pub fn cholesky(&self) -> [f64; 3] {
        cholesky2(self.cov)
    }

    /// Draws a slope from the lobe truncated at [`CUTOFF_R2`]: the Mahalanobis radius from
    /// the truncated Rayleigh law r² = −2 ln(1 − u₁(1 − e^{−R²/2})), the angle uniform,
    /// mapped through the Cholesky factor.
    #[inline]
    pub fn sample_slope(&self, u: Vec2) -> [f64; 2] {
        let [l11, l21, l22] = self.cholesky();
        let (zx, zy) = truncated_standard_normal_2d(u);
        [self.mean[0] + l11 * zx, self.mean[1] + l21 * zx + l22 * zy]
    }
}

/// Cholesky factor (l11, l21, l22) of a symmetric 2×2 matrix (xx, xy, yy), clamping
/// negative pivots to zero.
#[inline]
pub fn cholesky2(m: [f64; 3]) -> [f64; 3] {
    let l11 = m[0].max(0.0).sqrt();
    let l21 = if l11 > 0.0 { m[1] / l11 } else { 0.0 };
    let l22 = (m[2] - l21 * l21).max(0.0).sqrt();
    [l11, l21, l22]
}

/// A standard 2-D normal truncated to radius² ≤ [`CUTOFF_R2`], from two uniforms.
#[inline]
pub fn truncated_standard_normal_2d(u: Vec2) -> (f64, f64) {
    let mass = 1.0 / TRUNCATED_NORM; // 1 − e^{−R²/2}
    let r = (-2.0 * (-u.x * mass).ln_1p()).max(0.0).sqrt();
    let (s, c) = (TWO_PI * u.y).sin_cos();
    (r * c, r * s)
}

/// A standard 2-D normal (Box–Muller), from two uniforms.
#[inline]
pub fn standard_normal_2d(u: Vec2) -> (f64, f64) {
    let r = (-2.0 * (-u.x).ln_1p()).max(0.0).sqrt();
    let (s, c) = (TWO_PI * u.y).sin_cos();
    (r * c, r * s)
}

/// The microfacet normal of slope (x̃, ỹ): m ∝ (−x̃, −ỹ, 1)  [CCM19 §3].
#[inline]
pub fn normal_of_slope(s: [f64; 2]) -> Vec3 {
    let inv = 1.0 / (1.0 + s[0] * s[0] + s[1] * s[1]).sqrt();
    Vec3::new(-s[0] * inv, -s[1] * inv, inv)
}

/// The slope of a normal with m_z > 0: (−m_x/m_z, −m_y/m_z)  [CCM19 §3].
#[inline]
pub fn slope_of_normal(m: Vec3) -> [f64; 2] {
    [-m.x / m.z, -m.y / m.z]
}

/// ∫ (v·m)⁺ D(m) dω_m by adaptive quadrature over the hemisphere of normals (θ, φ), the
/// definition of IL18 eq. 19 / CCM19 eq. 11: the check of the closed form
/// [`LobeF64::visible_projected_area`]. Breakpoints are placed around the lobe's mean
/// direction so that narrow lobes are resolved.
pub fn visible_projected_area_numeric(lobe: &LobeF64, v: Vec3) -> f64 {
    use crate::math::quadrature::integrate_adaptive;
    let mean_n = normal_of_slope(lobe.mean);
    let (theta0, phi0) = crate::math::spherical_angles(mean_n);
    let width = (lobe.cov[0].max(lobe.cov[2])).sqrt().max(1e-4);
    // θ breakpoints: geometric steps away from the mean polar angle.
    let mut tb = vec![0.0, 0.5 * PI];
    let mut w = 0.25 * width;
    while w < PI {
        for t in [theta0 - w, theta0 + w] {
            if t > 0.0 && t < 0.5 * PI {
                tb.push(t);
            }
        }
        w *= 2.0;
    }
    tb.push(theta0.clamp(0.0, 0.5 * PI));
    tb.sort_by(f64::total_cmp);
    tb.dedup();
    let inner = |theta: f64| {
        let st = theta.sin();
        // φ breakpoints around the mean azimuth, scaled by the angular width at this θ.
        let aw = (width / st.max(1e-6)).min(PI);
        let mut pb = vec![phi0 - PI, phi0 + PI];
        let mut w = 0.25 * aw;
        while w < PI {
            pb.push(phi0 - w);
            pb.push(phi0 + w);
            w *= 2.0;
        }
        pb.push(phi0);
        pb.sort_by(f64::total_cmp);
        pb.dedup();
        let f = |phi: f64| {
            let m = crate::math::spherical_direction(theta, phi);
            v.dot(m).max(0.0) * lobe.d_untruncated(m)
        };
        pb.windows(2)
            .map(|p| integrate_adaptive(p[0], p[1], 1e-300, 1e-11, f))
            .sum::<f64>()
            * st
    };
    tb.windows(2)
        .map(|p| integrate_adaptive(p[0], p[1], 1e-300, 1e-10, inner))
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::spherical_direction;
    use crate::microfacet::{Beckmann, Distribution};

    #[test]
    fn truncated_norm_constant_matches_its_definition() {
        let exact = 1.0 / (1.0 - (-0.5 * CUTOFF_R2).exp());
        assert!((TRUNCATED_NORM - exact).abs() < 1e-7, "{exact}");
    }

    #[test]
    fn centred_isotropic_lobe_is_the_beckmann_distribution() {
        // Slope σ per axis ⇔ Beckmann α = √2 σ  [WMLT07 eq. 25].
        let sigma = 0.2;
        let lobe = LobeF64 {
            mean: [0.0, 0.0],
            cov: [sigma * sigma, 0.0, sigma * sigma],
        };
        let b = Beckmann::isotropic(sigma * std::f64::consts::SQRT_2).unwrap();
        for k in 0..60 {
            let v = spherical_direction(k as f64 * 0.025, 0.7 + k as f64);
            let rel = (lobe.d_untruncated(v) - b.d(v)).abs() / b.d(v).max(1e-300);
            assert!(rel < 1e-12, "D differs at {k}");
            let l = lobe.lambda(v);
            let lb = b.lambda(v);
            assert!((l - lb).abs() <= 1e-12 * (1.0 + lb), "Λ {l} vs {lb}");
        }
    }

    #[test]
    fn closed_form_masking_matches_numerical_integration() {
        // Non-centred, correlated, anisotropic lobes (ERRATA 15) against the definition.
        let lobes = [
            LobeF64 {
                mean: [0.3, -0.2],
                cov: [0.04, 0.012, 0.01],
            },
            LobeF64 {
                mean: [-0.8, 0.5],
                cov: [0.09, -0.05, 0.16],
            },
            LobeF64 {
                mean: [0.05, 0.0],
                cov: [1e-4, 0.0, 1e-4],
            },
        ];
        let mut worst: f64 = 0.0;
        for lobe in &lobes {
            for (t, p) in [(0.0, 0.0), (0.6, 0.3), (1.2, 2.0), (1.45, 4.0), (1.55, 0.9)] {
                let v = spherical_direction(t, p);
                let closed = lobe.visible_projected_area(v);
                let num = visible_projected_area_numeric(lobe, v);
                let rel = (closed - num).abs() / num;
                worst = worst.max(rel);
                // Λ from the closed form agrees with Λ from the integral.
                let a = lobe.projected_area(v);
                if a > 1e-3 {
                    let ln = num / a - 1.0;
                    assert!((lobe.lambda(v) - ln).abs() < 1e-6 * (1.0 + ln), "{t} {p}");
                }
            }
        }
        println!("closed-form I(v) vs numerical integration: max relative error {worst:.2e}");
        assert!(worst < 1e-7, "{worst}");
    }

    #[test]
    fn projected_area_is_exact_for_any_lobe() {
        // ∫ (v·m) D dω = v_z − v_⊥·μ (signed): the mean facet's projected area.
        let lobe = LobeF64 {
            mean: [0.2, 0.1],
            cov: [0.02, 0.005, 0.03],
        };
        let v = spherical_direction(0.5, 1.0);
        let signed = crate::microfacet::smith_lambda::projected_area(&LobeAsDistribution(lobe), v);
        assert!((signed - lobe.projected_area(v)).abs() < 1e-8, "{signed}");
    }

    struct LobeAsDistribution(LobeF64);
    impl Distribution for LobeAsDistribution {
        fn d(&self, m: Vec3) -> f64 {
            self.0.d_untruncated(m)
        }
        fn lambda(&self, v: Vec3) -> f64 {
            self.0.lambda(v)
        }
        fn sample_normal(&self, _: Vec2) -> Vec3 {
            Vec3::Z
        }
        fn pdf_normal(&self, _: Vec3) -> f64 {
            0.0
        }
        fn typical_width(&self) -> f64 {
            0.1
        }
        fn describe(&self) -> String {
            "lobe".into()
        }
    }

    #[test]
    fn truncated_sampler_stays_inside_the_cutoff_and_has_unit_covariance() {
        let mut rng = crate::math::rng::Pcg32::new(3, 1);
        use crate::math::rng::RandomSource;
        let n = 200_000;
        let (mut sxx, mut sxy) = (0.0, 0.0);
        for _ in 0..n {
            let (x, y) = truncated_standard_normal_2d(rng.next_2d());
            assert!(x * x + y * y <= CUTOFF_R2 + 1e-9);
            sxx += x * x;
            sxy += x * y;
        }
        assert!((sxx / n as f64 - 1.0).abs() < 0.02);
        assert!((sxy / n as f64).abs() < 0.01);
    }

    #[test]
    fn stored_lobe_round_trips() {
        let l = SlopeLobe::from_moments([0.1, -0.3], [0.02, 0.004, 0.05]);
        let f = l.to_f64();
        assert!((f.cov[0] - 0.02).abs() < 1e-8 && (f.cov[1] - 0.004).abs() < 1e-8);
        let s = [0.12f32, -0.25];
        let d = f.p22_untruncated([s[0] as f64, s[1] as f64]) * TRUNCATED_NORM;
        assert!((l.p22(s) - d).abs() < 1e-5 * d);
    }
}
