//! The measured values a fit uses: valid MERL bins with both directions at most
//! `max_theta` from the normal (grazing measurements are the least reliable and the
//! microfacet models' weakest part), a deterministic random subset of at most
//! `max_samples` bins (fixed seed), each with its bin-centre directions.

use crate::merl::{bin_centre, bin_indices, directions_from_angles, MerlBrdf, BINS};
use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::{Spectrum, Vec3};

/// One measured value.
#[derive(Clone, Copy, Debug)]
pub struct FitSample {
    /// Light direction.
    pub i: Vec3,
    /// View direction.
    pub o: Vec3,
    /// Measured f (1/sr).
    pub f: Spectrum,
}

/// Selects the fitting samples of a MERL BRDF.
pub fn select_samples(
    merl: &MerlBrdf,
    max_theta_deg: f64,
    max_samples: usize,
    seed: u64,
) -> Vec<FitSample> {
    let cos_max = max_theta_deg.to_radians().cos();
    let mut all: Vec<FitSample> = (0..BINS)
        .filter_map(|k| {
            let f = merl.bin(k)?;
            let (ih, id, ip) = bin_indices(k);
            let (th, td, pd) = bin_centre(ih, id, ip);
            let (i, o) = directions_from_angles(th, td, pd);
            (i.z >= cos_max && o.z >= cos_max).then_some(FitSample { i, o, f })
        })
        .collect();
    if all.len() > max_samples {
        // A partial Fisher–Yates shuffle with a fixed seed: the same subset every run.
        let mut rng = Pcg32::new(seed, 21);
        for k in 0..max_samples {
            let j = k + rng.next_below((all.len() - k) as u32) as usize;
            all.swap(k, j);
        }
        all.truncate(max_samples);
    }
    all
}

/// A rough diffuse reflectance per channel: π times the median of f over samples far from
/// the specular configuration (half vector more than 25° from the normal).
pub fn diffuse_estimate(samples: &[FitSample]) -> Spectrum {
    let mut out = Spectrum::splat(0.5);
    for c in 0..3 {
        let mut v: Vec<f64> = samples
            .iter()
            .filter(|s| (s.i + s.o).normalize().z < 25f64.to_radians().cos())
            .map(|s| s.f[c])
            .collect();
        if v.is_empty() {
            v = samples.iter().map(|s| s.f[c]).collect();
        }
        if v.is_empty() {
            continue;
        }
        v.sort_by(f64::total_cmp);
        out[c] = (std::f64::consts::PI * v[v.len() / 2]).clamp(0.02, 0.95);
    }
    out
}
