//! Work that splits exactly, for distributed runs (`facette.distributed`): parts of a
//! render and of an IL table as bytes (the `.fcpart` / `.fctpart` formats of
//! docs/file-formats.md), and their merges.

use crate::errors::{os_error, value_error};
use crate::interrupt;
use crate::render::{film_array, options, scene_arg};
use crate::toml_value::table_from_py;
use facette_bsdf::microfacet::integral::{check_tolerance, TableEntries};
use facette_bsdf::models::il::il_table::BodyTable;
use facette_bsdf::models::il::il_table_part::{merge_table_parts as merge_tables, TablePart};
use facette_bsdf::models::il::interfaced_lambertian::{BodyEvaluation, Scattering};
use facette_bsdf::models::InterfacedLambertian;
use facette_bsdf::recipe::microfacet::{parse_distribution, parse_masking, parse_sampling};
use facette_bsdf::recipe::Params;
use facette_render::partial_film::{merge_parts, PartialFilm};
use numpy::{IntoPyArray, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::path::Path;

/// Renders part `part` of `parts` of a scene's samples; returns the `.fcpart` bytes. An
/// interrupted part is never returned (it would merge as a wrong image).
#[pyfunction]
#[pyo3(signature = (kind, scene, part, parts, spp = None, seed = 0, threads = None,
    defines = None, width = None, height = None, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn render_part<'py>(
    py: Python<'py>,
    kind: &str,
    scene: &Bound<'py, PyAny>,
    part: u32,
    parts: u32,
    spp: Option<usize>,
    seed: u64,
    threads: Option<usize>,
    defines: Option<Vec<(String, String)>>,
    width: Option<usize>,
    height: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyBytes>> {
    let opts = options(spp, seed, threads, None)?;
    let arg = scene_arg(kind, scene, defines, width, height)?;
    let bytes = interrupt::run_all(py, "facette.render_part", progress, move |c| {
        let s = arg.load()?;
        let (p, _) =
            facette_render::partial_film::render_part(&s, &opts, part, parts, c.flag(), &|d, t| {
                c.progress(d, t)
            })
            .map_err(value_error)?;
        PyResult::Ok(p.to_bytes())
    })??;
    Ok(PyBytes::new(py, &bytes))
}

/// The N parts rendered in this process and merged: the reference a distributed render
/// reproduces bit for bit. Returns (H, W, 3) float32 times 2^(scene exposure).
#[pyfunction]
#[pyo3(signature = (kind, scene, parts, spp = None, seed = 0, threads = None,
    defines = None, width = None, height = None, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn render_in_parts<'py>(
    py: Python<'py>,
    kind: &str,
    scene: &Bound<'py, PyAny>,
    parts: u32,
    spp: Option<usize>,
    seed: u64,
    threads: Option<usize>,
    defines: Option<Vec<(String, String)>>,
    width: Option<usize>,
    height: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let opts = options(spp, seed, threads, None)?;
    let arg = scene_arg(kind, scene, defines, width, height)?;
    let a = interrupt::run_all(py, "facette.render_in_parts", progress, move |c| {
        let s = arg.load()?;
        // `partial_film::render_in_parts`, part by part, so that Ctrl-C stops it.
        let mut films = Vec::new();
        for k in 0..parts {
            let (p, _) = facette_render::partial_film::render_part(
                &s,
                &opts,
                k,
                parts,
                c.flag(),
                &|d, t| c.progress(d + k as u64 * t, t * parts as u64),
            )
            .map_err(value_error)?;
            if c.cancelled() {
                return Err(value_error("interrupted"));
            }
            films.push(p);
        }
        let film = merge_parts(&films).map_err(value_error)?;
        Ok(film_array(&film, s.film.exposure))
    })??;
    Ok(a.into_pyarray(py))
}

/// Merges render parts (bytes of `.fcpart` files, any order); returns (H, W, 3) float32
/// times 2^exposure (the parts' scene exposure unless given).
#[pyfunction]
#[pyo3(signature = (parts, exposure = None))]
pub fn merge_render_parts<'py>(
    py: Python<'py>,
    parts: Vec<Vec<u8>>,
    exposure: Option<f64>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let a = interrupt::run_all(py, "facette.merge_render_parts", None, move |_| {
        let films: Vec<PartialFilm> = parts
            .iter()
            .enumerate()
            .map(|(k, b)| PartialFilm::from_bytes(b, Path::new(&format!("part #{k}"))))
            .collect::<Result<_, _>>()
            .map_err(value_error)?;
        let film = merge_parts(&films).map_err(value_error)?;
        let e = exposure.unwrap_or(films[0].exposure);
        PyResult::Ok(film_array(&film, e))
    })??;
    Ok(a.into_pyarray(py))
}

/// The microfacet lobe and n_i of a rough IL material (tables need one).
fn il_lobe(
    material: &Bound<'_, PyAny>,
) -> PyResult<(facette_bsdf::microfacet::specular_lobe::SpecularLobe, f64)> {
    let table = table_from_py(material)?;
    interrupt::guard("facette.tabulate", || {
        let ty = table.get("type").and_then(|v| v.as_str()).unwrap_or("");
        if ty != "il" && ty != "interfaced-lambertian" {
            return Err(value_error(format!(
                "tabulate needs an interfaced-Lambertian material (type = \"il\"), got type `{ty}`"
            )));
        }
        facette_bsdf::recipe::build_material(&table).map_err(value_error)?;
        let p = Params::new(&table, "material \"il\"");
        let ni = p.f64_or("ni", 1.5).map_err(value_error)?;
        let ndf = parse_distribution(&p, true)
            .map_err(value_error)?
            .ok_or_else(|| {
                value_error("the material is flat (alpha = 0): its body term needs no table")
            })?;
        let masking = parse_masking(&p, Some(&ndf)).map_err(value_error)?;
        let sampling = parse_sampling(&p).map_err(value_error)?;
        let lobe =
            facette_bsdf::microfacet::specular_lobe::SpecularLobe::new(ndf, masking, sampling)
                .map_err(value_error)?;
        // Validates the combination as the material would.
        InterfacedLambertian::new(
            facette_bsdf::Spectrum::splat(0.5),
            ni,
            Some(lobe.clone()),
            BodyEvaluation::Stochastic,
            Scattering::Single,
        )
        .map_err(value_error)?;
        Ok((lobe, ni))
    })
}

/// The entries of a table: `samples` QMC microfacets each, or adaptive quadrature to
/// `tolerance` (checked against the range of the `tolerance` key) when it is given — what
/// `facette tabulate --samples / --tolerance` chooses.
fn table_entries(samples: usize, tolerance: Option<f64>) -> PyResult<TableEntries> {
    Ok(match tolerance {
        Some(t) => TableEntries::Adaptive {
            tolerance: check_tolerance(t).map_err(value_error)?,
        },
        None => TableEntries::Samples(samples),
    })
}

/// Checks that `material` can be tabulated (a rough IL material): the driver-side check
/// of a distributed table.
#[pyfunction]
pub fn check_table_material(material: &Bound<'_, PyAny>) -> PyResult<()> {
    il_lobe(material).map(|_| ())
}

/// Tabulates the body term of an IL material (`facette tabulate`); returns the `.fctab`
/// bytes and writes them to `output` when given.
#[pyfunction]
#[pyo3(signature = (material, step = 5.0, samples = 10_000, output = None, progress = None, tolerance = None))]
pub fn tabulate<'py>(
    py: Python<'py>,
    material: &Bound<'py, PyAny>,
    step: f64,
    samples: usize,
    output: Option<std::path::PathBuf>,
    progress: Option<Py<PyAny>>,
    tolerance: Option<f64>,
) -> PyResult<Bound<'py, PyBytes>> {
    let (lobe, ni) = il_lobe(material)?;
    let entries = table_entries(samples, tolerance)?;
    let bytes = interrupt::run_all(py, "facette.tabulate", progress, move |c| {
        let t = BodyTable::build_with(&lobe, ni, step, entries, &|d, t| {
            c.progress(d as u64, t as u64)
        })
        .map_err(value_error)?;
        if let Some(o) = &output {
            t.save(o).map_err(os_error)?;
        }
        PyResult::Ok(t.to_bytes())
    })??;
    Ok(PyBytes::new(py, &bytes))
}

/// Part `part` of `parts` of a table (`facette tabulate --part`); returns `.fctpart` bytes.
#[pyfunction]
#[pyo3(signature = (material, part, parts, step = 5.0, samples = 10_000, progress = None, tolerance = None))]
#[allow(clippy::too_many_arguments)]
pub fn tabulate_part<'py>(
    py: Python<'py>,
    material: &Bound<'py, PyAny>,
    part: u32,
    parts: u32,
    step: f64,
    samples: usize,
    progress: Option<Py<PyAny>>,
    tolerance: Option<f64>,
) -> PyResult<Bound<'py, PyBytes>> {
    let (lobe, ni) = il_lobe(material)?;
    let entries = table_entries(samples, tolerance)?;
    let bytes = interrupt::run_all(py, "facette.tabulate_part", progress, move |c| {
        let p = TablePart::build_with(&lobe, ni, step, entries, part, parts, &|d, t| {
            c.progress(d as u64, t as u64)
        })
        .map_err(value_error)?;
        PyResult::Ok(p.to_bytes())
    })??;
    Ok(PyBytes::new(py, &bytes))
}

/// Merges table parts (bytes, any order) into the `.fctab` bytes (written to `output` when
/// given) — byte for byte what `tabulate` makes.
#[pyfunction]
#[pyo3(signature = (parts, output = None))]
pub fn merge_table_parts<'py>(
    py: Python<'py>,
    parts: Vec<Vec<u8>>,
    output: Option<std::path::PathBuf>,
) -> PyResult<Bound<'py, PyBytes>> {
    let bytes = interrupt::run_all(py, "facette.merge_table_parts", None, move |_| {
        let ps: Vec<TablePart> = parts
            .iter()
            .enumerate()
            .map(|(k, b)| TablePart::from_bytes(b, &format!("part #{k}")))
            .collect::<Result<_, _>>()
            .map_err(value_error)?;
        let t = merge_tables(&ps).map_err(|e| value_error(format!("cannot merge: {e}")))?;
        if let Some(o) = &output {
            t.save(o).map_err(os_error)?;
        }
        PyResult::Ok(t.to_bytes())
    })??;
    Ok(PyBytes::new(py, &bytes))
}
