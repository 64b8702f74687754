//! What every `create_*` function of the builder needs besides its own description:
//! where errors point (the description's spans) and where relative paths start.

use crate::scene::source::Spans;
use crate::scene::SceneError;
use std::ops::Range;
use std::path::PathBuf;

pub(crate) struct Ctx<'a> {
    pub spans: Spans<'a>,
    /// Directory that relative paths of the description are resolved against.
    pub base_dir: PathBuf,
}

impl Ctx<'_> {
    /// An error at `span` of the description (file and line resolved by the spans).
    pub fn err(&self, span: Option<Range<usize>>, message: impl Into<String>) -> SceneError {
        self.spans.err(span, message)
    }
}
