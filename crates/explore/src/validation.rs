//! The validation view: the material's `validate` checks (chi-square tests of its sampler
//! against its pdf, the energy bound, reciprocity, the NaN/Inf sweep — the same harness as
//! `facette validate --material`), with sample counts the app chooses, each line with its
//! measured figure and verdict. Stopped between steps when the request is abandoned.

use crate::cancel::Cancel;
use facette_bsdf::validation::bsdf_checks::{check_bsdf_watched, BsdfCheckOptions};
use facette_bsdf::validation::chi2::Chi2Config;
use facette_bsdf::validation::Report;
use facette_bsdf::Bsdf;
use serde::Deserialize;
use serde_json::{json, Value};

/// A validation run.
#[derive(Clone, Debug, Deserialize)]
pub struct ValidateRequest {
    pub material: String,
    /// Samples per chi-square test (the other checks scale with it).
    pub samples: usize,
    #[serde(default = "seven")]
    pub seed: u64,
}

fn seven() -> u64 {
    7
}

/// The sample counts a run may ask for (`facette validate` takes 1,000 and up).
pub const SAMPLES: (usize, usize) = (1000, 4_000_000);

impl ValidateRequest {
    pub fn check(&self) -> Result<(), String> {
        if (SAMPLES.0..=SAMPLES.1).contains(&self.samples) {
            Ok(())
        } else {
            Err(format!(
                "`samples` = {} is out of range: expected {} <= samples <= {}",
                self.samples, SAMPLES.0, SAMPLES.1
            ))
        }
    }

    /// The harness's options: chi-square at `samples`, the sweep and the albedo at the
    /// same count, the rest at the harness's defaults scaled down in proportion.
    pub fn options(&self) -> BsdfCheckOptions {
        let d = BsdfCheckOptions::default();
        let scale = self.samples as f64 / d.chi2.samples as f64;
        let scaled = |n: usize, min: usize| ((n as f64 * scale) as usize).max(min);
        BsdfCheckOptions {
            chi2: Chi2Config {
                samples: self.samples,
                seed: self.seed,
                ..d.chi2
            },
            sweep: self.samples,
            albedo_samples: self.samples,
            consistency_samples: scaled(d.consistency_samples, 1000),
            reciprocity_pairs: scaled(d.reciprocity_pairs, 200),
            ..d
        }
    }
}

/// `{"lines": [{"verdict", "subject", "name", "figure"}…], "passed", "failed",
/// "summary"}`, or `None` once cancelled.
pub fn validate(bsdf: &dyn Bsdf, q: &ValidateRequest, cancel: &Cancel) -> Option<Value> {
    let checks = check_bsdf_watched(bsdf, &q.options(), &|_, _| !cancel.is_cancelled());
    if cancel.is_cancelled() {
        return None;
    }
    let mut report = Report::new();
    report.extend(checks);
    let lines: Vec<Value> = report
        .checks
        .iter()
        .map(|c| {
            let verdict = match report.judge(c) {
                Some(true) => "PASS",
                Some(false) => "FAIL",
                None => "INFO",
            };
            json!({"verdict": verdict, "subject": c.subject, "name": c.name, "figure": c.figure})
        })
        .collect();
    Some(json!({
        "material": bsdf.describe(),
        "lines": lines,
        "passed": report.passed(),
        "failed": report.failed(),
        "summary": report.summary_line(),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::build;

    #[test]
    fn a_sound_material_passes_and_cancelling_stops() {
        let m = build(r#"{type = "conductor", distribution = "ggx", alpha = 0.4}"#).unwrap();
        let q = ValidateRequest {
            material: m.text.clone(),
            samples: 20_000,
            seed: 7,
        };
        let v = validate(&*m.bsdf, &q, &Cancel::default()).unwrap();
        assert_eq!(v["failed"], 0, "{v}");
        assert!(v["lines"].as_array().unwrap().len() > 5);
        let c = Cancel::default();
        c.cancel();
        assert!(validate(&*m.bsdf, &q, &c).is_none());
        assert!(ValidateRequest { samples: 10, ..q }.check().is_err());
    }
}
