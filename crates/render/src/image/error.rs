//! Errors of the image module. Every variant names the file it concerns and says why in
//! plain words: a missing, corrupt, truncated or unsupported file is reported, never a
//! panic and never an image with NaN pixels.

use std::path::PathBuf;

use facette_bsdf::storage::atomic_file::AtomicWriteError;
use facette_bsdf::ParamError;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum ImageError {
    /// The file could not be opened or read (missing, permissions, I/O failure).
    #[error("cannot read image `{path}`: {source}")]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The file's first bytes match none of the formats we read.
    #[error(
        "cannot read image `{path}`: unrecognized file format (facette reads PNG, OpenEXR \
         and Radiance HDR files)"
    )]
    UnknownFormat { path: PathBuf },
    /// The file claims to be of `format` but is corrupt or truncated.
    #[error("cannot read image `{path}`: not a valid {format} file: {reason}")]
    Corrupt {
        path: PathBuf,
        format: &'static str,
        reason: String,
    },
    /// A valid file whose content we do not support (deep data, no colour channels, …).
    #[error("cannot read image `{path}`: unsupported {format} content: {reason}")]
    Unsupported {
        path: PathBuf,
        format: &'static str,
        reason: String,
    },
    /// The output extension names no format we write.
    #[error(
        "cannot write image `{path}`: unsupported extension {extension}; supported \
         extensions: .exr, .png"
    )]
    UnsupportedExtension { path: PathBuf, extension: String },
    /// Writing failed; the target (if it existed) is untouched and no temporary file is
    /// left behind.
    #[error("cannot write image `{path}`: {reason}")]
    Write { path: PathBuf, reason: String },
    /// The data handed to a writer or builder is inconsistent (channel lengths, names).
    #[error("invalid image data for `{path}`: {reason}")]
    InvalidData { path: PathBuf, reason: String },
    /// A parameter of something stored in a file (e.g. the sky) is out of range.
    #[error("cannot create `{path}`: {source}")]
    Param {
        path: PathBuf,
        #[source]
        source: ParamError,
    },
}

impl ImageError {
    /// The file the error is about.
    pub fn path(&self) -> &std::path::Path {
        match self {
            ImageError::Read { path, .. }
            | ImageError::UnknownFormat { path }
            | ImageError::Corrupt { path, .. }
            | ImageError::Unsupported { path, .. }
            | ImageError::UnsupportedExtension { path, .. }
            | ImageError::Write { path, .. }
            | ImageError::InvalidData { path, .. }
            | ImageError::Param { path, .. } => path,
        }
    }
}

impl From<AtomicWriteError> for ImageError {
    fn from(e: AtomicWriteError) -> ImageError {
        ImageError::Write {
            path: e.path,
            reason: e.reason,
        }
    }
}
