//! Fresnel reflectance of a conductor with complex index η + ik, unpolarized light
//! (Born & Wolf; the form of pbrt-v4's `FrComplex`).

use crate::error::{ParamError, ParamResult};
use crate::math::complex::Complex;
use crate::math::spectrum::{Spectrum, CHANNELS};

/// F for one channel.
#[inline]
pub fn fresnel_conductor_scalar(cos_theta: f64, eta: f64, k: f64) -> f64 {
    let c = cos_theta.abs().clamp(0.0, 1.0);
    let n = Complex::new(eta, k);
    let sin2 = 1.0 - c * c;
    let sin2_t = Complex::from(sin2) / (n * n);
    let cos_t = (Complex::from(1.0) - sin2_t).sqrt();
    let nc = n * Complex::from(c);
    let r_parl = (nc - cos_t) / (nc + cos_t);
    let nct = n * cos_t;
    let cc = Complex::from(c);
    let r_perp = (cc - nct) / (cc + nct);
    let f = 0.5 * (r_parl.norm_sqr() + r_perp.norm_sqr());
    if f.is_finite() {
        f.clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// F per channel.
#[inline]
pub fn fresnel_conductor(cos_theta: f64, eta: Spectrum, k: Spectrum) -> Spectrum {
    let mut r = [0.0; CHANNELS];
    for (c, v) in r.iter_mut().enumerate() {
        *v = fresnel_conductor_scalar(cos_theta, eta[c], k[c]);
    }
    Spectrum(r)
}

/// Named metals: complex index at the linear-sRGB primaries, relative to air.
///
/// Values are the RGB reductions of measured spectral data (Palik's *Handbook of Optical
/// Constants of Solids* via refractiveindex.info) shipped with Mitsuba 0.5 and widely reused
/// since; `docs/materials.md` lists them with their normal-incidence reflectance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetalPreset {
    pub name: &'static str,
    pub eta: [f64; 3],
    pub k: [f64; 3],
}

pub const METALS: &[MetalPreset] = &[
    MetalPreset {
        name: "Au",
        eta: [0.143_119, 0.374_957, 1.442_48],
        k: [3.983_16, 2.385_72, 1.603_22],
    },
    MetalPreset {
        name: "Ag",
        eta: [0.155_265, 0.116_723, 0.138_342],
        k: [4.828_35, 3.122_25, 2.146_96],
    },
    MetalPreset {
        name: "Cu",
        eta: [0.200_438, 0.924_033, 1.102_21],
        k: [3.912_95, 2.452_85, 2.142_19],
    },
    MetalPreset {
        name: "Al",
        eta: [1.657_46, 0.880_369, 0.521_229],
        k: [9.223_87, 6.269_52, 4.837],
    },
    MetalPreset {
        name: "Cr",
        eta: [4.369_68, 2.916_7, 1.654_7],
        k: [5.206_37, 4.231_11, 3.754_69],
    },
];

impl MetalPreset {
    pub fn find(name: &str) -> ParamResult<&'static MetalPreset> {
        METALS
            .iter()
            .find(|m| m.name.eq_ignore_ascii_case(name))
            .ok_or_else(|| ParamError::UnknownChoice {
                what: "metal preset".into(),
                given: name.into(),
                valid: METALS.iter().map(|m| m.name).collect::<Vec<_>>().join(", "),
            })
    }

    pub fn eta(&self) -> Spectrum {
        Spectrum(self.eta)
    }

    pub fn k(&self) -> Spectrum {
        Spectrum(self.k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fresnel::fresnel_dielectric;

    #[test]
    fn reduces_to_dielectric_when_k_is_zero() {
        for k in 0..=50 {
            let c = k as f64 / 50.0;
            let a = fresnel_conductor_scalar(c, 1.5, 0.0);
            let b = fresnel_dielectric(c, 1.5);
            assert!((a - b).abs() < 1e-12, "c={c}: {a} vs {b}");
        }
    }

    #[test]
    fn normal_incidence_closed_form() {
        // F(0°) = ((n−1)² + k²) / ((n+1)² + k²).
        let (n, k) = (0.2, 3.9);
        let f0 = ((n - 1.0) * (n - 1.0) + k * k) / ((n + 1.0) * (n + 1.0) + k * k);
        assert!((fresnel_conductor_scalar(1.0, n, k) - f0).abs() < 1e-14);
        assert!((fresnel_conductor_scalar(0.0, n, k) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn presets_are_found_case_insensitively_and_errors_list_them() {
        assert_eq!(MetalPreset::find("au").unwrap().name, "Au");
        let e = MetalPreset::find("gold").unwrap_err().to_string();
        assert!(e.contains("Au, Ag, Cu, Al, Cr"), "{e}");
        // Gold is yellow: red reflects more than blue at normal incidence.
        let au = MetalPreset::find("Au").unwrap();
        let f = fresnel_conductor(1.0, au.eta(), au.k());
        assert!(f[0] > 0.9 && f[2] < 0.6, "{f:?}");
    }
}
