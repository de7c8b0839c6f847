//! Standard output as an output: `-` names it where a path is asked for ([`is_stdout`]),
//! and writing to it treats a closed pipe (`eha rig | head`) as no error
//! ([`print_stdout`]).

use super::error::CliError;
use std::io::{self, Write};
use std::path::Path;

/// `-` means standard output.
pub fn is_stdout(path: &Path) -> bool {
    path.as_os_str() == "-"
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
