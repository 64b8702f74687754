//! Checks that every output of a command can be written before the first one is — and
//! before the work that produces them starts. A command with two outputs (`plot … -o p.svg
//! --csv dir/p.csv`) must not replace the first and then fail on the second, and an hour of
//! rendering or tabulating must not end in "cannot write" because of a typo in a directory
//! name. Every command that writes files calls [`check_writable`] first.

use anyhow::{bail, Result};
use std::fs::OpenOptions;
use std::path::{Path, PathBuf};

/// Each output (the option that names it, its path) can be written: the path is not
/// empty, not a directory, not read-only, its directory exists, and a file can be created
/// there. The last is proved by creating and removing an empty probe file, because
/// permission bits do not tell (root ignores them; ACLs and read-only mounts are not in
/// them). Nothing else is touched: an existing output stays as it is until the command
/// writes it atomically.
pub fn check_writable(outputs: &[(&str, &Path)]) -> Result<()> {
    for (option, path) in outputs {
        check_one(option, path)?;
    }
    // Two options naming one file: the second write would replace the first.
    let key = |p: &Path| {
        let dir = std::fs::canonicalize(parent_dir(p)).unwrap_or_else(|_| parent_dir(p).into());
        dir.join(p.file_name().unwrap_or_default())
    };
    for (i, (a, pa)) in outputs.iter().enumerate() {
        for (b, pb) in &outputs[i + 1..] {
            if key(pa) == key(pb) {
                bail!(
                    "{a} {} and {b} {} name the same file: the second would replace the first (nothing was written)",
                    pa.display(),
                    pb.display()
                );
            }
        }
    }
    Ok(())
}

fn check_one(option: &str, path: &Path) -> Result<()> {
    if path.as_os_str().is_empty() {
        bail!("{option}: the output path is empty");
    }
    if path.is_dir() {
        bail!("{option} {}: is a directory, not a file", path.display());
    }
    let dir = parent_dir(path);
    if !dir.is_dir() {
        bail!(
            "{option} {}: the directory {} does not exist (nothing was written)",
            path.display(),
            dir.display()
        );
    }
    if let Ok(m) = std::fs::metadata(path) {
        if m.permissions().readonly() {
            bail!(
                "{option} {}: the file exists and is read-only (nothing was written)",
                path.display()
            );
        }
    }
    let probe = dir.join(format!(
        ".facette-write-check-{}-{}",
        std::process::id(),
        path.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    ));
    match OpenOptions::new().write(true).create_new(true).open(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        // A probe left by a crashed run of the same process id: the directory is writable.
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(()),
        Err(e) => bail!(
            "{option} {}: cannot create a file in {} ({e}; nothing was written)",
            path.display(),
            dir.display()
        ),
    }
}

fn parent_dir(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// `-o` and, when given, `--csv`.
pub fn check_with_csv(output: &Path, csv: &Option<PathBuf>) -> Result<()> {
    let mut list = vec![("-o", output)];
    if let Some(c) = csv {
        list.push(("--csv", c.as_path()));
    }
    check_writable(&list)
}

/// An output directory holding several files (`reproduce -o DIR`): it is a directory or
/// can be created as one, and each of `files` in it is writable. Creates nothing.
pub fn check_output_dir(option: &str, dir: &Path, files: &[String]) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!(
            "{option} {}: is a file, not a directory (nothing was written)",
            dir.display()
        );
    }
    // The nearest existing ancestor must let us create the missing levels.
    let mut existing = dir;
    while !existing.exists() {
        existing = match existing.parent().filter(|p| !p.as_os_str().is_empty()) {
            Some(p) => p,
            None => Path::new("."),
        };
        if existing == Path::new(".") {
            break;
        }
    }
    if !existing.is_dir() {
        bail!(
            "{option} {}: {} is not a directory (nothing was written)",
            dir.display(),
            existing.display()
        );
    }
    if dir.is_dir() {
        for f in files {
            check_one(option, &dir.join(f))?;
        }
    } else {
        check_one(option, &existing.join(".facette-dir-check"))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_directory_is_named_before_anything_is_written() {
        let e = check_writable(&[
            ("-o", Path::new("p.svg")),
            ("--csv", Path::new("no/dir/p.csv")),
        ])
        .unwrap_err();
        assert!(e.to_string().contains("--csv no/dir/p.csv"), "{e}");
        assert!(check_writable(&[("-o", Path::new("."))]).is_err());
    }

    #[test]
    fn two_options_naming_one_file_are_refused() {
        let d = tempfile::tempdir().unwrap();
        let a = d.path().join("p.svg");
        let b = d.path().join(".").join("p.svg");
        let e = check_writable(&[("-o", &a), ("--csv", &b)]).unwrap_err();
        assert!(e.to_string().contains("name the same file"), "{e}");
        check_writable(&[("-o", &a), ("--csv", &d.path().join("p.csv"))]).unwrap();
    }

    #[test]
    fn the_probe_leaves_nothing_behind() {
        let d = tempfile::tempdir().unwrap();
        let out = d.path().join("x.exr");
        check_writable(&[("-o", &out)]).unwrap();
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0);
    }

    #[test]
    fn an_output_directory_that_is_a_file_is_refused() {
        let d = tempfile::tempdir().unwrap();
        let f = d.path().join("figures");
        std::fs::write(&f, "x").unwrap();
        let e = check_output_dir("-o", &f, &["a.svg".into()]).unwrap_err();
        assert!(e.to_string().contains("is a file"), "{e}");
        check_output_dir("-o", &d.path().join("new/deeper"), &["a.svg".into()]).unwrap();
        assert!(!d.path().join("new").exists());
    }

    #[test]
    fn a_read_only_file_is_refused() {
        let d = tempfile::tempdir().unwrap();
        let f = d.path().join("t.fctab");
        std::fs::write(&f, "x").unwrap();
        let mut p = std::fs::metadata(&f).unwrap().permissions();
        p.set_readonly(true);
        std::fs::set_permissions(&f, p).unwrap();
        let e = check_writable(&[("-o", &f)]).unwrap_err();
        assert!(e.to_string().contains("read-only"), "{e}");
    }
}
