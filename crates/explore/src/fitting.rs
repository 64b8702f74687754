//! The fit view: a measured file (MERL) fitted by a model (`facette fit`'s families and
//! options, [`facette_lab::fit::FitOptions`]), answered with the fitted material, its
//! parameters and errors, and the incidence-plane slices at θ_i = 30° and 70° of the
//! measurement (nearest bin) and of the fit, per channel (IL18 Fig. 19's comparison).

use crate::frame::Frame;
use facette_lab::fit::driver::predict_at;
use facette_lab::fit::FitOptions;
use facette_lab::merl::MerlBrdf;
use facette_lab::plot::bsdf_data::{light_direction, plane_direction, signed_angles, Side};
use serde::Deserialize;
use serde_json::json;

/// A fit, with `facette fit`'s option names.
#[derive(Clone, Debug, Deserialize)]
pub struct FitRequest {
    /// The measured file's id (from its upload).
    pub measured: u64,
    pub model: String,
    pub distribution: String,
    #[serde(default = "approx")]
    pub il_evaluation: String,
    #[serde(default = "il_samples")]
    pub il_samples: usize,
    #[serde(default = "log")]
    pub error: String,
    #[serde(default = "samples")]
    pub samples: usize,
    #[serde(default = "max_theta")]
    pub max_theta: f64,
    #[serde(default = "seed")]
    pub seed: u64,
}

fn approx() -> String {
    "approx".into()
}
fn il_samples() -> usize {
    128
}
fn log() -> String {
    "log".into()
}
fn samples() -> usize {
    4000
}
fn max_theta() -> f64 {
    80.0
}
fn seed() -> u64 {
    1
}

/// Bounds of a fit request's sizes (a fit cannot be interrupted once it runs).
pub const MAX_IL_SAMPLES: usize = 1 << 12;
pub const MAX_SAMPLES: usize = 100_000;

impl FitRequest {
    /// Checks the sizes (the names and the other ranges are [`FitOptions::check`]'s).
    pub fn check(&self) -> Result<(), String> {
        if !(8..=MAX_IL_SAMPLES).contains(&self.il_samples) {
            return Err(format!(
                "`il_samples` = {} is out of range: expected 8 <= il_samples <= {MAX_IL_SAMPLES}",
                self.il_samples
            ));
        }
        if !(10..=MAX_SAMPLES).contains(&self.samples) {
            return Err(format!(
                "`samples` = {} is out of range: expected 10 <= samples <= {MAX_SAMPLES}",
                self.samples
            ));
        }
        self.options().check().map_err(|e| e.to_string())
    }

    pub fn options(&self) -> FitOptions {
        FitOptions {
            model: self.model.clone(),
            distribution: self.distribution.clone(),
            il_evaluation: self.il_evaluation.clone(),
            il_samples: self.il_samples,
            error: self.error.clone(),
            samples: self.samples,
            max_theta_deg: self.max_theta,
            seed: self.seed,
        }
    }
}

/// The incidence angles of the comparison slices.
pub const SLICE_THETAS: [f64; 2] = [30.0, 70.0];

/// Fits and answers the frame: fields `material` (the fitted TOML, when the family has
/// one), `family`, `parameters` ([{name, value, unit}]), `rms_residual`,
/// `rms_relative_error`, `seconds`, `converged`; arrays `theta_o` and, for each θ_i of
/// [`SLICE_THETAS`], `measured_{θ}_{r,g,b}` (NaN where the bin is invalid) and
/// `fitted_{θ}_{r,g,b}`. The error is the fit's own message.
pub fn fit(merl: &MerlBrdf, q: &FitRequest) -> Result<Frame, String> {
    let options = q.options();
    let fitted = options.fit(merl).map_err(|e| e.to_string())?;
    let r = &fitted.report;
    let parameters: Vec<_> = r
        .parameters
        .iter()
        .zip(&r.values)
        .map(|(p, v)| json!({"name": p.name, "value": v, "unit": p.unit}))
        .collect();
    let mut frame = Frame::default()
        .field("material", fitted.material_toml())
        .field("family", r.family.clone())
        .field("parameters", parameters)
        .field("rms_residual", r.rms_residual)
        .field("rms_relative_error", r.rms_relative_error)
        .field("seconds", r.seconds)
        .field("converged", r.converged)
        .field("used_samples", fitted.used_samples)
        .field("valid_bins", fitted.valid_bins);
    let angles = signed_angles(179);
    frame = frame.array("theta_o", angles.clone());
    for t in SLICE_THETAS {
        let wi = light_direction(t);
        let pairs: Vec<_> = angles
            .iter()
            .map(|&a| (wi, plane_direction(a, Side::Reflection)))
            .collect();
        let predicted =
            predict_at(&*fitted.family, &r.values, &pairs).map_err(|e| e.to_string())?;
        for (c, name) in ["r", "g", "b"].iter().enumerate() {
            let measured = pairs
                .iter()
                .map(|&(i, o)| merl.lookup(i, o).map_or(f64::NAN, |v| v[c]))
                .collect();
            frame = frame
                .array(&format!("measured_{t}_{name}"), measured)
                .array(
                    &format!("fitted_{t}_{name}"),
                    predicted.iter().map(|f| f[c]).collect(),
                );
        }
    }
    Ok(frame)
}
