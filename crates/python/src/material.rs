//! `facette.Material`: a material of the library on numpy arrays.

use crate::arrays::directions;
use crate::errors::value_error;
use crate::interrupt::{guard, run_all, run_small_or_all, Control};
use crate::toml_value::{inline_toml, table_from_py, table_to_py};
use facette_bsdf::math::rng::{mix_seed, Pcg32, RandomSource};
use facette_bsdf::math::spherical_direction;
use facette_bsdf::validation::bsdf_checks::{
    check_bsdf_watched, directional_albedo, BsdfCheckOptions,
};
use facette_bsdf::validation::chi2::Chi2Config;
use facette_bsdf::validation::Report;
use facette_bsdf::{Bsdf, BsdfContext, Spectrum, TransportMode};
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
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
        ..Default::default()
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
    /// The spec it was built from: its identity (`==`, pickling, `.spec`).
    table: toml::Table,
}

impl Material {
    /// The material's BSDF, shared.
    pub(crate) fn bsdf(&self) -> Arc<dyn Bsdf> {
        self.bsdf.clone()
    }

    /// The spec it was built from.
    pub(crate) fn table(&self) -> &toml::Table {
        &self.table
    }
}

/// A thread pool of `threads` threads; None (all cores) is rayon's global pool, started
/// once per process rather than per call.
fn pool(threads: Option<usize>) -> PyResult<Option<rayon::ThreadPool>> {
    match threads {
        None => Ok(None),
        Some(0) => Err(value_error("`threads` must be at least 1")),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map(Some)
            .map_err(|e| value_error(format!("cannot start the thread pool: {e}"))),
    }
}

/// `f` in `pool`, or in the global pool.
fn install<T: Send>(pool: &Option<rayon::ThreadPool>, f: impl FnOnce() -> T + Send) -> T {
    match pool {
        Some(p) => p.install(f),
        None => f(),
    }
}

/// Rows per parallel chunk: large enough that scheduling costs nothing, small enough that
/// a cancel is seen quickly and the cores share the work.
const CHUNK: usize = 256;

/// `f(k)` for every k < n, in chunks on `pool`, stopping (rows left at their default)
/// when cancelled.
fn par_rows<T: Send + Default + Clone>(
    pool: &Option<rayon::ThreadPool>,
    c: &Control,
    n: usize,
    f: impl Fn(usize) -> T + Sync,
) -> Vec<T> {
    c.set_total(n as u64);
    let mut out = vec![T::default(); n];
    install(pool, || {
        out.par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(j, chunk)| {
                if c.cancelled() {
                    return;
                }
                for (i, o) in chunk.iter_mut().enumerate() {
                    *o = f(j * CHUNK + i);
                }
                c.advance(chunk.len() as u64);
            })
    });
    out
}

#[pymethods]
impl Material {
    #[new]
    fn new(spec: &Bound<'_, PyAny>) -> PyResult<Self> {
        let table = table_from_py(spec)?;
        let bsdf = guard("facette.Material", || {
            facette_bsdf::recipe::build_material(&table).map_err(value_error)
        })?;
        Ok(Material { bsdf, table })
    }

    /// The model and its parameters.
    #[getter]
    fn description(&self) -> String {
        self.bsdf.describe()
    }

    /// Whether the model is stochastic: its `eval` an unbiased estimate, or (IL with both
    /// quadratures) its sampling weights only, `eval` then being deterministic.
    #[getter]
    fn is_stochastic(&self) -> bool {
        self.bsdf.is_stochastic()
    }

    /// The spec as a dict (TOML types: str, int, float, bool, list, dict).
    #[getter]
    fn spec<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        table_to_py(py, &self.table)
    }

    /// The spec as a TOML inline table, as the command line's `--material` takes it.
    #[getter]
    fn toml(&self) -> String {
        inline_toml(&self.table)
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<Material>()
            .is_ok_and(|o| o.get().table == self.table)
    }

    fn __hash__(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        inline_toml(&self.table).hash(&mut h);
        h.finish()
    }

    fn __repr__(&self) -> String {
        format!("Material({})", self.bsdf.describe())
    }

    /// f(wi, wo) without the cosine, per RGB channel, for rows of `wi` (toward the light)
    /// and `wo` (toward the viewer), both (N, 3) in the local frame (z = normal). Stochastic
    /// materials average `samples` estimates per row from one stream seeded by `seed` —
    /// the values `facette eval` prints for the same rows, seed and samples — and so run on
    /// one thread; the others run on `threads` threads (all cores when None). With
    /// `with_error`, three more columns: each value's error (`facette eval --with-error`'s:
    /// the standard error of stochastic estimates, the adaptive quadrature's error
    /// estimate, 0 for closed forms).
    #[pyo3(signature = (wi, wo, samples = 100_000, mode = "radiance", seed = 1, threads = None,
        progress = None, with_error = false))]
    #[allow(clippy::too_many_arguments)]
    fn eval<'py>(
        &self,
        py: Python<'py>,
        wi: PyReadonlyArray2<'py, f64>,
        wo: PyReadonlyArray2<'py, f64>,
        samples: usize,
        mode: &str,
        seed: u64,
        threads: Option<usize>,
        progress: Option<Py<PyAny>>,
        with_error: bool,
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
        let pool = pool(threads)?;
        let bsdf = self.bsdf.clone();
        // A stochastic row costs `samples` evaluations.
        let work = wi.len()
            * if self.bsdf.eval_is_deterministic() {
                1
            } else {
                samples
            };
        let small = work <= CHUNK;
        let rows = run_small_or_all(py, "facette.Material.eval", progress, small, move |c| {
            if !bsdf.eval_is_deterministic() {
                // One stream through the rows, in order: `facette eval`'s values.
                c.set_total(wi.len() as u64);
                let mut rng = Pcg32::new(seed, 0);
                let mut out = vec![[0.0; 6]; wi.len()];
                for k in 0..wi.len() {
                    if c.cancelled() {
                        break;
                    }
                    let (f, e) = bsdf.eval_estimate(wo[k], wi[k], &ctx, samples, &mut rng);
                    out[k] = [f[0], f[1], f[2], e[0], e[1], e[2]];
                    c.advance(1);
                }
                out
            } else {
                par_rows(&pool, c, wi.len(), |k| {
                    // Deterministic: the generator is not drawn from.
                    let mut rng = Pcg32::new(seed, k as u64);
                    // The error estimate only where asked: it may cost more than the value.
                    let (f, e) = if with_error {
                        bsdf.eval_estimate(wo[k], wi[k], &ctx, samples, &mut rng)
                    } else {
                        (bsdf.eval(wo[k], wi[k], &ctx, &mut rng), Spectrum::ZERO)
                    };
                    [f[0], f[1], f[2], e[0], e[1], e[2]]
                })
            }
        })?;
        let columns = if with_error { 6 } else { 3 };
        let mut out = Array2::<f64>::zeros((rows.len(), columns));
        for (k, f) in rows.iter().enumerate() {
            for c in 0..columns {
                out[[k, c]] = f[c];
            }
        }
        Ok(out.into_pyarray(py))
    }

    /// Solid-angle density with which `sample(wo)` draws `wi` (non-delta lobes), shape (N,).
    /// Arguments in `eval`'s order: `wi` first.
    #[pyo3(signature = (wi, wo, mode = "radiance", threads = None))]
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        wi: PyReadonlyArray2<'py, f64>,
        wo: PyReadonlyArray2<'py, f64>,
        mode: &str,
        threads: Option<usize>,
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
        let pool = pool(threads)?;
        let bsdf = self.bsdf.clone();
        let small = wi.len() <= CHUNK;
        let out = run_small_or_all(py, "facette.Material.pdf", None, small, move |c| {
            par_rows(&pool, c, wi.len(), |k| bsdf.pdf(wo[k], wi[k], &ctx))
        })?;
        Ok(Array1::from_vec(out).into_pyarray(py))
    }

    /// Draws a direction per row of `wo`: returns (wi (N, 3), weight = f·|cos θ_i|/pdf
    /// (N, 3), pdf (N,), lobe names (list)). `u`, when given, is an (N, K) array of uniform
    /// numbers in [0, 1) consumed in order by row k's sampler (a stream seeded by `seed`
    /// and k continues when a row needs more than K); a failed sample has weight 0, pdf 0
    /// and lobe "none". Rows are independent: `threads` does not change the result.
    #[pyo3(signature = (wo, u = None, mode = "radiance", seed = 1, threads = None))]
    #[allow(clippy::type_complexity)]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        wo: PyReadonlyArray2<'py, f64>,
        u: Option<PyReadonlyArray2<'py, f64>>,
        mode: &str,
        seed: u64,
        threads: Option<usize>,
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
        let pool = pool(threads)?;
        let bsdf = self.bsdf.clone();
        type Row = ([f64; 3], [f64; 3], f64, String);
        let small = wo.len() <= CHUNK;
        let rows: Vec<Row> =
            run_small_or_all(py, "facette.Material.sample", None, small, move |c| {
                par_rows(&pool, c, wo.len(), |k| {
                    let row: Vec<f64> = u.as_ref().map(|a| a.row(k).to_vec()).unwrap_or_default();
                    let mut rng = ReplayRandom {
                        given: &row,
                        next: 0,
                        rest: Pcg32::new(mix_seed(seed, k as u64), 0),
                    };
                    match bsdf.sample(wo[k], &ctx, &mut rng) {
                        Some(s) => (
                            [s.wi[0], s.wi[1], s.wi[2]],
                            [s.weight[0], s.weight[1], s.weight[2]],
                            s.pdf,
                            s.lobe.describe(),
                        ),
                        None => ([0.0; 3], [0.0; 3], 0.0, "none".to_string()),
                    }
                })
            })?;
        let n = rows.len();
        let mut wis = Array2::<f64>::zeros((n, 3));
        let mut weights = Array2::<f64>::zeros((n, 3));
        let mut pdfs = Array1::<f64>::zeros(n);
        let mut lobes = Vec::with_capacity(n);
        for (k, (wi, w, p, lobe)) in rows.into_iter().enumerate() {
            for c in 0..3 {
                wis[[k, c]] = wi[c];
                weights[[k, c]] = w[c];
            }
            pdfs[k] = p;
            lobes.push(lobe);
        }
        Ok((
            wis.into_pyarray(py),
            weights.into_pyarray(py),
            pdfs.into_pyarray(py),
            lobes,
        ))
    }

    /// Directional reflectance and transmittance for incidence angles `theta_i` (degrees,
    /// a list; 0–90 from above, 90–180 from below), with standard errors — the numbers of
    /// `facette albedo`. Returns a dict of (K, 3) arrays. The angles run in parallel on
    /// `threads` threads (each angle has its own seeded stream: threads change nothing).
    #[pyo3(signature = (theta_i, samples = 1_000_000, seed = 1, threads = None, progress = None))]
    fn albedo<'py>(
        &self,
        py: Python<'py>,
        theta_i: Vec<f64>,
        samples: usize,
        seed: u64,
        threads: Option<usize>,
        progress: Option<Py<PyAny>>,
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
        let pool = pool(threads)?;
        let bsdf = self.bsdf.clone();
        let rows = run_all(py, "facette.Material.albedo", progress, move |c| {
            c.set_total(theta_i.len() as u64);
            install(&pool, || {
                theta_i
                    .par_iter()
                    .map(|t| {
                        let wi = spherical_direction(t.to_radians(), 0.0);
                        let r = directional_albedo(
                            bsdf.as_ref(),
                            wi,
                            &BsdfContext::IMPORTANCE,
                            samples,
                            seed,
                        );
                        c.advance(1);
                        r
                    })
                    .collect::<Vec<_>>()
            })
        })?;
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
    /// side, pdf/sample consistency, albedo bound, reciprocity, NaN/Inf sweep). Progress
    /// counts the steps (incidences, then the two sweeps).
    #[pyo3(signature = (samples = 200_000, seed = 1, progress = None))]
    fn validate(
        &self,
        py: Python<'_>,
        samples: usize,
        seed: u64,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<ValidationReport> {
        if samples < 1000 {
            return Err(value_error("`samples` must be at least 1000"));
        }
        let bsdf = self.bsdf.clone();
        let report = run_all(py, "facette.Material.validate", progress, move |c| {
            let opts = BsdfCheckOptions {
                chi2: Chi2Config {
                    samples,
                    seed,
                    ..Chi2Config::default()
                },
                ..BsdfCheckOptions::default()
            };
            let mut r = Report::new();
            r.extend(check_bsdf_watched(bsdf.as_ref(), &opts, &|d, t| {
                c.progress(d as u64, t as u64);
                !c.cancelled()
            }));
            r
        })?;
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
