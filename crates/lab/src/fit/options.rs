//! The options of a fit by name, as `facette fit` and `facette.fit` (Python) take them: one
//! place turns names into a model family and an error metric, checks the ranges and runs
//! the fit on a MERL file, so both front ends accept the same values and print the same
//! errors.

use super::{
    fit, select_samples, ErrorMetric, FitReport, IlDistribution, IlFamily, IlFitEvaluation,
    KelemenFamily, ModelFamily, PlasticFamily,
};
use crate::merl::MerlBrdf;
use facette_bsdf::ParamError;

/// Model families a fit accepts.
pub const MODEL_NAMES: &[&str] = &["il", "plastic", "kelemen"];
/// IL body-term evaluations a fit accepts.
pub const IL_EVALUATION_NAMES: &[&str] = &["quadrature", "approx"];
/// Distributions of the plastic family.
pub const PLASTIC_DISTRIBUTION_NAMES: &[&str] = &["beckmann", "ggx"];

/// How to fit: the CLI's flags, with its defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct FitOptions {
    /// `il`, `plastic` or `kelemen`.
    pub model: String,
    /// `beckmann`, `ggx` or `gaussian` for il; `beckmann` or `ggx` for plastic.
    pub distribution: String,
    /// IL body term while fitting: `quadrature` or `approx`.
    pub il_evaluation: String,
    /// Microfacets of the IL quadrature (≥ 8).
    pub il_samples: usize,
    /// Error metric: `log` or `cosine`.
    pub error: String,
    /// Measured values used (a fixed random subset of the valid bins, ≥ 10).
    pub samples: usize,
    /// Bins with θ_i or θ_o above this angle (degrees, (10, 90]) are ignored.
    pub max_theta_deg: f64,
    /// Seed of the sample selection.
    pub seed: u64,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            model: "il".into(),
            distribution: "beckmann".into(),
            il_evaluation: "quadrature".into(),
            il_samples: 128,
            error: "log".into(),
            samples: 4000,
            max_theta_deg: 80.0,
            seed: 1,
        }
    }
}

/// A finished fit: the report, and the family it was fitted with (for plots and the
/// material description).
pub struct FittedModel {
    pub report: FitReport,
    pub family: Box<dyn ModelFamily>,
    /// Valid bins of the measured file, and the values the fit used.
    pub valid_bins: usize,
    pub used_samples: usize,
}

impl FittedModel {
    /// The fitted model as a facette material description (TOML inline table), where the
    /// family has one.
    pub fn material_toml(&self) -> Option<String> {
        self.family.material_toml(&self.report.values)
    }
}

fn unknown(what: &str, given: &str, valid: &[&str]) -> ParamError {
    ParamError::UnknownChoice {
        what: what.into(),
        given: given.into(),
        valid: valid.join(", "),
    }
}

impl FitOptions {
    /// Checks the numeric options (the names are checked by [`Self::family`] and
    /// [`Self::metric`]).
    pub fn check(&self) -> Result<(), ParamError> {
        if self.samples < 10 {
            return Err(ParamError::Invalid(format!(
                "samples = {}: must be at least 10",
                self.samples
            )));
        }
        if !(self.max_theta_deg > 10.0 && self.max_theta_deg <= 90.0) {
            return Err(ParamError::Invalid(format!(
                "max_theta = {}: expected (10, 90] degrees",
                self.max_theta_deg
            )));
        }
        Ok(())
    }

    /// The error metric named by `error`.
    pub fn metric(&self) -> Result<ErrorMetric, ParamError> {
        ErrorMetric::parse(&self.error)
            .ok_or_else(|| unknown("error metric", &self.error, ErrorMetric::NAMES))
    }

    /// The model family named by `model`, `distribution` and the IL evaluation options.
    pub fn family(&self) -> Result<Box<dyn ModelFamily>, ParamError> {
        Ok(match self.model.as_str() {
            "il" => {
                let d = IlDistribution::parse(&self.distribution).ok_or_else(|| {
                    unknown(
                        "distribution for il",
                        &self.distribution,
                        IlDistribution::NAMES,
                    )
                })?;
                let ev = match self.il_evaluation.as_str() {
                    "quadrature" => {
                        if self.il_samples < 8 {
                            return Err(ParamError::Invalid(format!(
                                "il_samples = {}: must be at least 8",
                                self.il_samples
                            )));
                        }
                        IlFitEvaluation::Quadrature(self.il_samples)
                    }
                    "approx" => IlFitEvaluation::Approx,
                    other => return Err(unknown("IL evaluation", other, IL_EVALUATION_NAMES)),
                };
                Box::new(IlFamily::new(d, ev))
            }
            "plastic" => Box::new(PlasticFamily {
                ggx: match self.distribution.as_str() {
                    "beckmann" => false,
                    "ggx" => true,
                    other => {
                        return Err(unknown(
                            "distribution for plastic",
                            other,
                            PLASTIC_DISTRIBUTION_NAMES,
                        ))
                    }
                },
            }),
            "kelemen" => Box::new(KelemenFamily::default()),
            other => return Err(unknown("model", other, MODEL_NAMES)),
        })
    }

    /// Fits the chosen model to a measured BRDF.
    pub fn fit(&self, merl: &MerlBrdf) -> Result<FittedModel, ParamError> {
        self.check()?;
        let metric = self.metric()?;
        let family = self.family()?;
        let samples = select_samples(merl, self.max_theta_deg, self.samples, self.seed);
        let report = fit(family.as_ref(), &samples, metric)?;
        Ok(FittedModel {
            report,
            family,
            valid_bins: merl.valid_bins(),
            used_samples: samples.len(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_names_list_the_valid_ones() {
        let o = FitOptions {
            model: "phong".into(),
            ..Default::default()
        };
        let e = o.family().err().unwrap().to_string();
        assert!(
            e.contains("phong") && e.contains("il, plastic, kelemen"),
            "{e}"
        );
        let o = FitOptions {
            model: "plastic".into(),
            distribution: "gaussian".into(),
            ..Default::default()
        };
        let e = o.family().err().unwrap().to_string();
        assert!(e.contains("beckmann, ggx"), "{e}");
        let o = FitOptions {
            error: "l2".into(),
            ..Default::default()
        };
        let e = o.metric().unwrap_err().to_string();
        assert!(e.contains("log, cosine"), "{e}");
        let o = FitOptions {
            max_theta_deg: f64::NAN,
            ..Default::default()
        };
        assert!(o.check().is_err());
        let o = FitOptions {
            samples: 3,
            ..Default::default()
        };
        assert!(o.check().unwrap_err().to_string().contains("at least 10"));
    }
}
