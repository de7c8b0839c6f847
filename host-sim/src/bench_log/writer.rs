//! The writer (`bench-log.md`, "File"): a log checked against the contract's rules first
//! ([`BenchLog::check`]), so that every file written reads back, then its metadata lines,
//! the header of the columns present and one row per sample, the values in shortest
//! round-trip notation ([`super::number`]), as an output of the command's transaction
//! ([`crate::output::Outputs`]): a failed write leaves no partial file.

use super::columns::{BenchLog, Signal};
use super::error::BenchLogError;
use super::number;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// Writes `log` to `path` as a command's one output ([`crate::output::Outputs`]), after
/// [`BenchLog::check`]: metadata lines, the header of the columns present, one row per
/// sample in shortest round-trip notation.
pub fn write(path: &Path, log: &BenchLog) -> Result<(), BenchLogError> {
    let mut out = crate::output::Outputs::new();
    stage(&mut out, "", path, log)
        .and_then(|()| out.commit())
        .map_err(|e| match e {
            crate::output::CliError::BenchLog(e) => e,
            crate::output::CliError::Write { file, source } => {
                BenchLogError::Write { file, source }
            }
            e => BenchLogError::Write {
                file: path.to_path_buf(),
                source: io::Error::other(e.to_string()),
            },
        })
}

/// Stages `log` (checked first) as the output file `path` given by `flag`.
pub fn stage(
    out: &mut crate::output::Outputs,
    flag: &str,
    path: &Path,
    log: &BenchLog,
) -> Result<(), crate::output::CliError> {
    log.check(path)?;
    out.file_with(flag, path, |w| write_to(w, log))
}

/// Writes `log` (checked first) as the file `name` of a staged output folder.
pub fn write_into(
    d: &crate::output::StagedFolder,
    name: &str,
    log: &BenchLog,
) -> Result<(), crate::output::CliError> {
    log.check(&d.shown(name))?;
    d.file_with(name, |w| write_to(w, log))
}

/// `log` as the bytes [`write`] puts in a file, after the same checks.
pub fn to_bytes(log: &BenchLog) -> Result<Vec<u8>, BenchLogError> {
    log.check(Path::new(IN_MEMORY))?;
    let mut out = Vec::new();
    write_to(&mut out, log).map_err(|source| BenchLogError::Write {
        file: PathBuf::from(IN_MEMORY),
        source,
    })?;
    Ok(out)
}

/// What errors about a log held in memory name as its file.
const IN_MEMORY: &str = "<in memory>";

/// Writes `log` (assumed checked) to `w`: the metadata lines, the header, the rows. Names
/// and numbers never need CSV quoting, so the rows are spelled directly, a block of them
/// at a time.
fn write_to(w: &mut dyn Write, log: &BenchLog) -> io::Result<()> {
    for (k, v) in &log.metadata {
        writeln!(w, "# {k}: {v}")?;
    }
    let columns: Vec<(Signal, &[f64])> = log.columns().collect();
    let names: Vec<&str> = columns.iter().map(|(s, _)| s.name()).collect();
    writeln!(w, "{}", names.join(","))?;
    let mut block: Vec<u8> = Vec::with_capacity(1 << 16);
    for row in 0..log.len() {
        for (k, (_, c)) in columns.iter().enumerate() {
            if k > 0 {
                block.push(b',');
            }
            number::push_bytes(&mut block, c.get(row).copied().unwrap_or(f64::NAN));
        }
        block.push(b'\n');
        if block.len() >= 1 << 15 {
            w.write_all(&block)?;
            block.clear();
        }
    }
    w.write_all(&block)?;
    w.flush()
}

/// Shortest round-trip text of `v`: the fewest digits that parse back to the same f64;
/// positional for ordinary magnitudes, exponent notation for very small or large ones
/// (where positional would spell out dozens of zeros) — Rust's float formatting, spelled
/// faster ([`number`]).
pub fn format_value(out: &mut String, v: f64) {
    number::push(out, v);
}
