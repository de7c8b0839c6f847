//! What every subcommand reports through: the error type [`CliError`] with its exit status,
//! the paths it is given, checked before it runs ([`paths`], [`folder`]), its outputs as one
//! transaction ([`transaction`]: every file, folder and standard output of a command
//! written together at the end, or none), clean-up when a run is interrupted
//! ([`interrupt`]), and progress on a terminal ([`progress`]).
//!
//! Exit status: 0 on success, 2 for bad input or arguments (a bad rig file, a bad bench
//! log, a value out of range), 1 for anything else; the message goes to standard error.
//!
//! # Writing a command's outputs
//!
//! A command declares the paths it reads and writes, with the files an output folder of
//! its own may hold; `eha` checks them all before the command starts ([`paths::check`]):
//!
//! ```ignore
//! /// The files `eha fleet` writes into its folder.
//! pub const FILES: &[&str] = &["fleet.csv", "fleet.json", "trends.csv", "trend_*.svg", "trend_*.png"];
//!
//! impl FleetArgs {
//!     pub fn paths(&self) -> Declared<'_> {
//!         Declared::default()
//!             .input("--manifest", self.manifest.as_ref())
//!             .dir("--out", Some(&self.out), FILES)
//!             .file("--json", self.json.as_ref())
//!     }
//! }
//! ```
//!
//! When its work is done it stages every output, then commits them together:
//!
//! ```ignore
//! let mut out = Outputs::new();
//! out.folder("--out", &args.out, FILES, |d| {
//!     d.file("fleet.csv", table.as_bytes())?;            // or d.file_with(name, |w| …)
//!     figure.write_into(d, "trend_drive7.svg")?;          // plots render, the folder writes
//!     Ok(())
//! })?;
//! if let Some(path) = &args.json {
//!     out.json("--json", path, &value)?;                  // `-`: standard output
//! }
//! out.print(&summary);                                    // standard output, after the files
//! out.commit()
//! ```
//!
//! Nothing appears until [`Outputs::commit`]; an error (or `?`) before it drops the
//! transaction and removes what was staged. A command that keeps results across runs
//! commits each in a transaction of its own; an interruption then keeps the committed
//! ones and says so.

pub mod folder;
pub mod hooks;
pub mod interrupt;
pub mod paths;
pub mod progress;
pub mod transaction;

pub use transaction::{Outputs, StagedFolder};

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
    /// An output that cannot be staged or moved into place: none of the command's
    /// outputs is written.
    #[error("cannot write `{}`: {}; no output written", file.display(), paths::describe(source))]
    Write {
        /// The file.
        file: PathBuf,
        /// Why.
        source: io::Error,
    },
    /// Standard output that cannot be written (a closed pipe is no error).
    #[error("cannot write standard output: {}{}", paths::describe(source), written(*files_written))]
    Stdout {
        /// Why.
        source: io::Error,
        /// Outputs (files and folders) in place before: all of the command's others.
        files_written: usize,
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

/// `; its other outputs were written` when there were any.
fn written(files: usize) -> &'static str {
    if files == 0 {
        ""
    } else {
        "; the command's other outputs were written"
    }
}

/// Writes `text` to standard output; a closed pipe (`eha rig | head`) is not an error.
pub fn print_stdout(text: &str) -> Result<(), CliError> {
    let mut out = io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != io::ErrorKind::BrokenPipe => Err(CliError::Stdout {
            source: e,
            files_written: 0,
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
