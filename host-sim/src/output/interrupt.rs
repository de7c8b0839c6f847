//! Interrupted runs leave nothing behind: temporary files and staging folders register
//! here while they exist, and Ctrl-C (SIGINT), SIGTERM or SIGHUP removes them before the
//! process exits with status 130. (SIGKILL cannot be caught; what it leaves are hidden
//! `.NAME.tmp-PID-N` files or `.NAME.staging-PID` folders beside the output.)

use std::path::{Path, PathBuf};
use std::sync::{Mutex, Once};

/// Paths to remove on interruption (files or folders).
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
static INSTALL: Once = Once::new();

/// Installs the signal handler (once per process; the binary's `main` calls it).
pub fn install() {
    INSTALL.call_once(|| {
        // Without a handler (another one installed first) an interruption just ends the
        // process, as it would have anyway.
        let _ = ctrlc::set_handler(|| {
            let paths = match PENDING.lock() {
                Ok(p) => p.clone(),
                Err(poisoned) => poisoned.into_inner().clone(),
            };
            for p in paths.iter().rev() {
                let _ = std::fs::remove_dir_all(p).or_else(|_| std::fs::remove_file(p));
            }
            eprintln!("eha: interrupted; no output written");
            std::process::exit(130);
        });
    });
}

/// Removes `path` if the process is interrupted while the guard lives.
#[must_use = "the path is unregistered when the guard drops"]
pub struct Guard(PathBuf);

/// Registers `path` for removal on interruption until the returned guard drops.
pub fn remove_on_interrupt(path: &Path) -> Guard {
    if let Ok(mut p) = PENDING.lock() {
        p.push(path.to_path_buf());
    }
    Guard(path.to_path_buf())
}

impl Drop for Guard {
    fn drop(&mut self) {
        if let Ok(mut p) = PENDING.lock() {
            if let Some(i) = p.iter().rposition(|q| *q == self.0) {
                p.remove(i);
            }
        }
    }
}
