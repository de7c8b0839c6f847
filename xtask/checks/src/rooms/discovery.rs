//! Which files a crate has: every `.rs` file under its `src/` with its line count (the
//! long-file list), and the roots its module trees grow from (`lib.rs`, `main.rs`,
//! `bin/*.rs`, `bin/*/main.rs`), each a separate tree as Cargo compiles them.

use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// A source file and how many lines it has.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Sized {
    /// The file.
    pub path: PathBuf,
    /// Its lines (as `wc -l` counts them when the file ends in a newline).
    pub lines: usize,
}

/// Every `.rs` file below `src`, sorted by path, with its line count.
pub fn rust_files(src: &Path) -> Result<Vec<Sized>> {
    let mut out = Vec::new();
    for entry in walkdir::WalkDir::new(src).sort_by_file_name() {
        let entry = entry.with_context(|| format!("listing {}", src.display()))?;
        let path = entry.path();
        if !entry.file_type().is_file() || path.extension().is_none_or(|e| e != "rs") {
            continue;
        }
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        out.push(Sized {
            path: path.to_path_buf(),
            lines: text.lines().count(),
        });
    }
    Ok(out)
}

/// The files of `files` with more than `limit` lines.
pub fn long_files(files: &[Sized], limit: usize) -> Vec<Sized> {
    files.iter().filter(|f| f.lines > limit).cloned().collect()
}

/// The crate roots below `src`: the library, the default binary, and `bin/` binaries.
pub fn roots(src: &Path) -> Result<Vec<PathBuf>> {
    let mut roots: Vec<PathBuf> = ["lib.rs", "main.rs"]
        .iter()
        .map(|f| src.join(f))
        .filter(|p| p.is_file())
        .collect();
    let bin = src.join("bin");
    if bin.is_dir() {
        let mut bins = Vec::new();
        for entry in
            std::fs::read_dir(&bin).with_context(|| format!("listing {}", bin.display()))?
        {
            let path = entry?.path();
            if path.extension().is_some_and(|e| e == "rs") && path.is_file() {
                bins.push(path);
            } else if path.join("main.rs").is_file() {
                bins.push(path.join("main.rs"));
            }
        }
        bins.sort();
        roots.extend(bins);
    }
    Ok(roots)
}
