//! Rust errors as Python exceptions, keeping the CLI's messages.

use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::PyErr;

/// A bad value, name, key or file content.
pub fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A file that cannot be read or written.
pub fn os_error(e: impl std::fmt::Display) -> PyErr {
    PyOSError::new_err(e.to_string())
}
