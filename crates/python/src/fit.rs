//! `facette.fit` and `facette.measure`: fitting models to measured MERL BRDFs, and writing
//! a material as a MERL file — the `facette fit` and `facette measure` commands.

use crate::errors::{os_error, value_error};
use crate::interrupt::run_all;
use crate::material::Material;
use facette_lab::fit::slices::fit_slices;
use facette_lab::fit::FitOptions;
use facette_lab::measure::measure_material;
use facette_lab::merl::{MerlBrdf, MerlError};
use facette_lab::plot::{save_figure, Format};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

fn merl_error(e: MerlError) -> PyErr {
    match e {
        MerlError::Io { .. } => os_error(e),
        MerlError::Invalid { .. } => value_error(e),
    }
}

/// Fits `model` to the MERL file at `path` (the options of `facette fit`, same defaults);
/// returns a dict: `model`, `metric`, `parameters` {name: value}, `units` {name: unit},
/// `rms_residual`, `rms_relative_error`, `evaluations`, `seconds`, `converged`,
/// `material` (a TOML inline table or None), `valid_bins`, `samples`. With `output`, also
/// writes the measured-vs-fitted slices at θ_i = 30° and 70° (.svg or .png).
#[pyfunction]
#[pyo3(signature = (path, model = "il", distribution = "beckmann", il_evaluation = "quadrature",
    il_samples = 128, error = "log", samples = 4000, max_theta = 80.0, seed = 1, output = None,
    progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn fit<'py>(
    py: Python<'py>,
    path: PathBuf,
    model: &str,
    distribution: &str,
    il_evaluation: &str,
    il_samples: usize,
    error: &str,
    samples: usize,
    max_theta: f64,
    seed: u64,
    output: Option<PathBuf>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let options = FitOptions {
        model: model.into(),
        distribution: distribution.into(),
        il_evaluation: il_evaluation.into(),
        il_samples,
        error: error.into(),
        samples,
        max_theta_deg: max_theta,
        seed,
    };
    options.check().map_err(value_error)?;
    options.metric().map_err(value_error)?;
    options.family().map_err(value_error)?;
    if let Some(o) = &output {
        Format::of(o).map_err(value_error)?;
    }
    // The fit reports no progress of its own: `progress` sees (0, 1) until it ends.
    let fitted = run_all(py, "facette.fit", progress, move |c| -> PyResult<_> {
        c.set_total(1);
        let merl = MerlBrdf::load(&path).map_err(merl_error)?;
        let fitted = options
            .fit(&merl)
            .map_err(|e| value_error(format!("fit: {e}")))?;
        if let Some(o) = &output {
            let name = path
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("measured");
            let fig = fit_slices(
                &merl,
                fitted.family.as_ref(),
                &fitted.report.values,
                &format!("{name}: measured vs {} fit", options.model),
                &[30.0, 70.0],
            )
            .map_err(value_error)?;
            save_figure(&fig, o).map_err(os_error)?;
        }
        c.advance(1);
        Ok(fitted)
    })??;
    let r = &fitted.report;
    let d = PyDict::new(py);
    let parameters = PyDict::new(py);
    let units = PyDict::new(py);
    for (p, v) in r.parameters.iter().zip(&r.values) {
        parameters.set_item(p.name, *v)?;
        units.set_item(p.name, p.unit)?;
    }
    d.set_item("model", r.family.clone())?;
    d.set_item("metric", r.metric.name())?;
    d.set_item("parameters", parameters)?;
    d.set_item("units", units)?;
    d.set_item("rms_residual", r.rms_residual)?;
    d.set_item("rms_relative_error", r.rms_relative_error)?;
    d.set_item("evaluations", r.evaluations)?;
    d.set_item("seconds", r.seconds)?;
    d.set_item("converged", r.converged)?;
    d.set_item("material", fitted.material_toml())?;
    d.set_item("valid_bins", fitted.valid_bins)?;
    d.set_item("samples", fitted.used_samples)?;
    Ok(d)
}

/// Writes `material` as a MERL file at `path` (`facette measure`), with multiplicative
/// Gaussian noise of relative deviation `noise`; returns the number of valid bins.
#[pyfunction]
#[pyo3(signature = (material, path, noise = 0.0, seed = 1))]
pub fn measure(
    py: Python<'_>,
    material: &Material,
    path: PathBuf,
    noise: f64,
    seed: u64,
) -> PyResult<usize> {
    if !(noise.is_finite() && (0.0..=1.0).contains(&noise)) {
        return Err(value_error(format!(
            "noise = {noise}: expected a relative deviation in [0, 1]"
        )));
    }
    let bsdf = material.bsdf();
    run_all(py, "facette.measure", None, move |_| {
        let merl = measure_material(bsdf.as_ref(), noise, seed);
        merl.save(&path).map_err(merl_error)?;
        Ok(merl.valid_bins())
    })?
}
