//! The numbers behind the BSDF plots: incidence-plane slices, polar lobes, hemisphere maps
//! and directional albedo, computed from any [`Bsdf`].
//!
//! Geometry: the light comes from i = (sin θ_i, 0, cos θ_i) (azimuth 0). An outgoing
//! direction in the incidence plane is given by a *signed* angle θ_o ∈ [−90°, 90°]:
//! positive on the mirror side (φ_o = 180°, where the specular peak sits at θ_o = θ_i),
//! negative on the light's side (backscattering, the retro-reflection at θ_o = −θ_i). For
//! transmission the same signed angle is measured from −n, positive on the forward
//! (refraction) side. Stochastic models are evaluated with `eval_estimate` over `samples`
//! independent estimates per point.

use facette_bsdf::math::rng::{mix_seed, Pcg32};
use facette_bsdf::math::spherical_direction;
use facette_bsdf::validation::bsdf_checks::directional_albedo;
use facette_bsdf::{Bsdf, BsdfContext, Spectrum, Vec3};
use rayon::prelude::*;

/// What a slice shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// f(i, o), 1/sr.
    F,
    /// f(i, o) |cos θ_o|: the scattered intensity per unit projected area (WMLT07 Fig. 2).
    FCosO,
    /// f(i, o) cos θ_i: the reflected radiance for unit irradiance normal to the beam
    /// (KSK01's radiance lobes).
    FCosI,
}

impl Quantity {
    pub const NAMES: &'static [&'static str] = &["f", "fcos", "fcos-i"];

    pub fn parse(s: &str) -> Option<Quantity> {
        match s {
            "f" => Some(Quantity::F),
            "fcos" | "fcos-o" => Some(Quantity::FCosO),
            "fcos-i" => Some(Quantity::FCosI),
            _ => None,
        }
    }

    /// Axis label with units.
    pub fn label(&self) -> &'static str {
        match self {
            Quantity::F => "f (1/sr)",
            Quantity::FCosO => "f·|cos θ_o| (1/sr)",
            Quantity::FCosI => "f·cos θ_i (1/sr)",
        }
    }
}

/// Which side of the surface the outgoing directions are on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    Reflection,
    Transmission,
}

/// The light direction for incidence angle θ_i (degrees; above 90 = from below).
pub fn light_direction(theta_i_deg: f64) -> Vec3 {
    spherical_direction(theta_i_deg.to_radians(), 0.0)
}

/// The outgoing direction of signed angle `theta_o_deg` in the incidence plane.
pub fn plane_direction(theta_o_deg: f64, side: Side) -> Vec3 {
    let t = theta_o_deg.clamp(-89.95, 89.95).to_radians();
    match side {
        Side::Reflection => Vec3::new(-t.sin(), 0.0, t.cos()),
        Side::Transmission => Vec3::new(-t.sin(), 0.0, -t.cos()),
    }
}

/// Evenly spaced signed angles over [−90°, 90°] (`n` ≥ 2 points).
pub fn signed_angles(n: usize) -> Vec<f64> {
    let n = n.max(2);
    (0..n)
        .map(|k| -90.0 + 180.0 * k as f64 / (n - 1) as f64)
        .collect()
}

/// A converged f(i, o) (mean of `samples` estimates for stochastic models).
pub fn eval_f(bsdf: &dyn Bsdf, wi: Vec3, wo: Vec3, samples: usize, seed: u64) -> Spectrum {
    let mut rng = Pcg32::new(seed, 3);
    bsdf.eval_estimate(wo, wi, &BsdfContext::RADIANCE, samples, &mut rng)
        .0
}

/// The quantity at one direction pair.
pub fn quantity_value(
    bsdf: &dyn Bsdf,
    q: Quantity,
    wi: Vec3,
    wo: Vec3,
    samples: usize,
    seed: u64,
) -> Spectrum {
    let f = eval_f(bsdf, wi, wo, samples, seed);
    match q {
        Quantity::F => f,
        Quantity::FCosO => f * wo.z.abs(),
        Quantity::FCosI => f * wi.z.abs(),
    }
}

/// An incidence-plane slice: (signed θ_o in degrees, value) at `angles`.
pub fn incidence_plane(
    bsdf: &dyn Bsdf,
    theta_i_deg: f64,
    side: Side,
    q: Quantity,
    angles: &[f64],
    samples: usize,
    seed: u64,
) -> Vec<(f64, Spectrum)> {
    let wi = light_direction(theta_i_deg);
    angles
        .par_iter()
        .enumerate()
        .map(|(k, &t)| {
            let wo = plane_direction(t, side);
            (
                t,
                quantity_value(bsdf, q, wi, wo, samples, mix_seed(seed, k as u64)),
            )
        })
        .collect()
}

/// A slice as a polar curve in the incidence plane: (x, z) = value · (−sin θ_o, ±cos θ_o),
/// so that the curve's distance from the origin is the value in that direction (x < 0 on
/// the mirror side, as seen with the light coming from the +x side).
pub fn polar_points(slice: &[(f64, f64)], side: Side) -> Vec<(f64, f64)> {
    slice
        .iter()
        .map(|&(t, v)| {
            let d = plane_direction(t, side);
            (v * d.x, v * d.z)
        })
        .collect()
}

/// Directional reflectance and transmittance (channel means) for light incident at each
/// angle of `thetas_deg`, estimated from the sampler with `samples` samples:
/// (θ_i, R, R's standard error, T, T's standard error).
pub fn albedo_curve(
    bsdf: &dyn Bsdf,
    thetas_deg: &[f64],
    samples: usize,
    seed: u64,
) -> Vec<(f64, Spectrum, Spectrum, Spectrum, Spectrum)> {
    thetas_deg
        .iter()
        .map(|&t| {
            let wi = light_direction(t.clamp(0.0, 89.9));
            let (r, rse, tr, tse) =
                directional_albedo(bsdf, wi, &BsdfContext::IMPORTANCE, samples, seed);
            (t, r, rse, tr, tse)
        })
        .collect()
}

/// Which channel of a spectrum a curve shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    Mean,
    R,
    G,
    B,
}

impl Channel {
    pub const NAMES: &'static [&'static str] = &["mean", "r", "g", "b"];

    pub fn parse(s: &str) -> Option<Channel> {
        match s {
            "mean" => Some(Channel::Mean),
            "r" | "red" => Some(Channel::R),
            "g" | "green" => Some(Channel::G),
            "b" | "blue" => Some(Channel::B),
            _ => None,
        }
    }

    pub fn pick(&self, s: Spectrum) -> f64 {
        match self {
            Channel::Mean => s.average(),
            Channel::R => s[0],
            Channel::G => s[1],
            Channel::B => s[2],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use facette_bsdf::models::Lambert;
    use facette_bsdf::two_sided::TwoSided;

    #[test]
    fn lambert_slice_is_flat_and_polar_is_a_circle() {
        let l = TwoSided::new(Lambert::new(Spectrum::splat(0.5)).unwrap());
        let angles = signed_angles(7);
        let s = incidence_plane(&l, 30.0, Side::Reflection, Quantity::F, &angles, 1, 1);
        for (_, v) in &s {
            assert!((v[0] - 0.5 / std::f64::consts::PI).abs() < 1e-12);
        }
        // f cos θ_o of a Lambertian surface: a circle through the origin, tangent to the surface.
        let s = incidence_plane(&l, 30.0, Side::Reflection, Quantity::FCosO, &angles, 1, 1);
        let pts: Vec<(f64, f64)> = s.iter().map(|(t, v)| (*t, v[0])).collect();
        let r = 0.5 / std::f64::consts::PI / 2.0;
        for (x, z) in polar_points(&pts, Side::Reflection) {
            assert!((x * x + (z - r) * (z - r)).sqrt() - r < 1e-9);
        }
        // Mirror side is positive θ_o: the mirror direction of i.
        let m = plane_direction(30.0, Side::Reflection);
        let i = light_direction(30.0);
        assert!((m.x + i.x).abs() < 1e-12 && (m.z - i.z).abs() < 1e-12);
        let a = albedo_curve(&l, &[0.0, 60.0], 4000, 1);
        assert!((a[1].1[0] - 0.5).abs() < 1e-9 && a[1].3[0] == 0.0);
    }
}
