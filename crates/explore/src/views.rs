//! The numbers behind the app's views, for one material:
//!
//! - [`slice`]: f (or f·cos) in the incidence plane, reflection and transmission sides,
//!   over signed outgoing angles — the slice plot and the polar lobe (the app draws the
//!   polar curve from the same numbers);
//! - [`hemisphere`]: f over the projected disk of outgoing directions for a light at
//!   (θ_i, φ_i);
//! - [`albedo`]: directional reflectance and transmittance against θ_i, estimated from the
//!   material's sampler, with standard errors.
//!
//! Geometry is the lab's ([`facette_lab::plot::bsdf_data`]): the light comes from
//! i = (sin θ_i, 0, cos θ_i); a signed angle θ_o is positive on the mirror side. Values are
//! f(i, o) with i the light direction (radiance mode), as `facette eval` prints them.
//! Stochastic models average `samples` estimates per value and report the standard error;
//! deterministic ones report 0. Each computation polls its [`Cancel`] flag and gives up
//! (returns `None`) once the request is abandoned.

use crate::cancel::Cancel;
use crate::frame::Frame;
use facette_bsdf::math::rng::{mix_seed, Pcg32};
use facette_bsdf::math::spherical_direction;
use facette_bsdf::validation::bsdf_checks::directional_albedo;
use facette_bsdf::{Bsdf, BsdfContext, LobeFlags, Vec3};
use facette_lab::plot::bsdf_data::{light_direction, plane_direction, signed_angles, Side};
use rayon::prelude::*;
use serde::Deserialize;

/// What a value shows.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Quantity {
    /// f(i, o), 1/sr.
    #[default]
    F,
    /// f(i, o) |cos θ_o|.
    Fcos,
}

impl Quantity {
    fn weight(self, wo: Vec3) -> f64 {
        match self {
            Quantity::F => 1.0,
            Quantity::Fcos => wo.z.abs(),
        }
    }
}

fn default_seed() -> u64 {
    1
}
fn default_samples() -> usize {
    64
}

/// Bounds every request's sizes are checked against (a request is refused outside them).
pub const MAX_POINTS: usize = 4001;
pub const MAX_GRID: usize = 512;
pub const MAX_SAMPLES: usize = 1 << 20;

fn check(name: &str, v: f64, lo: f64, hi: f64) -> Result<(), String> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(format!(
            "`{name}` = {v} is out of range: expected {lo} <= {name} <= {hi}"
        ))
    }
}

/// An incidence-plane slice.
#[derive(Clone, Debug, Deserialize)]
pub struct SliceRequest {
    pub material: String,
    /// Light elevation, degrees in [0, 180] (above 90: from below).
    pub theta_i: f64,
    /// Outgoing angles over [−90°, 90°].
    pub points: usize,
    #[serde(default)]
    pub quantity: Quantity,
    /// Estimates per value of a stochastic model.
    #[serde(default = "default_samples")]
    pub samples: usize,
    #[serde(default = "default_seed")]
    pub seed: u64,
}

impl SliceRequest {
    pub fn check(&self) -> Result<(), String> {
        check("theta_i", self.theta_i, 0.0, 180.0)?;
        check("points", self.points as f64, 2.0, MAX_POINTS as f64)?;
        check("samples", self.samples as f64, 1.0, MAX_SAMPLES as f64)
    }
}

/// Fields every view reports about its material. `stochastic` says whether a value is an
/// average of `samples` estimates (the page then draws ±2 standard errors), i.e. whether
/// `eval` is random — not whether `sample` is: IL wholly by quadrature evaluates
/// deterministically while its sampler still walks.
fn describe(frame: Frame, bsdf: &dyn Bsdf, text: &str) -> Frame {
    frame
        .field("material", text)
        .field("describe", bsdf.describe())
        .field("stochastic", !bsdf.eval_is_deterministic())
        .field(
            "transmits",
            bsdf.flags().intersects(LobeFlags::TRANSMISSION),
        )
}

/// f (or f·|cos θ_o|) and its standard error at `wo` for light from `wi`, per channel.
fn value(bsdf: &dyn Bsdf, wi: Vec3, wo: Vec3, q: Quantity, samples: usize, seed: u64) -> [f64; 6] {
    let n = if bsdf.eval_is_deterministic() {
        1
    } else {
        samples
    };
    let mut rng = Pcg32::new(seed, 3);
    let (f, se) = bsdf.eval_estimate(wo, wi, &BsdfContext::RADIANCE, n, &mut rng);
    let w = q.weight(wo);
    [
        f[0] * w,
        f[1] * w,
        f[2] * w,
        se[0] * w,
        se[1] * w,
        se[2] * w,
    ]
}

const CHANNELS: [&str; 3] = ["r", "g", "b"];

/// Arrays `{prefix}_{r,g,b}` and `{prefix}_err_{r,g,b}` from rows of [`value`].
fn channel_arrays(mut frame: Frame, prefix: &str, rows: &[[f64; 6]]) -> Frame {
    for (c, name) in CHANNELS.iter().enumerate() {
        frame = frame.array(
            &format!("{prefix}_{name}"),
            rows.iter().map(|r| r[c]).collect(),
        );
    }
    for (c, name) in CHANNELS.iter().enumerate() {
        frame = frame.array(
            &format!("{prefix}_err_{name}"),
            rows.iter().map(|r| r[3 + c]).collect(),
        );
    }
    frame
}

/// Rows computed in parallel, `None` once cancelled.
fn rows(n: usize, cancel: &Cancel, f: impl Fn(usize) -> [f64; 6] + Sync) -> Option<Vec<[f64; 6]>> {
    let rows: Vec<Option<[f64; 6]>> = (0..n)
        .into_par_iter()
        .map(|k| (!cancel.is_cancelled()).then(|| f(k)))
        .collect();
    rows.into_iter().collect()
}

/// The incidence-plane slice: arrays `theta_o` (signed, degrees), `reflect_*` and
/// `transmit_*` (see [`channel_arrays`]).
pub fn slice(bsdf: &dyn Bsdf, text: &str, q: &SliceRequest, cancel: &Cancel) -> Option<Frame> {
    let angles = signed_angles(q.points);
    let wi = light_direction(q.theta_i);
    let side_rows = |side: Side, stream: u64| {
        rows(angles.len(), cancel, |k| {
            let wo = plane_direction(angles[k], side);
            value(
                bsdf,
                wi,
                wo,
                q.quantity,
                q.samples,
                mix_seed(q.seed, 2 * k as u64 + stream),
            )
        })
    };
    let reflect = side_rows(Side::Reflection, 0)?;
    let transmit = if bsdf.flags().intersects(LobeFlags::TRANSMISSION) {
        side_rows(Side::Transmission, 1)?
    } else {
        vec![[0.0; 6]; angles.len()]
    };
    let frame = describe(Frame::default(), bsdf, text)
        .field("theta_i", q.theta_i)
        .array("theta_o", angles);
    let frame = channel_arrays(frame, "reflect", &reflect);
    Some(channel_arrays(frame, "transmit", &transmit))
}

/// A hemisphere map.
#[derive(Clone, Debug, Deserialize)]
pub struct HemisphereRequest {
    pub material: String,
    pub theta_i: f64,
    #[serde(default)]
    pub phi_i: f64,
    /// Cells per side of the projected disk.
    pub n: usize,
    /// Outgoing directions below the surface (transmission) instead of above.
    #[serde(default)]
    pub transmission: bool,
    #[serde(default)]
    pub quantity: Quantity,
    #[serde(default = "default_samples")]
    pub samples: usize,
    #[serde(default = "default_seed")]
    pub seed: u64,
}

impl HemisphereRequest {
    pub fn check(&self) -> Result<(), String> {
        check("theta_i", self.theta_i, 0.0, 180.0)?;
        check("phi_i", self.phi_i, -360.0, 360.0)?;
        check("n", self.n as f64, 2.0, MAX_GRID as f64)?;
        check("samples", self.samples as f64, 1.0, MAX_SAMPLES as f64)
    }
}

/// The outgoing direction at the centre of cell `k` of an n × n grid over the projected
/// disk (row 0 at y = −1), or `None` outside the disk.
pub fn cell_direction(n: usize, k: usize, transmission: bool) -> Option<Vec3> {
    let (x, y) = facette_lab::plot::hemisphere_map::HemisphereMap::cell_centre(n, k);
    let r2 = x * x + y * y;
    (r2 < 1.0).then(|| {
        let z = (1.0 - r2).sqrt();
        Vec3::new(x, y, if transmission { -z } else { z })
    })
}

/// The map: arrays `value_{r,g,b}` and `value_err_{r,g,b}`, n² each, row-major; NaN
/// outside the disk.
pub fn hemisphere(
    bsdf: &dyn Bsdf,
    text: &str,
    q: &HemisphereRequest,
    cancel: &Cancel,
) -> Option<Frame> {
    let wi = spherical_direction(q.theta_i.to_radians(), q.phi_i.to_radians());
    let values = rows(q.n * q.n, cancel, |k| {
        match cell_direction(q.n, k, q.transmission) {
            Some(wo) => value(
                bsdf,
                wi,
                wo,
                q.quantity,
                q.samples,
                mix_seed(q.seed, k as u64),
            ),
            None => [f64::NAN; 6],
        }
    })?;
    let frame = describe(Frame::default(), bsdf, text)
        .field("theta_i", q.theta_i)
        .field("phi_i", q.phi_i)
        .field("n", q.n)
        .field("transmission", q.transmission);
    Some(channel_arrays(frame, "value", &values))
}

/// Directional albedo against θ_i.
#[derive(Clone, Debug, Deserialize)]
pub struct AlbedoRequest {
    pub material: String,
    /// Incidence angles, degrees in [0, 89.9].
    pub angles: Vec<f64>,
    /// Sampled directions per angle.
    pub samples: usize,
    #[serde(default = "default_seed")]
    pub seed: u64,
}

impl AlbedoRequest {
    pub fn check(&self) -> Result<(), String> {
        check("angles (count)", self.angles.len() as f64, 1.0, 361.0)?;
        for &a in &self.angles {
            check("angles", a, 0.0, 89.9)?;
        }
        check("samples", self.samples as f64, 16.0, MAX_SAMPLES as f64)
    }
}

/// Arrays `theta_i`, `reflect`, `reflect_err`, `transmit`, `transmit_err` (channel means).
pub fn albedo(bsdf: &dyn Bsdf, text: &str, q: &AlbedoRequest, cancel: &Cancel) -> Option<Frame> {
    let mut out = [vec![], vec![], vec![], vec![]];
    for &t in &q.angles {
        if cancel.is_cancelled() {
            return None;
        }
        let wi = light_direction(t);
        let (r, rse, tr, tse) =
            directional_albedo(bsdf, wi, &BsdfContext::IMPORTANCE, q.samples, q.seed);
        for (o, s) in out.iter_mut().zip([r, rse, tr, tse]) {
            o.push(s.average());
        }
    }
    let [r, rse, tr, tse] = out;
    Some(
        describe(Frame::default(), bsdf, text)
            .field("samples", q.samples)
            .array("theta_i", q.angles.clone())
            .array("reflect", r)
            .array("reflect_err", rse)
            .array("transmit", tr)
            .array("transmit_err", tse),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::build;

    #[test]
    fn slice_values_are_the_materials_eval() {
        let m =
            build(r#"{type = "conductor", distribution = "ggx", alpha = 0.3, material = "Au"}"#)
                .unwrap();
        let q = SliceRequest {
            material: m.text.clone(),
            theta_i: 30.0,
            points: 7,
            quantity: Quantity::F,
            samples: 1,
            seed: 1,
        };
        let f = slice(&*m.bsdf, &m.text, &q, &Cancel::default()).unwrap();
        let theta = f.get("theta_o").unwrap();
        let wi = light_direction(30.0);
        let mut rng = Pcg32::new(1, 1);
        for (k, &t) in theta.iter().enumerate() {
            let wo = plane_direction(t, Side::Reflection);
            let e = m.bsdf.eval(wo, wi, &BsdfContext::RADIANCE, &mut rng);
            assert_eq!(f.get("reflect_g").unwrap()[k], e[1]);
            assert_eq!(f.get("transmit_g").unwrap()[k], 0.0);
        }
        assert_eq!(f.fields["transmits"], false);
    }

    #[test]
    fn stochastic_means_a_random_eval() {
        // IL with body and inter-reflections by quadrature: `sample` walks, `eval` does not.
        let il = r#"{type = "il", kd = 0.8, alpha = 0.5, scattering = "multiple", evaluation = "quadrature", multiple_evaluation = "quadrature", tolerance = 1e-3}"#;
        for (text, random) in [
            (il, false),
            (r#"{type = "il", kd = 0.8, alpha = 0.5}"#, true),
            (r#"{type = "lambert"}"#, false),
        ] {
            let m = build(text).unwrap();
            let q = SliceRequest {
                material: m.text.clone(),
                theta_i: 30.0,
                points: 3,
                quantity: Quantity::F,
                samples: 4,
                seed: 1,
            };
            let f = slice(&*m.bsdf, &m.text, &q, &Cancel::default()).unwrap();
            assert_eq!(f.fields["stochastic"], random, "{text}");
        }
    }

    #[test]
    fn a_cancelled_view_gives_up() {
        let m = build(r#"{type = "lambert"}"#).unwrap();
        let c = Cancel::default();
        c.cancel();
        let q = HemisphereRequest {
            material: m.text.clone(),
            theta_i: 10.0,
            phi_i: 0.0,
            n: 16,
            transmission: false,
            quantity: Quantity::F,
            samples: 1,
            seed: 1,
        };
        assert!(hemisphere(&*m.bsdf, &m.text, &q, &c).is_none());
        let f = hemisphere(&*m.bsdf, &m.text, &q, &Cancel::default()).unwrap();
        let v = f.get("value_r").unwrap();
        assert_eq!(v.len(), 256);
        assert!(v[0].is_nan(), "a corner is outside the disk");
        assert!((v[8 * 16 + 8] - 0.5 / std::f64::consts::PI).abs() < 1e-12);
    }

    #[test]
    fn albedo_of_a_white_lambert_is_one() {
        let m = build(r#"{type = "lambert", reflectance = 1.0}"#).unwrap();
        let q = AlbedoRequest {
            material: m.text.clone(),
            angles: vec![0.0, 60.0],
            samples: 256,
            seed: 1,
        };
        let f = albedo(&*m.bsdf, &m.text, &q, &Cancel::default()).unwrap();
        for r in f.get("reflect").unwrap() {
            assert!((r - 1.0).abs() < 1e-12, "{r}");
        }
        assert!(q.check().is_ok());
        let bad = AlbedoRequest {
            angles: vec![95.0],
            ..q
        };
        assert!(bad.check().unwrap_err().contains("angles"));
    }
}
