//! Fitting a model family to measured samples by nonlinear least squares
//! (Levenberg–Marquardt, [`crate::least_squares`]), from each of the family's starting
//! points, keeping the best.
//!
//! Error metrics (one residual per sample and colour channel):
//! - `log` (default): r = ln(1 + f̂ cos θ_i) − ln(1 + f cos θ_i) — the compressive metric of
//!   Löw et al. 2012 ("BRDF models for accurate and efficient rendering of glossy
//!   surfaces"). Reflected radiance is f cos θ_i; the logarithm keeps the specular peak
//!   (f up to 10²–10³ 1/sr for glossy MERL materials) from swamping the diffuse part,
//!   while the 1 + keeps near-zero values from dominating the way a plain ln f would.
//!   Multiplicative measurement noise becomes additive and of similar size everywhere.
//! - `cosine`: r = (f̂ − f) cos θ_i — the plain radiance error; it fits the highlight
//!   first and the diffuse part only where the highlight leaves room.

use super::family::{ModelFamily, Parameter};
use super::samples::{diffuse_estimate, FitSample};
use crate::least_squares::minimize;
use facette_bsdf::{ParamError, Spectrum};
use std::time::Instant;

/// The residual of one value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorMetric {
    Log,
    Cosine,
}

impl ErrorMetric {
    pub const NAMES: &'static [&'static str] = &["log", "cosine"];

    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "log" => Some(ErrorMetric::Log),
            "cosine" | "cos" => Some(ErrorMetric::Cosine),
            _ => None,
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            ErrorMetric::Log => "log: ln(1 + f̂ cos θ_i) − ln(1 + f cos θ_i)",
            ErrorMetric::Cosine => "cosine: (f̂ − f) cos θ_i",
        }
    }

    #[inline]
    fn residual(&self, predicted: f64, measured: f64, cos_i: f64) -> f64 {
        match self {
            ErrorMetric::Log => (predicted * cos_i).ln_1p() - (measured * cos_i).ln_1p(),
            ErrorMetric::Cosine => (predicted - measured) * cos_i,
        }
    }
}

/// The outcome of a fit.
#[derive(Clone, Debug)]
pub struct FitReport {
    pub family: String,
    pub parameters: Vec<Parameter>,
    pub values: Vec<f64>,
    pub metric: ErrorMetric,
    /// Root mean square of the residuals at the solution.
    pub rms_residual: f64,
    /// Root mean square relative error |f̂ − f|/f over values with f > 10⁻³ 1/sr.
    pub rms_relative_error: f64,
    pub samples: usize,
    /// Residual evaluations of the Levenberg–Marquardt iterations, all starts (the
    /// finite-difference Jacobians come on top).
    pub evaluations: usize,
    pub seconds: f64,
    pub converged: bool,
}

impl FitReport {
    pub fn value(&self, name: &str) -> Option<f64> {
        self.parameters
            .iter()
            .position(|p| p.name == name)
            .map(|k| self.values[k])
    }
}

fn residuals(
    family: &dyn ModelFamily,
    p: &[f64],
    samples: &[FitSample],
    metric: ErrorMetric,
) -> Result<Vec<f64>, ParamError> {
    let pred = family.predict(p, samples)?;
    let mut r = Vec::with_capacity(3 * samples.len());
    for (s, f) in samples.iter().zip(&pred) {
        for c in 0..3 {
            r.push(metric.residual(f[c], s.f[c], s.i.z));
        }
    }
    Ok(r)
}

/// Fits `family` to `samples`.
pub fn fit(
    family: &dyn ModelFamily,
    samples: &[FitSample],
    metric: ErrorMetric,
) -> Result<FitReport, ParamError> {
    if samples.len() < 10 {
        return Err(ParamError::Invalid(format!(
            "only {} valid measured values to fit (need at least 10)",
            samples.len()
        )));
    }
    let start = Instant::now();
    let params = family.parameters();
    let to_params =
        |u: &[f64]| -> Vec<f64> { params.iter().zip(u).map(|(p, &x)| p.from_free(x)).collect() };
    let mut best: Option<(f64, Vec<f64>, bool)> = None;
    let mut evaluations = 0;
    for s in family.starts(diffuse_estimate(samples)) {
        // Fail early and clearly where the family cannot be evaluated at all.
        residuals(family, &s, samples, metric)?;
        let u0: Vec<f64> = params.iter().zip(&s).map(|(p, &v)| p.to_free(v)).collect();
        let out = minimize(&u0, |u| {
            residuals(family, &to_params(u), samples, metric)
                .unwrap_or_else(|_| vec![f64::NAN; 3 * samples.len()])
        });
        evaluations += out.evaluations;
        let p = to_params(&out.params);
        let r = residuals(family, &p, samples, metric)?;
        let ss: f64 = r.iter().map(|v| v * v).sum();
        if ss.is_finite() && best.as_ref().is_none_or(|b| ss < b.0) {
            best = Some((ss, p, out.converged));
        }
    }
    let (ss, values, converged) =
        best.ok_or_else(|| ParamError::Invalid("the fit found no finite solution".into()))?;
    let pred = family.predict(&values, samples)?;
    let (mut rel, mut n) = (0.0, 0usize);
    for (s, f) in samples.iter().zip(&pred) {
        for c in 0..3 {
            if s.f[c] > 1e-3 {
                rel += ((f[c] - s.f[c]) / s.f[c]).powi(2);
                n += 1;
            }
        }
    }
    Ok(FitReport {
        family: family.name(),
        parameters: params,
        values,
        metric,
        rms_residual: (ss / (3 * samples.len()) as f64).sqrt(),
        rms_relative_error: (rel / n.max(1) as f64).sqrt(),
        samples: samples.len(),
        evaluations,
        seconds: start.elapsed().as_secs_f64(),
        converged,
    })
}

/// Predictions of a fitted family at arbitrary direction pairs.
pub fn predict_at(
    family: &dyn ModelFamily,
    values: &[f64],
    pairs: &[(facette_bsdf::Vec3, facette_bsdf::Vec3)],
) -> Result<Vec<Spectrum>, ParamError> {
    let pts: Vec<FitSample> = pairs
        .iter()
        .map(|&(i, o)| FitSample {
            i,
            o,
            f: Spectrum::ZERO,
        })
        .collect();
    family.predict(values, &pts)
}
