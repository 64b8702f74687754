//! A parametric model family for fitting: its parameters with bounds, a starting point,
//! and predictions of f on a set of direction pairs.
//!
//! The optimizer works on unconstrained variables u; each parameter p ∈ (lo, hi) is
//! p = lo + (hi − lo)/(1 + e^{−u}), so that every trial point is a valid material (a
//! Levenberg–Marquardt step can never leave the domain, e.g. give n_i < 1).

use super::samples::FitSample;
use facette_bsdf::{ParamError, Spectrum};

/// One fitted parameter.
#[derive(Clone, Debug)]
pub struct Parameter {
    pub name: &'static str,
    pub unit: &'static str,
    pub lo: f64,
    pub hi: f64,
}

impl Parameter {
    pub const fn new(name: &'static str, unit: &'static str, lo: f64, hi: f64) -> Self {
        Parameter { name, unit, lo, hi }
    }

    /// Unconstrained variable → parameter.
    pub fn from_free(&self, u: f64) -> f64 {
        self.lo + (self.hi - self.lo) / (1.0 + (-u).exp())
    }

    /// Parameter → unconstrained variable (the value is first pulled inside the bounds).
    pub fn to_free(&self, p: f64) -> f64 {
        let t = ((p - self.lo) / (self.hi - self.lo)).clamp(1e-6, 1.0 - 1e-6);
        (t / (1.0 - t)).ln()
    }
}

/// A model family that can be fitted.
pub trait ModelFamily: Send + Sync {
    /// Name used on the command line and in reports.
    fn name(&self) -> String;

    /// The parameters, in the order of parameter vectors.
    fn parameters(&self) -> Vec<Parameter>;

    /// Starting points: the optimizer runs from each and keeps the best. `diffuse` is a
    /// rough estimate of the diffuse reflectance per channel from the data.
    fn starts(&self, diffuse: Spectrum) -> Vec<Vec<f64>>;

    /// f(i, o) for every sample, for parameters `p`.
    fn predict(&self, p: &[f64], samples: &[FitSample]) -> Result<Vec<Spectrum>, ParamError>;

    /// The fitted material as a `--material` TOML table where the library has the model
    /// as a material type.
    fn material_toml(&self, p: &[f64]) -> Option<String>;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounded_parameters_round_trip() {
        let p = Parameter::new("ni", "", 1.0, 3.0);
        for v in [1.01, 1.5, 2.99] {
            assert!((p.from_free(p.to_free(v)) - v).abs() < 1e-9);
        }
        assert!(p.from_free(-1e3) >= 1.0 && p.from_free(1e3) <= 3.0);
    }
}
