//! Exact Fresnel reflectance of a dielectric interface for unpolarized light
//! [WMLT07 eq. 22; IL18 eq. 8; TSBRM eq. 18].

use crate::lanes::Real;

/// F(c) for c = |i·m| and relative index `eta` = η_t / η_i (the index on the far side over
/// the index on the side of i). Returns 1 under total internal reflection and at grazing
/// incidence (unless η = 1, where the interface vanishes and F = 0).
///
/// F = ½ (g−c)²/(g+c)² [1 + (c(g+c)−1)²/(c(g−c)+1)²], g = √(η² − 1 + c²).
#[inline]
pub fn fresnel_dielectric(cos_theta: f64, eta: f64) -> f64 {
    fresnel_dielectric_lanes(cos_theta, eta)
}

/// [`fresnel_dielectric`] over lanes (each lane its own cosine and relative index): the
/// one source of the formula for the lab and the renderer's kernel.
#[inline(always)]
pub fn fresnel_dielectric_lanes<R: Real>(cos_theta: R, eta: R) -> R {
    let c = cos_theta.abs().min(R::one());
    let e2m1 = eta * eta - R::one();
    let g2 = e2m1 + c * c;
    let g = g2.sqrt();
    let gmc = e2m1 / (g + c);
    let gpc = g + c;
    let a = gmc / gpc;
    let num = c * gpc - R::one();
    let den = c * gmc + R::one();
    let f = (R::splat(0.5) * a * a * (R::one() + (num / den) * (num / den))).clamp(0.0, 1.0);
    let total = g2.le(R::zero()) | c.eq(R::zero());
    R::select(eta.eq(R::one()), R::zero(), R::select(total, R::one(), f))
}

#[inline]
pub fn refracted_cos(cos_theta: f64, eta: f64) -> Option<f64> {
    let c = cos_theta.abs().min(1.0);
    let s2t = (1.0 - c * c) / (eta * eta);
    if s2t >= 1.0 {
        None
    } else {
        Some((1.0 - s2t).sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The s/p amplitude form, independent of the g-form above.
    fn fresnel_sp(c: f64, eta: f64) -> f64 {
        match refracted_cos(c, eta) {
            None => 1.0,
            Some(ct) => {
                let rs = (c - eta * ct) / (c + eta * ct);
                let rp = (eta * c - ct) / (eta * c + ct);
                0.5 * (rs * rs + rp * rp)
            }
        }
    }

    #[test]
    fn matches_the_amplitude_form_on_both_sides() {
        for &eta in &[
            1.0001,
            1.01,
            1.2,
            1.33,
            1.5,
            2.0,
            3.0,
            1.0 / 1.5,
            1.0 / 1.33,
        ] {
            for k in 0..=200 {
                let c = k as f64 / 200.0;
                let a = fresnel_dielectric(c, eta);
                let b = fresnel_sp(c, eta);
                assert!((a - b).abs() < 1e-12, "eta={eta} c={c}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn known_values_and_limits() {
        // Normal incidence: ((η−1)/(η+1))².
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-15);
        assert_eq!(fresnel_dielectric(0.0, 1.5), 1.0);
        assert_eq!(fresnel_dielectric(0.3, 1.0), 0.0);
        assert_eq!(fresnel_dielectric(0.0, 1.0), 0.0);
        // Total internal reflection from inside glass beyond 41.8°.
        assert_eq!(fresnel_dielectric(45f64.to_radians().cos(), 1.0 / 1.5), 1.0);
        assert!(fresnel_dielectric(1e-9, 1.000001).is_finite());
    }
}
