//! Hemispherical averages of the Fresnel reflectance of a flat interface under Lambertian
//! illumination: r_e from outside (Molenaar et al. 1999)  [IL18 eq. 11; TSBRM eq. 23] and
//! r_i from inside, related by n_i² (1 − r_i) = 1 − r_e  [IL18 §3.1].

use super::dielectric::fresnel_dielectric;
use crate::math::quadrature::integrate_adaptive;

/// Below this n_i − 1 the closed form loses digits to cancellation (its terms are O(1/(n−1)))
/// and the average is computed by quadrature instead.
const CLOSED_FORM_MIN_EXCESS: f64 = 1e-3;

/// r_e = ∫_0^{π/2} F(θ) sin 2θ dθ for light incident from the medium of index n_0 on a flat
/// interface of relative index `ni` = n_1/n_0 ≥ 1, by Molenaar's closed form  [IL18 eq. 11].
pub fn external_diffuse_reflectance(ni: f64) -> f64 {
    if ni <= 1.0 {
        return 0.0;
    }
    if ni - 1.0 < CLOSED_FORM_MIN_EXCESS {
        return external_diffuse_reflectance_numeric(ni);
    }
    let n = ni;
    let n2 = n * n;
    let n4 = n2 * n2;
    0.5 - 2.0 * n2 * n * (n2 + 2.0 * n - 1.0) / ((n2 + 1.0) * (n4 - 1.0))
        + (n - 1.0) * (3.0 * n + 1.0) / (6.0 * (n + 1.0) * (n + 1.0))
        + 8.0 * n4 * (n4 + 1.0) / ((n2 + 1.0) * (n4 - 1.0) * (n4 - 1.0)) * n.ln()
        + n2 * (n2 - 1.0) * (n2 - 1.0) / ((n2 + 1.0) * (n2 + 1.0) * (n2 + 1.0))
            * ((n - 1.0) / (n + 1.0)).ln()
}

/// r_e by adaptive quadrature of ∫ F(θ) sin 2θ dθ (verification and the n_i → 1 range).
pub fn external_diffuse_reflectance_numeric(ni: f64) -> f64 {
    integrate_adaptive(0.0, 0.5 * std::f64::consts::PI, 1e-16, 1e-13, |t: f64| {
        fresnel_dielectric(t.cos(), ni) * (2.0 * t).sin()
    })
}

/// r_i = 1 − (1 − r_e)/n_i²: reflectance of the interface lit diffusely from inside
/// [IL18 §3.1; TSBRM §3.2].
pub fn internal_diffuse_reflectance(ni: f64) -> f64 {
    if ni <= 1.0 {
        return 0.0;
    }
    1.0 - (1.0 - external_diffuse_reflectance(ni)) / (ni * ni)
}

/// r_i by quadrature of the internal Fresnel reflectance (with total internal reflection).
pub fn internal_diffuse_reflectance_numeric(ni: f64) -> f64 {
    let crit = (1.0 / ni).asin();
    // Split at the critical angle where F jumps to 1.
    integrate_adaptive(0.0, crit, 1e-16, 1e-13, |t: f64| {
        fresnel_dielectric(t.cos(), 1.0 / ni) * (2.0 * t).sin()
    }) + integrate_adaptive(crit, 0.5 * std::f64::consts::PI, 1e-16, 1e-13, |t: f64| {
        (2.0 * t).sin()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_matches_quadrature_within_1e5() {
        for &n in &[1.0005, 1.01, 1.2, 1.33, 1.5, 2.0, 3.0] {
            let a = external_diffuse_reflectance(n);
            let b = external_diffuse_reflectance_numeric(n);
            assert!((a - b).abs() < 1e-5, "n={n}: closed {a} vs numeric {b}");
            let ri = internal_diffuse_reflectance(n);
            let ri_num = internal_diffuse_reflectance_numeric(n);
            assert!((ri - ri_num).abs() < 1e-5, "n={n}: r_i {ri} vs {ri_num}");
        }
        assert_eq!(external_diffuse_reflectance(1.0), 0.0);
        assert_eq!(internal_diffuse_reflectance(1.0), 0.0);
    }

    #[test]
    fn glass_reference_values() {
        // r_e(1.5) ≈ 0.0918 and r_i(1.5) ≈ 0.596 (Molenaar et al. 1999, Table 1).
        assert!((external_diffuse_reflectance(1.5) - 0.0918).abs() < 5e-4);
        assert!((internal_diffuse_reflectance(1.5) - 0.596).abs() < 2e-3);
    }
}
