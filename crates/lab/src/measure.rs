//! A virtual gonioreflectometer: a facette material written as a MERL file, so that fits,
//! plots and external tools can be checked on data whose true model is known.

use crate::merl::MerlBrdf;
use facette_bsdf::math::rng::{mix_seed, Pcg32};
use facette_bsdf::{Bsdf, BsdfContext};

/// Estimates per bin of a stochastic material (the IL body term in stochastic mode): the
/// file holds their mean, so its noise is that of a 64-sample average.
const STOCHASTIC_SAMPLES: usize = 64;

/// f of `material` at every MERL bin centre (light direction i, view o; f(o, i) in facette's
/// argument order), with multiplicative Gaussian noise of relative standard deviation
/// `noise` when it is positive. Deterministic for a seed.
pub fn measure_material(material: &dyn Bsdf, noise: f64, seed: u64) -> MerlBrdf {
    let ctx = BsdfContext::RADIANCE;
    let m = MerlBrdf::from_fn(|k, i, o| {
        let mut rng = Pcg32::new(mix_seed(seed, k as u64), 7);
        Some(if !material.eval_is_deterministic() {
            material
                .eval_estimate(o, i, &ctx, STOCHASTIC_SAMPLES, &mut rng)
                .0
        } else {
            material.eval(o, i, &ctx, &mut rng)
        })
    });
    if noise > 0.0 {
        m.with_multiplicative_noise(noise, seed)
    } else {
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use facette_bsdf::recipe::{build_material, parse_inline_table};
    use std::f64::consts::FRAC_1_PI;

    #[test]
    fn a_lambertian_file_holds_albedo_over_pi_in_every_valid_bin() {
        let b = build_material(&parse_inline_table("{type=\"lambert\", reflectance=0.6}").unwrap())
            .unwrap();
        let m = measure_material(b.as_ref(), 0.0, 1);
        assert!(m.valid_bins() > 1_000_000, "{}", m.valid_bins());
        for k in (0..crate::merl::BINS).step_by(997) {
            if let Some(s) = m.bin(k) {
                for c in 0..3 {
                    // MERL stores values scaled per channel: allow for the float round trip.
                    assert!((s[c] - 0.6 * FRAC_1_PI).abs() < 1e-9, "{k}: {s:?}");
                }
            }
        }
        let noisy = measure_material(b.as_ref(), 0.05, 1);
        assert_eq!(noisy.valid_bins(), m.valid_bins());
        assert_ne!(noisy.bin(100_000), m.bin(100_000));
    }
}
