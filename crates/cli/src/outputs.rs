//! Checks that every output of a command can be written before the first one is: a
//! command with two outputs (`plot … -o p.svg --csv dir/p.csv`) must not replace the first
//! and then fail on the second.

use anyhow::{bail, Result};
use std::path::Path;

/// Each path's directory exists and the path is not a directory; the option names it in
/// the error (`-o`, `--csv`).
pub fn check_writable(outputs: &[(&str, &Path)]) -> Result<()> {
    for (option, path) in outputs {
        if path.as_os_str().is_empty() {
            bail!("{option}: the output path is empty");
        }
        if path.is_dir() {
            bail!("{option} {}: is a directory, not a file", path.display());
        }
        let dir = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        if !dir.is_dir() {
            bail!(
                "{option} {}: the directory {} does not exist (nothing was written)",
                path.display(),
                dir.display()
            );
        }
        if let Ok(m) = std::fs::metadata(dir) {
            if m.permissions().readonly() {
                bail!(
                    "{option} {}: the directory {} is read-only (nothing was written)",
                    path.display(),
                    dir.display()
                );
            }
        }
    }
    Ok(())
}

/// `-o` and, when given, `--csv`.
pub fn check_with_csv(output: &Path, csv: &Option<std::path::PathBuf>) -> Result<()> {
    let mut list = vec![("-o", output)];
    if let Some(c) = csv {
        list.push(("--csv", c.as_path()));
    }
    check_writable(&list)
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
}
