//! Schlick's approximation F ≈ F0 + (1 − F0)(1 − cos θ)⁵ (Schlick 1994), offered as a
//! cheaper option; the exact forms are the default.

use crate::math::spectrum::Spectrum;

#[inline]
pub fn fresnel_schlick(cos_theta: f64, f0: Spectrum) -> Spectrum {
    let m = (1.0 - cos_theta.abs().min(1.0)).max(0.0);
    let m5 = m * m * m * m * m;
    f0 + (Spectrum::ONE - f0) * m5
}

/// Schlick for a dielectric of relative index η = η_t/η_i, using the cosine on the
/// optically thinner side so that total internal reflection is respected.
#[inline]
pub fn fresnel_schlick_dielectric(cos_theta: f64, eta: f64) -> f64 {
    let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
    let c = if eta < 1.0 {
        match super::dielectric::refracted_cos(cos_theta, eta) {
            None => return 1.0,
            Some(ct) => ct,
        }
    } else {
        cos_theta.abs()
    };
    fresnel_schlick(c, Spectrum::splat(f0))[0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fresnel::fresnel_dielectric;

    #[test]
    fn close_to_exact_for_glass() {
        let mut worst: f64 = 0.0;
        for k in 0..=100 {
            let c = k as f64 / 100.0;
            worst =
                worst.max((fresnel_schlick_dielectric(c, 1.5) - fresnel_dielectric(c, 1.5)).abs());
            assert!(fresnel_schlick_dielectric(c, 1.0 / 1.5) <= 1.0);
        }
        assert!(worst < 0.04, "{worst}");
        assert_eq!(fresnel_schlick_dielectric(0.5, 1.0 / 1.5), 1.0);
    }
}
