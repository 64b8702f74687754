//! `facette.Material`: a material of the library on numpy arrays.

use crate::arrays::directions;
use crate::errors::value_error;
use crate::toml_value::table_from_py;
use facette_bsdf::math::rng::{mix_seed, Pcg32, RandomSource};
use facette_bsdf::math::spherical_direction;
use facette_bsdf::validation::bsdf_checks::{check_bsdf, directional_albedo, BsdfCheckOptions};
use facette_bsdf::validation::chi2::Chi2Config;
use facette_bsdf::validation::Report;
use facette_bsdf::{Bsdf, BsdfContext, TransportMode};
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Arc;

fn context(mode: &str) -> PyResult<BsdfContext> {
    Ok(BsdfContext {
        mode: match mode {
            "radiance" => TransportMode::Radiance,
            "importance" => TransportMode::Importance,
            other => {
                return Err(value_error(format!(
                    "unknown mode `{other}`; valid: radiance, importance"
                )))
            }
        },
    })
}

/// Replays user-supplied uniform numbers, then continues with a seeded stream.
struct ReplayRandom<'a> {
    given: &'a [f64],
    next: usize,
    rest: Pcg32,
}

impl RandomSource for ReplayRandom<'_> {
    fn next_f64(&mut self) -> f64 {
        if let Some(&u) = self.given.get(self.next) {
            self.next += 1;
            u
        } else {
            self.rest.next_f64()
        }
    }
}

/// A material: any type of docs/materials.md, from a TOML inline table or a dict.
#[pyclass(frozen, module = "facette._facette")]
pub struct Material {
    bsdf: Arc<dyn Bsdf>,
}

impl Material {
    /// The material's BSDF, shared.
    pub(crate) fn bsdf(&self) -> Arc<dyn Bsdf> {
        self.bsdf.clone()
    }
}

#[pymethods]
impl Material {
    #[new]
    fn new(spec: &Bound<'_, PyAny>) -> PyResult<Self> {
        let table = table_from_py(spec)?;
        let bsdf = facette_bsdf::recipe::build_material(&table).map_err(value_error)?;
        Ok(Material { bsdf })
    }

    /// The model and its parameters.
    #[getter]
    fn description(&self) -> String {
        self.bsdf.describe()
    }

    /// Whether `eval` is a stochastic (unbiased) estimate.
    #[getter]
    fn is_stochastic(&self) -> bool {
        self.bsdf.is_stochastic()
    }

    fn __repr__(&self) -> String {
        format!("Material({})", self.bsdf.describe())
    }

    /// f(wi, wo) without the cosine, per RGB channel, for rows of `wi` (toward the light)
    /// and `wo` (toward the viewer), both (N, 3) in the local frame (z = normal). Stochastic
    /// materials average `samples` estimates per row from one stream seeded by `seed` —
    /// the values `facette eval` prints for the same rows, seed and samples.
    #[pyo3(signature = (wi, wo, samples = 100_000, mode = "radiance", seed = 1))]
    fn eval<'py>(
        &self,
        py: Python<'py>,
        wi: PyReadonlyArray2<'py, f64>,
        wo: PyReadonlyArray2<'py, f64>,
        samples: usize,
        mode: &str,
        seed: u64,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let ctx = context(mode)?;
        let (wi, wo) = (directions(&wi, "wi")?, directions(&wo, "wo")?);
        if wi.len() != wo.len() {
            return Err(value_error(format!(
                "`wi` has {} rows and `wo` {}",
                wi.len(),
                wo.len()
            )));
        }
        if samples == 0 {
            return Err(value_error("`samples` must be at least 1"));
        }
        let bsdf = self.bsdf.clone();
        let out = py.detach(move || {
            let mut rng = Pcg32::new(seed, 0);
            let mut out = Array2::<f64>::zeros((wi.len(), 3));
            for k in 0..wi.len() {
                let (f, _) = bsdf.eval_estimate(wo[k], wi[k], &ctx, samples, &mut rng);
                for c in 0..3 {
                    out[[k, c]] = f[c];
                }
            }
            out
        });
        Ok(out.into_pyarray(py))
    }

    /// Solid-angle density with which `sample(wo)` draws `wi` (non-delta lobes), shape (N,).
    #[pyo3(signature = (wo, wi, mode = "radiance"))]
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        wo: PyReadonlyArray2<'py, f64>,
        wi: PyReadonlyArray2<'py, f64>,
        mode: &str,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let ctx = context(mode)?;
        let (wi, wo) = (directions(&wi, "wi")?, directions(&wo, "wo")?);
        if wi.len() != wo.len() {
            return Err(value_error(format!(
                "`wi` has {} rows and `wo` {}",
                wi.len(),
                wo.len()
            )));
        }
        let bsdf = self.bsdf.clone();
        let out = py
            .detach(move || Array1::from_iter((0..wi.len()).map(|k| bsdf.pdf(wo[k], wi[k], &ctx))));
        Ok(out.into_pyarray(py))
    }

    /// Draws a direction per row of `wo`: returns (wi (N, 3), weight = f·|cos θ_i|/pdf
    /// (N, 3), pdf (N,), lobe names (list)). `u`, when given, is an (N, K) array of uniform
    /// numbers in [0, 1) consumed in order by row k's sampler (a stream seeded by `seed`
    /// and k continues when a row needs more than K); a failed sample has weight 0, pdf 0
    /// and lobe "none".
    #[pyo3(signature = (wo, u = None, mode = "radiance", seed = 1))]
    #[allow(clippy::type_complexity)]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        wo: PyReadonlyArray2<'py, f64>,
        u: Option<PyReadonlyArray2<'py, f64>>,
        mode: &str,
        seed: u64,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
        Vec<String>,
    )> {
        let ctx = context(mode)?;
        let wo = directions(&wo, "wo")?;
        let u: Option<Array2<f64>> = match u {
            None => None,
            Some(a) => {
                let v = a.as_array();
                if v.nrows() != wo.len() {
                    return Err(value_error(format!(
                        "`u` has {} rows and `wo` {}",
                        v.nrows(),
                        wo.len()
                    )));
                }
                if v.iter().any(|x| !(0.0..1.0).contains(x)) {
                    return Err(value_error("`u` must hold numbers in [0, 1)"));
                }
                Some(v.to_owned())
            }
        };
        let bsdf = self.bsdf.clone();
        let (wis, weights, pdfs, lobes) = py.detach(move || {
            let n = wo.len();
            let mut wis = Array2::<f64>::zeros((n, 3));
            let mut weights = Array2::<f64>::zeros((n, 3));
            let mut pdfs = Array1::<f64>::zeros(n);
            let mut lobes = Vec::with_capacity(n);
            for k in 0..n {
                let row: Vec<f64> = u.as_ref().map(|a| a.row(k).to_vec()).unwrap_or_default();
                let mut rng = ReplayRandom {
                    given: &row,
                    next: 0,
                    rest: Pcg32::new(mix_seed(seed, k as u64), 0),
                };
                match bsdf.sample(wo[k], &ctx, &mut rng) {
                    Some(s) => {
                        for c in 0..3 {
                            wis[[k, c]] = s.wi[c];
                            weights[[k, c]] = s.weight[c];
                        }
                        pdfs[k] = s.pdf;
                        lobes.push(s.lobe.describe());
                    }
                    None => lobes.push("none".to_string()),
                }
            }
            (wis, weights, pdfs, lobes)
        });
        Ok((
            wis.into_pyarray(py),
            weights.into_pyarray(py),
            pdfs.into_pyarray(py),
            lobes,
        ))
    }

    /// Directional reflectance and transmittance for incidence angles `theta_i` (degrees,
    /// a list; 0–90 from above, 90–180 from below), with standard errors — the numbers of
    /// `facette albedo`. Returns a dict of (K, 3) arrays.
    #[pyo3(signature = (theta_i, samples = 1_000_000, seed = 1))]
    fn albedo<'py>(
        &self,
        py: Python<'py>,
        theta_i: Vec<f64>,
        samples: usize,
        seed: u64,
    ) -> PyResult<Bound<'py, PyDict>> {
        if samples < 100 {
            return Err(value_error("`samples` must be at least 100"));
        }
        for &t in &theta_i {
            if !(t.is_finite() && (0.0..=180.0).contains(&t)) || t == 90.0 {
                return Err(value_error(format!(
                    "theta_i = {t}: expected an angle in [0, 180] degrees other than 90"
                )));
            }
        }
        let bsdf = self.bsdf.clone();
        let rows = py.detach(move || {
            theta_i
                .iter()
                .map(|t| {
                    let wi = spherical_direction(t.to_radians(), 0.0);
                    directional_albedo(bsdf.as_ref(), wi, &BsdfContext::IMPORTANCE, samples, seed)
                })
                .collect::<Vec<_>>()
        });
        let k = rows.len();
        let pick = |f: &dyn Fn(&(_, _, _, _)) -> facette_bsdf::Spectrum| {
            let mut a = Array2::<f64>::zeros((k, 3));
            for (r, row) in rows.iter().enumerate() {
                let s = f(row);
                for c in 0..3 {
                    a[[r, c]] = s[c];
                }
            }
            a
        };
        let d = PyDict::new(py);
        d.set_item("reflectance", pick(&|r| r.0).into_pyarray(py))?;
        d.set_item("reflectance_stderr", pick(&|r| r.1).into_pyarray(py))?;
        d.set_item("transmittance", pick(&|r| r.2).into_pyarray(py))?;
        d.set_item("transmittance_stderr", pick(&|r| r.3).into_pyarray(py))?;
        Ok(d)
    }

    /// Every BSDF check of `facette validate --material` (chi-square of the sampler per
    /// side, pdf/sample consistency, albedo bound, reciprocity, NaN/Inf sweep).
    #[pyo3(signature = (samples = 200_000, seed = 1))]
    fn validate(&self, py: Python<'_>, samples: usize, seed: u64) -> PyResult<ValidationReport> {
        if samples < 1000 {
            return Err(value_error("`samples` must be at least 1000"));
        }
        let bsdf = self.bsdf.clone();
        let report = py.detach(move || {
            let opts = BsdfCheckOptions {
                chi2: Chi2Config {
                    samples,
                    seed,
                    ..Chi2Config::default()
                },
                ..BsdfCheckOptions::default()
            };
            let mut r = Report::new();
            r.extend(check_bsdf(bsdf.as_ref(), &opts));
            r
        });
        Ok(ValidationReport::from(&report))
    }
}

/// One check of a validation report.
#[pyclass(frozen, get_all, module = "facette._facette")]
#[derive(Clone)]
pub struct ValidationCheck {
    pub subject: String,
    pub name: String,
    /// The measured figure, as printed.
    pub figure: String,
    /// True or False, None for measurements without a criterion.
    pub passed: Option<bool>,
}

#[pymethods]
impl ValidationCheck {
    fn __repr__(&self) -> String {
        let v = match self.passed {
            Some(true) => "pass",
            Some(false) => "FAIL",
            None => "info",
        };
        format!("[{v}] {} — {}: {}", self.subject, self.name, self.figure)
    }
}

/// The result of `Material.validate()`.
#[pyclass(frozen, get_all, module = "facette._facette")]
pub struct ValidationReport {
    pub checks: Vec<ValidationCheck>,
    /// True when no check failed.
    pub passed: bool,
    /// `N passed, M failed` line, as the CLI prints it.
    pub summary: String,
}

impl From<&Report> for ValidationReport {
    fn from(r: &Report) -> Self {
        ValidationReport {
            checks: r
                .checks
                .iter()
                .map(|c| ValidationCheck {
                    subject: c.subject.clone(),
                    name: c.name.clone(),
                    figure: c.figure.clone(),
                    passed: r.judge(c),
                })
                .collect(),
            passed: r.all_passed(),
            summary: r.summary_line(),
        }
    }
}

#[pymethods]
impl ValidationReport {
    fn __repr__(&self) -> String {
        self.summary.clone()
    }

    fn __str__(&self) -> String {
        let mut s: Vec<String> = self.checks.iter().map(|c| c.__repr__()).collect();
        s.push(self.summary.clone());
        s.join("\n")
    }
}
