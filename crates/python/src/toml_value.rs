//! Material descriptions from Python: a TOML inline table (`'{type = "il", ni = 1.5}'`),
//! TOML key/value lines, or a dict of str/int/float/bool/list/dict.

use crate::errors::value_error;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// The TOML table described by `spec`.
pub fn table_from_py(spec: &Bound<'_, PyAny>) -> PyResult<toml::Table> {
    if let Ok(s) = spec.cast::<PyString>() {
        let text: String = s.extract()?;
        return facette_bsdf::recipe::parse_inline_table(&text).map_err(value_error);
    }
    if let Ok(d) = spec.cast::<PyDict>() {
        return dict_to_table(d, "material");
    }
    Err(value_error(format!(
        "a material is a TOML inline table (str) or a dict, got {}",
        spec.get_type().name()?
    )))
}

fn dict_to_table(d: &Bound<'_, PyDict>, path: &str) -> PyResult<toml::Table> {
    let mut t = toml::Table::new();
    for (k, v) in d.iter() {
        let key: String = k
            .extract()
            .map_err(|_| value_error(format!("{path}: keys must be strings")))?;
        let value = to_value(&v, &format!("{path}.{key}"))?;
        t.insert(key, value);
    }
    Ok(t)
}

fn to_value(v: &Bound<'_, PyAny>, path: &str) -> PyResult<toml::Value> {
    // bool before int: Python's bool is an int.
    if let Ok(b) = v.cast::<PyBool>() {
        return Ok(toml::Value::Boolean(b.is_true()));
    }
    if v.is_instance_of::<PyInt>() {
        let i: i64 = v.extract()?;
        return Ok(toml::Value::Integer(i));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if let Ok(s) = v.cast::<PyString>() {
        return Ok(toml::Value::String(s.extract::<String>()?));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        return Ok(toml::Value::Table(dict_to_table(d, path)?));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let mut out = Vec::new();
        for (k, x) in v.try_iter()?.enumerate() {
            out.push(to_value(&x?, &format!("{path}[{k}]"))?);
        }
        return Ok(toml::Value::Array(out));
    }
    // numpy scalars and the like.
    if let Ok(f) = v.extract::<f64>() {
        return Ok(toml::Value::Float(f));
    }
    Err(value_error(format!(
        "{path}: unsupported value of type {}",
        v.get_type().name()?
    )))
}
