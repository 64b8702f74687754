//! Masking-shadowing G(i, o, m), chosen independently of D where the physics allows.
//!
//! | name | formula | transmission |
//! |---|---|---|
//! | `smith` | separable G1(i,m) G1(o,m)  [WMLT07 eq. 23; IL18 eq. 17] | yes |
//! | `smith-correlated` | height-correlated 1/(1 + Λ(i) + Λ(o)); B(1+Λ(i), 1+Λ(o)) across the interface (Heitz 2014, §6) | yes |
//! | `v-cavity` | Torrance–Sparrow, min(1, 2|in||mn|/|im|, 2|on||mn|/|om|)  [IL18 eq. 15] | no |
//! | `kelemen` | 2 (n·i)(n·o) / (1 + i·o)  [KSK01 eq. 2] | no |

use super::Distribution;
use crate::error::{ParamError, ParamResult};
use crate::math::special::beta;
use crate::math::Vec3;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Masking {
    SmithSeparable,
    SmithCorrelated,
    VCavity,
    Kelemen,
}

impl Masking {
    pub const NAMES: &'static [&'static str] =
        &["smith", "smith-correlated", "v-cavity", "kelemen"];

    pub fn parse(name: &str) -> ParamResult<Self> {
        match name {
            "smith" | "smith-separable" => Ok(Masking::SmithSeparable),
            "smith-correlated" | "smith-height-correlated" => Ok(Masking::SmithCorrelated),
            "v-cavity" | "torrance-sparrow" | "ts" => Ok(Masking::VCavity),
            "kelemen" => Ok(Masking::Kelemen),
            other => Err(ParamError::UnknownChoice {
                what: "masking".into(),
                given: other.into(),
                valid: Self::NAMES.join(", "),
            }),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            Masking::SmithSeparable => "smith",
            Masking::SmithCorrelated => "smith-correlated",
            Masking::VCavity => "v-cavity",
            Masking::Kelemen => "kelemen",
        }
    }

    /// Whether the form is defined for i and o on opposite sides (refraction).
    pub fn supports_transmission(&self) -> bool {
        matches!(self, Masking::SmithSeparable | Masking::SmithCorrelated)
    }

    /// Whether the form needs the distribution's Smith Λ.
    pub fn is_smith(&self) -> bool {
        matches!(self, Masking::SmithSeparable | Masking::SmithCorrelated)
    }

    /// G(i, o, m). Sidedness (WMLT07 eq. 7) is enforced for every form: zero when a
    /// direction sees the back of m relative to its side of the macrosurface.
    #[inline]
    pub fn g(&self, dist: &impl Distribution, i: Vec3, o: Vec3, m: Vec3) -> f64 {
        let im = i.dot(m);
        let om = o.dot(m);
        if im * i.z <= 0.0 || om * o.z <= 0.0 {
            return 0.0;
        }
        let reflection = i.z * o.z > 0.0;
        match self {
            Masking::SmithSeparable => dist.g1(i, m) * dist.g1(o, m),
            Masking::SmithCorrelated => {
                let li = dist.lambda(i);
                let lo = dist.lambda(o);
                if reflection {
                    1.0 / (1.0 + li + lo)
                } else if li.is_finite() && lo.is_finite() {
                    beta(1.0 + li, 1.0 + lo)
                } else {
                    0.0
                }
            }
            Masking::VCavity => {
                if !reflection {
                    return 0.0;
                }
                let (iz, oz, mz) = (i.z.abs(), o.z.abs(), m.z);
                let a = 2.0 * mz * iz / im.abs();
                let b = 2.0 * mz * oz / om.abs();
                a.min(b).clamp(0.0, 1.0)
            }
            Masking::Kelemen => {
                if !reflection {
                    return 0.0;
                }
                let d = 1.0 + i.dot(o);
                if d <= 0.0 {
                    return 0.0;
                }
                (2.0 * i.z.abs() * o.z.abs() / d).min(1.0)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::spherical_direction;
    use crate::microfacet::Ggx;

    #[test]
    fn forms_are_symmetric_bounded_and_sided() {
        let d = Ggx::new(0.3, 0.6).unwrap();
        let i = spherical_direction(0.7, 0.2);
        let o = spherical_direction(1.2, 2.5);
        let m = (i + o).normalize();
        for mk in [
            Masking::SmithSeparable,
            Masking::SmithCorrelated,
            Masking::VCavity,
            Masking::Kelemen,
        ] {
            let g = mk.g(&d, i, o, m);
            assert!((0.0..=1.0).contains(&g), "{mk:?} {g}");
            assert!(
                (g - mk.g(&d, o, i, m)).abs() < 1e-15,
                "{mk:?} not symmetric"
            );
            // A normal facing away from i gives zero.
            let back = Vec3::new(-i.x, -i.y, 0.1).normalize();
            assert_eq!(mk.g(&d, i, o, back), 0.0);
        }
        // Height correlation never masks less than the separable product.
        assert!(Masking::SmithCorrelated.g(&d, i, o, m) >= Masking::SmithSeparable.g(&d, i, o, m));
    }

    #[test]
    fn transmission_uses_the_beta_function() {
        let d = Ggx::isotropic(0.5).unwrap();
        let i = spherical_direction(0.5, 0.0);
        let o = -spherical_direction(0.4, 0.3);
        let m = Vec3::new(0.05, 0.02, 1.0).normalize();
        let g = Masking::SmithCorrelated.g(&d, i, o, m);
        let (li, lo) = (d.lambda(i), d.lambda(o));
        assert!((g - beta(1.0 + li, 1.0 + lo)).abs() < 1e-14);
        assert_eq!(Masking::VCavity.g(&d, i, o, m), 0.0);
    }

    #[test]
    fn parse_lists_valid_names() {
        let e = Masking::parse("smiht").unwrap_err().to_string();
        assert!(
            e.contains("smith, smith-correlated, v-cavity, kelemen"),
            "{e}"
        );
    }
}
