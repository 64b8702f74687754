//! Errors of the geometry module: invalid transforms and shape parameters, malformed mesh
//! data and mesh files. Every fallible constructor and loader returns [`GeometryError`];
//! nothing in this module panics on bad input.
//!
//! Messages name what was wrong, the value, and what was expected; errors found in a file
//! are wrapped in [`GeometryError::InFile`], which prefixes `path:line: `.

use std::path::PathBuf;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum GeometryError {
    #[error("transform matrix has a non-finite entry (row {row}, column {col}: {value})")]
    NonFiniteTransform { row: usize, col: usize, value: f64 },

    #[error("transform matrix is singular or too ill-conditioned to invert (determinant {det:e})")]
    SingularTransform { det: f64 },

    #[error("invalid transform parameter `{name}` = {value}: expected {expected}")]
    InvalidTransformParameter {
        name: &'static str,
        value: String,
        expected: &'static str,
    },

    #[error("invalid {shape} parameter `{name}` = {value}: expected {expected}")]
    InvalidShapeParameter {
        shape: &'static str,
        name: &'static str,
        value: String,
        expected: &'static str,
    },

    #[error("{shape}: unsupported `to_world` transform: {reason}")]
    UnsupportedTransform {
        shape: &'static str,
        reason: &'static str,
    },

    #[error("mesh vertex {index} has a non-finite {attribute} ({value})")]
    NonFiniteVertex {
        attribute: &'static str,
        index: usize,
        value: String,
    },

    #[error(
        "vertex index {index} of face {face} is out of range: the mesh has {vertex_count} \
         vertices (valid indices are 0 to {vertex_count} excluded)"
    )]
    IndexOutOfRange {
        index: i64,
        face: usize,
        vertex_count: usize,
    },

    #[error(
        "face refers to {attribute} {index}, but the file defines {count} \
         (OBJ indices start at 1; negative indices count back from the last definition)"
    )]
    ObjIndexOutOfRange {
        attribute: &'static str,
        index: i64,
        count: usize,
    },

    #[error("mesh {attribute} count {got} does not match the vertex count {expected}")]
    AttributeCountMismatch {
        attribute: &'static str,
        expected: usize,
        got: usize,
    },

    #[error("mesh index count {count} is not a multiple of 3 (indices must list triangles)")]
    IndexCountNotTriangles { count: usize },

    #[error("mesh has no triangles")]
    NoTriangles,

    #[error("mesh has {count} {what}, more than the supported {max}")]
    TooLarge {
        what: &'static str,
        count: usize,
        max: usize,
    },

    #[error("scene has {count} primitives, more than the supported {max}")]
    TooManyPrimitives { count: usize, max: usize },

    #[error("cannot read mesh file `{}`: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },

    #[error("unknown mesh file format `{}`: expected a `.obj` or `.ply` extension", path.display())]
    UnknownMeshFormat { path: PathBuf },

    #[error("malformed {format} data: {message}")]
    Malformed {
        format: &'static str,
        message: String,
    },

    /// An error found while loading a file, with its location.
    #[error("{}: {error}", location(path, *line))]
    InFile {
        path: PathBuf,
        /// 1-based line number when the parser knows it.
        line: Option<usize>,
        error: Box<GeometryError>,
    },
}

impl GeometryError {
    /// Wraps `self` with the file (and line) where it was found.
    pub fn in_file(self, path: impl Into<PathBuf>, line: Option<usize>) -> GeometryError {
        GeometryError::InFile {
            path: path.into(),
            line,
            error: Box::new(self),
        }
    }

    /// The underlying error, without file locations.
    pub fn root(&self) -> &GeometryError {
        match self {
            GeometryError::InFile { error, .. } => error.root(),
            e => e,
        }
    }
}

fn location(path: &std::path::Path, line: Option<usize>) -> String {
    match line {
        Some(l) => format!("{}:{l}", path.display()),
        None => path.display().to_string(),
    }
}

pub type GeometryResult<T> = Result<T, GeometryError>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn in_file_prefixes_path_and_line() {
        let e = GeometryError::NoTriangles.in_file("/tmp/a.obj", Some(12));
        assert_eq!(e.to_string(), "/tmp/a.obj:12: mesh has no triangles");
        assert!(matches!(e.root(), GeometryError::NoTriangles));
        let e = GeometryError::NoTriangles.in_file("/tmp/a.obj", None);
        assert_eq!(e.to_string(), "/tmp/a.obj: mesh has no triangles");
    }
}
