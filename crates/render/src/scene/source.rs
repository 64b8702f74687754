//! Where a scene description came from: what its spans index (the TOML text, or the
//! file:line table of a description translated from Mitsuba XML), so that an error at a
//! span names the right file and line, and the hash that identifies the source.
//!
//! This is the meeting point of the two readers: the TOML builder (`super::load`) and the
//! Mitsuba reader (`super::mitsuba`) both depend on it, not on each other.

use super::SceneError;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// A place in a scene file, for descriptions whose elements come from several files
/// (Mitsuba XML with `<include>`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Location {
    pub file: PathBuf,
    pub line: usize,
}

/// What the spans of a [`super::description::SceneDesc`] index.
pub(crate) enum Spans<'a> {
    /// Byte ranges of the TOML text of `file`.
    Text { file: &'a Path, source: &'a str },
    /// `i..i + 1` is entry `i` of `locations` (a description translated from Mitsuba XML);
    /// errors without a span name `file`, the main scene file.
    Table {
        file: &'a Path,
        locations: &'a [Location],
    },
}

impl Spans<'_> {
    /// An error at `span` (or at the file alone when there is none).
    pub fn err(&self, span: Option<Range<usize>>, message: impl Into<String>) -> SceneError {
        let (file, line) = match (self, span) {
            (Spans::Text { file, source }, Some(s)) => (
                file.to_path_buf(),
                Some(source[..s.start.min(source.len())].matches('\n').count() + 1),
            ),
            (Spans::Table { file, locations }, Some(s)) => match locations.get(s.start) {
                Some(l) => (l.file.clone(), Some(l.line)),
                None => (file.to_path_buf(), None),
            },
            (Spans::Text { file, .. } | Spans::Table { file, .. }, None) => {
                (file.to_path_buf(), None)
            }
        };
        SceneError {
            file,
            line,
            message: message.into(),
        }
    }
}

/// FNV-1a, 64-bit: the hash of a scene's source text (see `Scene::source_hash`).
pub fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= *b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// The text of a scene file (TOML or XML), read the one way both readers read it: the
/// size is checked against its limit before the file is read into memory, and bytes that
/// are not UTF-8 are reported at their line and column, not as a bare "stream did not
/// contain valid UTF-8".
pub(crate) fn read_scene_text(path: &Path) -> Result<String, SceneError> {
    let err = |line: Option<usize>, message: String| SceneError {
        file: path.to_path_buf(),
        line,
        message,
    };
    if let Ok(m) = std::fs::metadata(path) {
        facette_bsdf::limits::SCENE_FILE_BYTES
            .check(m.len())
            .map_err(|e| err(None, e.to_string()))?;
    }
    let bytes =
        std::fs::read(path).map_err(|e| err(None, format!("cannot read the scene file: {e}")))?;
    String::from_utf8(bytes).map_err(|e| {
        let good = &e.as_bytes()[..e.utf8_error().valid_up_to()];
        let line = 1 + good.iter().filter(|&&b| b == b'\n').count();
        let line_start = good.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        let column = 1 + String::from_utf8_lossy(&good[line_start..]).chars().count();
        let byte = e.as_bytes()[good.len()];
        err(
            Some(line),
            format!("column {column}: byte 0x{byte:02x} is not UTF-8 text (scene files are UTF-8)"),
        )
    })
}

#[cfg(test)]
mod read_tests {
    use super::*;

    #[test]
    fn bytes_that_are_not_utf8_are_reported_at_their_line_and_column() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("s.toml");
        std::fs::write(&p, b"[film]\nwidth = 8\nheight = \xff6\n").unwrap();
        let e = read_scene_text(&p).unwrap_err();
        assert_eq!(e.line, Some(3));
        assert!(e.to_string().contains("s.toml:3"), "{e}");
        assert!(e.message.contains("column 10: byte 0xff"), "{}", e.message);
    }
}
