//! Fresnel reflectance of a conductor with complex index η + ik, unpolarized light
//! (Born & Wolf; the form of pbrt-v4's `FrComplex`).

use crate::error::{ParamError, ParamResult};
use crate::lanes::Real;
use crate::math::spectrum::{Spectrum, CHANNELS};

/// F for one channel.
#[inline]
pub fn fresnel_conductor_scalar(cos_theta: f64, eta: f64, k: f64) -> f64 {
    fresnel_conductor_lanes(cos_theta, eta, k)
}

/// F of the complex index η + ik at cos θ = c, over lanes, in real arithmetic (the
/// expansion of Born & Wolf's complex form used by pbrt-v3's `FrConductor` and Mitsuba's
/// `fresnel_conductor`): with a² + b² = √((η² − k² − sin²θ)² + 4η²k²) and
/// a = √((a² + b² + η² − k² − sin²θ)/2),
/// R_s = (a² + b² + c² − 2ac)/(a² + b² + c² + 2ac),
/// R_p = R_s (c²(a² + b²) + sin⁴θ − 2ac sin²θ)/(c²(a² + b²) + sin⁴θ + 2ac sin²θ),
/// F = (R_s + R_p)/2 = R_s t₃/(t₃ + t₄) with t₃ = c²(a² + b²) + sin⁴θ and t₄ = 2ac sin²θ
/// (one division). It agrees with the complex form to 3e-12 (test below; the two round differently
/// at η, k ~ 100).
#[inline(always)]
pub fn fresnel_conductor_lanes<R: Real>(cos_theta: R, eta: f64, k: f64) -> R {
    let c = cos_theta.abs().clamp(0.0, 1.0);
    let cos2 = c * c;
    let sin2 = R::one() - cos2;
    let (eta2, k2) = (R::splat(eta * eta), R::splat(k * k));
    let t0 = eta2 - k2 - sin2;
    let a2b2 = (t0 * t0 + R::splat(4.0) * eta2 * k2).sqrt();
    let a = (R::splat(0.5) * (a2b2 + t0)).max(R::zero()).sqrt();
    let t1 = a2b2 + cos2;
    let t2 = R::splat(2.0) * c * a;
    let t3 = cos2 * a2b2 + sin2 * sin2;
    let t4 = t2 * sin2;
    // (R_s + R_p)/2 = R_s (1 + (t3 − t4)/(t3 + t4))/2 = R_s t3/(t3 + t4): one division.
    let f = (t1 - t2) * t3 / ((t1 + t2) * (t3 + t4));
    // At c = 0 both ratios are 0/0 when k = 0 and η < 1; grazing light is reflected.
    R::select(f.is_finite(), f.clamp(0.0, 1.0), R::one())
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
    use crate::lanes::F32x8;
    use crate::math::complex::Complex;

    /// Born & Wolf's complex form (pbrt-v4's `FrComplex`), the reference of the real form.
    fn fresnel_complex(c: f64, eta: f64, k: f64) -> f64 {
        let n = Complex::new(eta, k);
        let sin2_t = Complex::from(1.0 - c * c) / (n * n);
        let cos_t = (Complex::from(1.0) - sin2_t).sqrt();
        let nc = n * Complex::from(c);
        let r_parl = (nc - cos_t) / (nc + cos_t);
        let nct = n * cos_t;
        let cc = Complex::from(c);
        let r_perp = (cc - nct) / (cc + nct);
        0.5 * (r_parl.norm_sqr() + r_perp.norm_sqr())
    }

    #[test]
    fn real_form_matches_the_complex_form_and_f32_lanes_match_f64() {
        let mut worst: f64 = 0.0;
        let mut worst32: f64 = 0.0;
        for &(eta, k) in &[
            (0.2, 3.9),
            (1.5, 0.0),
            (0.5, 0.0),
            (1e-4, 0.0),
            (100.0, 100.0),
            (1.66, 9.2),
            (4.37, 5.2),
            (1e-4, 100.0),
        ] {
            for i in 0..=400 {
                let c = i as f64 / 400.0;
                let a = fresnel_conductor_scalar(c, eta, k);
                worst = worst.max((a - fresnel_complex(c, eta, k).clamp(0.0, 1.0)).abs());
                let l = fresnel_conductor_lanes(F32x8::splat(c), eta, k).0[3] as f64;
                worst32 = worst32.max((l - a).abs());
            }
        }
        assert!(worst < 1e-11, "f64 real vs complex: {worst:e}");
        assert!(worst32 < 2e-6, "f32 lanes vs f64: {worst32:e}");
    }

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
