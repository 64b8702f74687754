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
