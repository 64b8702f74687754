//! The one error type of scene loading, shared by the TOML builder and the Mitsuba reader
//! so that every message names a file and, when known, a line.

use std::path::PathBuf;

/// A scene error: file, line (when known) and what was expected.
#[derive(Debug, thiserror::Error)]
#[error("{}{}: {message}", file.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
pub struct SceneError {
    pub file: PathBuf,
    pub line: Option<usize>,
    pub message: String,
}
