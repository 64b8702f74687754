//! Checked conversions between numpy arrays and directions.

use crate::errors::value_error;
use facette_bsdf::math::Vec3;
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;

/// An (N, 3) float64 array of finite, non-zero vectors, normalized.
pub fn directions(a: &PyReadonlyArray2<'_, f64>, name: &str) -> PyResult<Vec<Vec3>> {
    let v = a.as_array();
    if v.ncols() != 3 {
        return Err(value_error(format!(
            "`{name}` must have shape (N, 3), got {:?}",
            v.shape()
        )));
    }
    let mut out = Vec::with_capacity(v.nrows());
    for (k, row) in v.rows().into_iter().enumerate() {
        let d = Vec3::new(row[0], row[1], row[2]);
        let len = d.length();
        if !d.is_finite() || len == 0.0 {
            return Err(value_error(format!(
                "`{name}`[{k}] = ({}, {}, {}) is not a finite non-zero vector",
                row[0], row[1], row[2]
            )));
        }
        out.push(d / len);
    }
    Ok(out)
}
