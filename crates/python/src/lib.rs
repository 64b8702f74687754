//! `facette` for Python: the native module `facette._facette`, wrapped by the pure-Python
//! package in `crates/python/python/facette` (docs/python.md). Materials evaluate and
//! sample (N, 3) numpy arrays; renders come back as (H, W, 3) float32 arrays; parts of
//! renders and tables travel as bytes for distributed runs. Every heavy loop runs in Rust
//! with the GIL released. Rust errors become `ValueError` (bad values, unknown names or
//! keys, malformed files) or `OSError` (files that cannot be read or written), with the
//! messages the CLI prints.

mod arrays;
mod errors;
mod fit;
mod material;
mod parts;
mod render;
mod toml_value;

use pyo3::prelude::*;

#[pymodule]
fn _facette(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<material::Material>()?;
    m.add_class::<material::ValidationReport>()?;
    m.add_class::<material::ValidationCheck>()?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(render::write_image, m)?)?;
    m.add_function(wrap_pyfunction!(render::read_image, m)?)?;
    m.add_function(wrap_pyfunction!(parts::render_part, m)?)?;
    m.add_function(wrap_pyfunction!(parts::render_in_parts, m)?)?;
    m.add_function(wrap_pyfunction!(parts::merge_render_parts, m)?)?;
    m.add_function(wrap_pyfunction!(parts::tabulate, m)?)?;
    m.add_function(wrap_pyfunction!(parts::tabulate_part, m)?)?;
    m.add_function(wrap_pyfunction!(parts::merge_table_parts, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit, m)?)?;
    m.add_function(wrap_pyfunction!(fit::measure, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
