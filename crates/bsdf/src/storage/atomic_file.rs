//! Atomic file output, the one way facette writes a file a user sees (images, tables,
//! render parts, plots, CSV, MERL files): the bytes go to a temporary file in the target's
//! directory, which is flushed and fsynced, then renamed over the target. A rename within
//! one file system is atomic, so a reader (or a crash, or a full disk) sees either the old
//! file or the complete new one — never a truncated file — and a failed write never
//! destroys a file that was there before. On failure the temporary file is removed.
//!
//! The temporary's name holds the process id and a per-process counter, and is created
//! with `create_new`: two threads or two processes writing into the same directory (even
//! the same target) never share a temporary. The last rename wins with
//! [`Existing::Replace`]; with [`Existing::Keep`] the first complete file stays.

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// What to do when the target exists.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Existing {
    Replace,
    /// Keep it and report `Ok(false)` (the rename is a no-clobber link, so two writers
    /// racing on the same path both succeed and the first one's file stays).
    Keep,
}

/// A failed atomic write: the target, what went wrong, and the I/O error kind (`Other`
/// when the caller's own writer failed).
#[derive(Debug, thiserror::Error)]
#[error("cannot write `{}`: {reason}", path.display())]
pub struct AtomicWriteError {
    pub path: PathBuf,
    pub reason: String,
    pub kind: io::ErrorKind,
}

impl From<AtomicWriteError> for io::Error {
    /// The reason alone: callers that wrap an `io::Error` name the path themselves.
    fn from(e: AtomicWriteError) -> io::Error {
        io::Error::new(e.kind, e.reason)
    }
}

/// Writes `bytes` to `path` atomically, replacing any file there.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomically_with(path, Existing::Replace, |w| {
        w.write_all(bytes).map_err(|e| format!("write failed: {e}"))
    })?;
    Ok(())
}

/// Writes `path` atomically with `fill`, which receives a buffered writer on the
/// temporary file and returns a reason on failure. Returns whether the file was written
/// (false only with [`Existing::Keep`] when the target already exists).
pub fn write_atomically_with(
    path: &Path,
    existing: Existing,
    fill: impl FnOnce(&mut BufWriter<&File>) -> Result<(), String>,
) -> Result<bool, AtomicWriteError> {
    let fail = |kind: io::ErrorKind, reason: String| AtomicWriteError {
        path: path.to_path_buf(),
        reason,
        kind,
    };
    let Some(name) = path.file_name() else {
        return Err(fail(
            io::ErrorKind::InvalidInput,
            "the path does not name a file".into(),
        ));
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if existing == Existing::Keep && path.exists() {
        return Ok(false);
    }
    let tmp = Temporary::create(&dir, &name.to_string_lossy()).map_err(|e| {
        fail(
            e.kind(),
            format!("cannot create a temporary file in `{}`: {e}", dir.display()),
        )
    })?;
    {
        let mut w = BufWriter::new(&tmp.file);
        fill(&mut w).map_err(|r| fail(io::ErrorKind::Other, r))?;
        w.flush()
            .map_err(|e| fail(e.kind(), format!("write failed: {e}")))?;
    }
    tmp.file
        .sync_all()
        .map_err(|e| fail(e.kind(), format!("fsync failed: {e}")))?;
    // A replaced file keeps its permissions.
    if let Ok(meta) = std::fs::metadata(path) {
        if meta.is_file() {
            let _ = std::fs::set_permissions(&tmp.path, meta.permissions());
        }
    }
    let written = tmp
        .persist(path, existing)
        .map_err(|e| fail(e.kind(), format!("cannot rename the temporary file: {e}")))?;
    // Make the rename itself durable; not every platform can fsync a directory, and the
    // data is already safe, so a failure here is not an error.
    if let Ok(d) = File::open(&dir) {
        let _ = d.sync_all();
    }
    Ok(written)
}

/// Counter that makes temporary names unique within the process (across threads).
static NEXT_TEMPORARY: AtomicU64 = AtomicU64::new(0);

/// A temporary file, removed when dropped unless persisted.
struct Temporary {
    file: File,
    path: PathBuf,
    persisted: bool,
}

impl Temporary {
    /// `.{name}.{pid}-{counter}.tmp` in `dir`, created new (never an existing file: a
    /// leftover of a crashed process with the same pid is skipped).
    fn create(dir: &Path, name: &str) -> io::Result<Temporary> {
        loop {
            let k = NEXT_TEMPORARY.fetch_add(1, Ordering::Relaxed);
            let path = dir.join(format!(".{name}.{}-{k}.tmp", std::process::id()));
            // Like a plain `File::create`: rw for everyone, reduced by the umask.
            match OpenOptions::new().write(true).create_new(true).open(&path) {
                Ok(file) => {
                    return Ok(Temporary {
                        file,
                        path,
                        persisted: false,
                    })
                }
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        }
    }

    /// Moves the temporary to `target`; with [`Existing::Keep`], returns `Ok(false)` and
    /// leaves `target` alone when it exists.
    fn persist(mut self, target: &Path, existing: Existing) -> io::Result<bool> {
        match existing {
            Existing::Replace => {
                std::fs::rename(&self.path, target)?;
                self.persisted = true;
                Ok(true)
            }
            // A hard link fails, atomically, when the target exists: the no-clobber
            // rename. The temporary name is removed on drop either way.
            Existing::Keep => match std::fs::hard_link(&self.path, target) {
                Ok(()) => Ok(true),
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => Ok(false),
                Err(e) => Err(e),
            },
        }
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        if !self.persisted {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!(
            "facette-atomic-{name}-{}-{}",
            std::process::id(),
            NEXT_TEMPORARY.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn leftovers(dir: &Path) -> Vec<String> {
        std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".tmp"))
            .collect()
    }

    fn put(w: &mut BufWriter<&File>, bytes: &[u8]) -> Result<(), String> {
        w.write_all(bytes).map_err(|e| e.to_string())
    }

    #[test]
    fn replaces_and_keeps() {
        let dir = scratch("keep");
        let p = dir.join("a.bin");
        assert!(write_atomically_with(&p, Existing::Replace, |w| put(w, b"one")).unwrap());
        assert!(!write_atomically_with(&p, Existing::Keep, |w| put(w, b"two")).unwrap());
        assert_eq!(std::fs::read(&p).unwrap(), b"one");
        write_atomically(&p, b"three").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"three");
        let q = dir.join("b.bin");
        assert!(write_atomically_with(&q, Existing::Keep, |w| put(w, b"new")).unwrap());
        assert_eq!(std::fs::read(&q).unwrap(), b"new");
        assert!(leftovers(&dir).is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_failing_writer_leaves_the_target_and_no_temporary() {
        let dir = scratch("fail");
        let p = dir.join("a.bin");
        std::fs::write(&p, b"precious").unwrap();
        let err = write_atomically_with(&p, Existing::Replace, |w| {
            put(w, &[0u8; 100_000])?;
            Err("encoder failed halfway".into())
        })
        .unwrap_err();
        assert!(err.to_string().contains("encoder failed halfway"), "{err}");
        assert_eq!(err.path, p);
        assert_eq!(std::fs::read(&p).unwrap(), b"precious");
        assert!(leftovers(&dir).is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_missing_directory_is_an_error_naming_it() {
        let dir = scratch("missing");
        let err = write_atomically(&dir.join("no/such/x.bin"), b"x").unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::NotFound);
        assert!(err.to_string().contains("temporary file"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn threads_writing_into_one_directory_never_collide() {
        // Eight threads each write their own file and race on a shared one, many times:
        // every write succeeds, every file holds one writer's complete bytes.
        let dir = scratch("threads");
        let shared = dir.join("shared.bin");
        std::thread::scope(|s| {
            for t in 0..8u8 {
                let (dir, shared) = (&dir, &shared);
                s.spawn(move || {
                    let body = vec![t; 64 * 1024];
                    for _ in 0..25 {
                        write_atomically(&dir.join(format!("own-{t}.bin")), &body).unwrap();
                        write_atomically(shared, &body).unwrap();
                        write_atomically_with(&dir.join("first.bin"), Existing::Keep, |w| {
                            put(w, &body)
                        })
                        .unwrap();
                    }
                });
            }
        });
        for t in 0..8u8 {
            assert_eq!(
                std::fs::read(dir.join(format!("own-{t}.bin"))).unwrap(),
                vec![t; 64 * 1024]
            );
        }
        for p in [&shared, &dir.join("first.bin")] {
            let bytes = std::fs::read(p).unwrap();
            assert_eq!(bytes.len(), 64 * 1024);
            assert!(bytes.iter().all(|b| *b == bytes[0]));
        }
        assert!(leftovers(&dir).is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    #[cfg(unix)]
    fn new_files_are_not_private() {
        use std::os::unix::fs::PermissionsExt;
        let dir = scratch("mode");
        let p = dir.join("a.bin");
        write_atomically(&p, b"").unwrap();
        let mode = std::fs::metadata(&p).unwrap().permissions().mode();
        // The same mode as a plain `File::create` under the same umask.
        let q = dir.join("b.bin");
        File::create(&q).unwrap();
        let plain = std::fs::metadata(&q).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, plain & 0o777);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
