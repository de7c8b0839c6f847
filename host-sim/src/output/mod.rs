//! What every subcommand reports through: the error type [`CliError`] with its exit status,
//! standard output that tolerates a closed pipe ([`print_stdout`]), JSON documents written
//! to a file or standard output ([`write_json`]), and output files that appear whole or not
//! at all ([`atomic`]); the paths a subcommand is given, checked before it runs
//! ([`paths`]); and clean-up when a run is interrupted ([`interrupt`]).
//!
//! Exit status: 0 on success, 2 for bad input or arguments (a bad rig file, a bad bench
//! log, a value out of range), 1 for anything else; the message goes to standard error.

pub mod atomic;
pub mod interrupt;
pub mod paths;
pub mod progress;

use crate::bench_log::BenchLogError;
use crate::rig_file::RigFileError;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// Why `eha` failed.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// A bench log that cannot be read (bad input) or written.
    #[error(transparent)]
    BenchLog(#[from] BenchLogError),
    /// A rig file that cannot be used.
    #[error(transparent)]
    RigFile(#[from] RigFileError),
    /// An argument or input value that makes no sense.
    #[error("{0}")]
    BadInput(String),
    /// An output file that cannot be written.
    #[error("cannot write `{}`: {source}", file.display())]
    Write {
        /// The file.
        file: PathBuf,
        /// Why.
        source: io::Error,
    },
    /// Any other failure.
    #[error("{0}")]
    Failed(String),
}

impl CliError {
    /// Exit status: 2 for bad input or arguments, 1 for anything else.
    pub fn exit_status(&self) -> u8 {
        match self {
            CliError::BenchLog(e) if e.is_bad_input() => 2,
            CliError::RigFile(_) | CliError::BadInput(_) => 2,
            _ => 1,
        }
    }
}

/// `-` means standard output.
pub fn is_stdout(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// Writes one JSON object, pretty-printed, to `path` atomically or to standard output.
pub fn write_json(path: &Path, value: &serde_json::Value) -> Result<(), CliError> {
    let mut text =
        serde_json::to_string_pretty(value).map_err(|e| CliError::Failed(e.to_string()))?;
    text.push('\n');
    if is_stdout(path) {
        print_stdout(&text)
    } else {
        atomic::write(path, text.as_bytes()).map_err(|source| CliError::Write {
            file: path.to_path_buf(),
            source,
        })
    }
}

/// Writes `text` to standard output; a closed pipe (`eha rig | head`) is not an error.
pub fn print_stdout(text: &str) -> Result<(), CliError> {
    let mut out = io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != io::ErrorKind::BrokenPipe => Err(CliError::Write {
            file: PathBuf::from("<standard output>"),
            source: e,
        }),
        _ => Ok(()),
    }
}

/// A fresh, empty scratch folder `eha-<name>-<pid>` for a unit test.
#[cfg(test)]
pub(crate) fn scratch_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("eha-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}
