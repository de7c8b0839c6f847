//! Why `eha` failed ([`CliError`]), and the process's exit status for it: 2 for bad input
//! or arguments (a bad rig file, a bad bench log, a value out of range), 1 for anything
//! else (an output that cannot be written, a failed computation).

use super::file_kind::describe;
use crate::bench_log::error::BenchLogError;
use crate::rig_file::RigFileError;
use std::io;
use std::path::PathBuf;

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
    #[error("cannot write `{}`: {}; no output written", file.display(), describe(source))]
    Write {
        /// The file.
        file: PathBuf,
        /// Why.
        source: io::Error,
    },
    /// Standard output that cannot be written (a closed pipe is no error).
    #[error("cannot write standard output: {}{}", describe(source), written(*files_written))]
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

/// `; its other outputs were written` when there were any.
fn written(files: usize) -> &'static str {
    if files == 0 {
        ""
    } else {
        "; the command's other outputs were written"
    }
}
