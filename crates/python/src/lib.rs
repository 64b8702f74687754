//! `facette` for Python: the native module `facette._facette`, wrapped by the pure-Python
//! package in `crates/python/python/facette` (docs/python.md). Materials evaluate and
//! sample (N, 3) numpy arrays; renders come back as (H, W, 3) float32 arrays; parts of
//! renders and tables travel as bytes for distributed runs. Every heavy loop runs in Rust
//! with the GIL released, and stops on Ctrl-C (`interrupt`). Rust errors become `ValueError` (bad values, unknown names or
//! keys, malformed files) or `OSError` (files that cannot be read or written), with the
//! messages the CLI prints; a panic (a bug) becomes a `RuntimeError` naming the call.

mod arrays;
mod errors;
mod fit;
mod interrupt;
mod material;
mod parts;
mod render;
mod toml_value;

use pyo3::prelude::*;

/// Raises (or lowers) a resource limit for this process, `"KEY=N"` as the CLI's
/// `--limit`; an unknown key, a fixed limit or a value above the ceiling is a
/// `ValueError` naming the valid keys or the ceiling.
#[pyfunction]
fn set_limit(assignment: &str) -> PyResult<()> {
    facette_bsdf::limits::set_limit(assignment).map_err(errors::value_error)
}

/// Every resource limit: `(key, value in force, default, ceiling, what it counts)`.
#[pyfunction]
fn limits() -> Vec<(&'static str, u64, u64, u64, &'static str)> {
    facette_bsdf::limits::all()
        .iter()
        .map(|l| (l.key, l.max(), l.default, l.ceiling, l.what))
        .collect()
}

#[pymodule]
fn _facette(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<material::Material>()?;
    m.add_class::<material::ValidationReport>()?;
    m.add_class::<material::ValidationCheck>()?;
    // NumPy's C API is looked up on first use by importing numpy. Looked up during a call
    // interrupted by Ctrl-C, that import fails on the pending KeyboardInterrupt and
    // rust-numpy panics ("Failed to access NumPy array API capsule"): look it up now.
    numpy::PyArray1::<f64>::zeros(m.py(), 0, false);
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(render::check_scene, m)?)?;
    m.add_function(wrap_pyfunction!(render::scene_toml, m)?)?;
    m.add_function(wrap_pyfunction!(render::write_image, m)?)?;
    m.add_function(wrap_pyfunction!(render::read_image, m)?)?;
    m.add_function(wrap_pyfunction!(parts::render_part, m)?)?;
    m.add_function(wrap_pyfunction!(parts::render_in_parts, m)?)?;
    m.add_function(wrap_pyfunction!(parts::merge_render_parts, m)?)?;
    m.add_function(wrap_pyfunction!(parts::tabulate, m)?)?;
    m.add_function(wrap_pyfunction!(parts::check_table_material, m)?)?;
    m.add_function(wrap_pyfunction!(parts::tabulate_part, m)?)?;
    m.add_function(wrap_pyfunction!(parts::merge_table_parts, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit, m)?)?;
    m.add_function(wrap_pyfunction!(fit::measure, m)?)?;
    m.add_function(wrap_pyfunction!(set_limit, m)?)?;
    m.add_function(wrap_pyfunction!(limits, m)?)?;
    // `FACETTE_LIMITS` applies to Python as to the CLI (and reaches Ray workers through
    // their environment); a bad value fails the import with the CLI's message.
    facette_bsdf::limits::set_limits_from_env().map_err(errors::value_error)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
