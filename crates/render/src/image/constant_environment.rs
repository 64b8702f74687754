//! A uniform environment: the same radiance from every direction (the white furnace, a
//! plain grey studio), sampled uniformly over the sphere. The same interface as
//! [`EnvironmentMap`](super::environment::EnvironmentMap) so the light code can treat both
//! alike (Mitsuba 3's `constant` emitter plays this role).

use std::f64::consts::PI;

use facette_bsdf::math::warp::square_to_uniform_sphere;
use facette_bsdf::{ParamError, ParamResult, Spectrum};
use glam::{DVec2, DVec3};

use super::environment::EnvSample;

const INV_FOUR_PI: f64 = 0.25 / PI;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstantEnvironment {
    radiance: Spectrum,
}

impl ConstantEnvironment {
    /// Radiance must be finite and non-negative.
    pub fn new(radiance: Spectrum) -> ParamResult<Self> {
        if !radiance.is_finite() || radiance.has_negative() {
            return Err(ParamError::OutOfRange {
                name: "radiance".into(),
                value: radiance.min_component(),
                expected: "finite values ≥ 0".into(),
            });
        }
        Ok(ConstantEnvironment { radiance })
    }

    /// The radiance, whatever the direction (black for a zero or non-finite `d`, like the
    /// map).
    #[inline]
    pub fn eval(&self, d: DVec3) -> Spectrum {
        if d.is_finite() && d.length_squared() > 0.0 {
            self.radiance
        } else {
            Spectrum::ZERO
        }
    }

    /// 1/4π for every valid direction.
    #[inline]
    pub fn pdf(&self, d: DVec3) -> f64 {
        if d.is_finite() && d.length_squared() > 0.0 {
            INV_FOUR_PI
        } else {
            0.0
        }
    }

    /// A uniform direction on the sphere. `None` only for a black environment (nothing to
    /// sample), like [`EnvironmentMap::sample`](super::environment::EnvironmentMap::sample).
    #[inline]
    pub fn sample(&self, u: DVec2) -> Option<EnvSample> {
        if self.radiance.is_black() {
            return None;
        }
        let u = DVec2::new(
            if u.x.is_finite() {
                u.x.clamp(0.0, 1.0)
            } else {
                0.0
            },
            if u.y.is_finite() {
                u.y.clamp(0.0, 1.0)
            } else {
                0.0
            },
        );
        let direction = square_to_uniform_sphere(u);
        Some(EnvSample {
            direction,
            radiance: self.radiance,
            pdf: INV_FOUR_PI,
        })
    }

    pub fn mean_radiance(&self) -> Spectrum {
        self.radiance
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use facette_bsdf::math::rng::{Pcg32, RandomSource};
    use facette_bsdf::validation::{chi2_test, Chi2Config, SphereMap};

    #[test]
    fn uniform_sampling_passes_chi_square() {
        let env = ConstantEnvironment::new(Spectrum::rgb(1.0, 2.0, 3.0)).unwrap();
        let cfg = Chi2Config {
            samples: 200_000,
            ..Default::default()
        };
        let out = chi2_test(
            &SphereMap::standard(),
            &cfg,
            |rng| env.sample(rng.next_2d()).map(|s| s.direction),
            |d| env.pdf(d),
        );
        assert!(out.passes(0.01), "{}", out.summary());
        let mut rng = Pcg32::new(3, 0);
        let s = env.sample(rng.next_2d()).unwrap();
        assert_eq!(s.radiance, env.eval(s.direction));
        assert_eq!(s.pdf, env.pdf(s.direction));
        assert!(ConstantEnvironment::new(Spectrum::splat(-1.0)).is_err());
        assert!(ConstantEnvironment::new(Spectrum::ZERO)
            .unwrap()
            .sample(DVec2::splat(0.5))
            .is_none());
    }
}
