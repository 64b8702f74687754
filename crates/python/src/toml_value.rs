//! Material and scene descriptions from Python: a TOML inline table
//! (`'{type = "il", ni = 1.5}'`), TOML key/value lines, a dict of str/int/float/bool/list/
//! dict (numpy arrays and scalars included), or a `Material` — and back.

use crate::errors::value_error;
use crate::material::Material;
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
    if let Some(m) = material(spec) {
        return Ok(m);
    }
    Err(value_error(format!(
        "a material is a Material, a TOML inline table (str) or a dict, got {}",
        spec.get_type().name()?
    )))
}

/// The spec of a `Material`: the native class, or the Python wrapper holding one as `_m`.
fn material(v: &Bound<'_, PyAny>) -> Option<toml::Table> {
    if let Ok(m) = v.cast::<Material>() {
        return Some(m.get().table().clone());
    }
    let inner = v.getattr("_m").ok()?;
    let m = inner.cast::<Material>().ok()?;
    Some(m.get().table().clone())
}

pub fn dict_to_table(d: &Bound<'_, PyDict>, path: &str) -> PyResult<toml::Table> {
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
        let i: i64 = v
            .extract()
            .map_err(|_| value_error(format!("{path}: integer out of range")))?;
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
    if let Some(m) = material(v) {
        return Ok(toml::Value::Table(m));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let mut out = Vec::new();
        for (k, x) in v.try_iter()?.enumerate() {
            out.push(to_value(&x?, &format!("{path}[{k}]"))?);
        }
        return Ok(toml::Value::Array(out));
    }
    // numpy arrays and scalars: `tolist()` gives lists of Python numbers (a scalar gives
    // the number itself), whatever the dtype and memory layout.
    let type_name = v.get_type().name()?.to_string();
    let module: String = v.get_type().module()?.extract()?;
    if module == "numpy" {
        if let Ok(l) = v.call_method0("tolist") {
            return to_value(&l, path);
        }
    }
    Err(value_error(format!(
        "{path}: unsupported value of type {type_name}"
    )))
}

/// A TOML table as a dict.
pub fn table_to_py<'py>(py: Python<'py>, t: &toml::Table) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in t {
        d.set_item(k, value_to_py(py, v)?)?;
    }
    Ok(d)
}

fn value_to_py<'py>(py: Python<'py>, v: &toml::Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        toml::Value::String(s) => s.into_pyobject(py)?.into_any(),
        toml::Value::Integer(i) => i.into_pyobject(py)?.into_any(),
        toml::Value::Float(f) => f.into_pyobject(py)?.into_any(),
        toml::Value::Boolean(b) => PyBool::new(py, *b).to_owned().into_any(),
        toml::Value::Datetime(d) => d.to_string().into_pyobject(py)?.into_any(),
        toml::Value::Array(a) => PyList::new(
            py,
            a.iter()
                .map(|x| value_to_py(py, x))
                .collect::<PyResult<Vec<_>>>()?,
        )?
        .into_any(),
        toml::Value::Table(t) => table_to_py(py, t)?.into_any(),
    })
}

/// A table as one TOML inline table (`{type = "il", ni = 1.5}`).
pub fn inline_toml(t: &toml::Table) -> String {
    let items: Vec<String> = t
        .iter()
        .map(|(k, v)| {
            let key = toml::Value::String(k.clone()).to_string();
            // Bare keys where TOML allows them.
            let bare = !k.is_empty()
                && k.chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
            let key = if bare { k.clone() } else { key };
            let value = match v {
                toml::Value::Table(inner) => inline_toml(inner),
                other => other.to_string(),
            };
            format!("{key} = {value}")
        })
        .collect();
    format!("{{{}}}", items.join(", "))
}
