//! Atomic file replacement: the bytes go to a temporary file in the destination directory,
//! which is flushed and fsynced, then renamed over the target. A rename within one file
//! system is atomic, so a reader (or a crash, or a full disk) sees either the old file or
//! the complete new one — never a truncated image, and a failed write never destroys a
//! file that was there before. On failure the temporary file is removed
//! (`tempfile::NamedTempFile` deletes it on drop).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use super::error::ImageError;

/// What to do when the target exists.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Existing {
    Replace,
    /// Keep it and report `Ok(false)` (the rename is a no-clobber link, so two writers
    /// racing on the same path both succeed and the first one's file stays).
    Keep,
}

/// Writes `path` atomically with `fill`, which receives a buffered writer on the
/// temporary file and returns a reason on failure. Returns whether the file was written
/// (false only with [`Existing::Keep`] when the target already exists).
pub(crate) fn write_atomically(
    path: &Path,
    existing: Existing,
    fill: impl FnOnce(&mut BufWriter<&File>) -> Result<(), String>,
) -> Result<bool, ImageError> {
    let fail = |reason: String| ImageError::Write {
        path: path.to_path_buf(),
        reason,
    };
    let name = path
        .file_name()
        .ok_or_else(|| fail("the path does not name a file".into()))?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if existing == Existing::Keep && path.exists() {
        return Ok(false);
    }
    let prefix = format!(".{}.", name.to_string_lossy());
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    // Like a plain `File::create`: rw for everyone, reduced by the umask (tempfile's own
    // default, 0600, would make every output private).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let tmp = builder.tempfile_in(&dir).map_err(|e| {
        fail(format!(
            "cannot create a temporary file in `{}`: {e}",
            dir.display()
        ))
    })?;

    {
        let mut w = BufWriter::new(tmp.as_file());
        fill(&mut w).map_err(&fail)?;
        w.flush().map_err(|e| fail(format!("write failed: {e}")))?;
    }
    tmp.as_file()
        .sync_all()
        .map_err(|e| fail(format!("fsync failed: {e}")))?;
    // A replaced file keeps its permissions.
    if let Ok(meta) = std::fs::metadata(path) {
        if meta.is_file() {
            let _ = std::fs::set_permissions(tmp.path(), meta.permissions());
        }
    }
    let written = match existing {
        Existing::Replace => {
            tmp.persist(path)
                .map_err(|e| fail(format!("cannot rename the temporary file: {}", e.error)))?;
            true
        }
        Existing::Keep => match tmp.persist_noclobber(path) {
            Ok(_) => true,
            Err(e) if e.error.kind() == std::io::ErrorKind::AlreadyExists => false,
            Err(e) => {
                return Err(fail(format!(
                    "cannot rename the temporary file: {}",
                    e.error
                )))
            }
        },
    };
    // Make the rename itself durable; not every platform can fsync a directory, and the
    // data is already safe, so a failure here is not an error.
    if let Ok(d) = File::open(&dir) {
        let _ = d.sync_all();
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn leftovers(dir: &Path) -> Vec<String> {
        std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".tmp"))
            .collect()
    }

    #[test]
    fn replaces_and_keeps() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.bin");
        assert!(write_atomically(&p, Existing::Replace, |w| {
            w.write_all(b"one").map_err(|e| e.to_string())
        })
        .unwrap());
        assert!(!write_atomically(&p, Existing::Keep, |w| {
            w.write_all(b"two").map_err(|e| e.to_string())
        })
        .unwrap());
        assert_eq!(std::fs::read(&p).unwrap(), b"one");
        write_atomically(&p, Existing::Replace, |w| {
            w.write_all(b"three").map_err(|e| e.to_string())
        })
        .unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"three");
        assert!(leftovers(dir.path()).is_empty());
    }

    #[test]
    fn a_failing_writer_leaves_the_target_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.bin");
        std::fs::write(&p, b"precious").unwrap();
        let err = write_atomically(&p, Existing::Replace, |w| {
            w.write_all(&[0u8; 100_000]).map_err(|e| e.to_string())?;
            Err("encoder failed halfway".into())
        })
        .unwrap_err();
        assert!(err.to_string().contains("encoder failed halfway"), "{err}");
        assert_eq!(err.path(), p.as_path());
        assert_eq!(std::fs::read(&p).unwrap(), b"precious");
        assert!(leftovers(dir.path()).is_empty());
    }

    #[test]
    #[cfg(unix)]
    fn new_files_are_not_private() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.bin");
        write_atomically(&p, Existing::Replace, |_| Ok(())).unwrap();
        let mode = std::fs::metadata(&p).unwrap().permissions().mode();
        // The same mode as a plain `File::create` under the same umask.
        let q = dir.path().join("b.bin");
        std::fs::File::create(&q).unwrap();
        let plain = std::fs::metadata(&q).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, plain & 0o777);
    }
}
