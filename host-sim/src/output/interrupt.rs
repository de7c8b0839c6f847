//! Interrupted runs leave nothing behind: temporary files and staging folders register
//! here while they exist, and Ctrl-C (SIGINT), SIGTERM or SIGHUP removes them before the
//! process exits with status 130. (SIGKILL cannot be caught; what it leaves are hidden
//! `.NAME.tmp-PID-N` files or `.NAME.staging-PID` folders beside the output.)
//!
//! A command whose normal end *is* an interruption (`eha watch`, stopped with Ctrl-C)
//! holds a [`Stop`] guard instead: the first signal then only raises the flag its loop
//! polls ([`stop_requested`]), so it finishes its output itself; a second signal ends the
//! process as above.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Mutex, Once};

/// Paths to remove on interruption (files or folders).
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
static INSTALL: Once = Once::new();
/// Live [`Stop`] guards.
static STOPPERS: AtomicUsize = AtomicUsize::new(0);
/// A signal arrived while a [`Stop`] guard lived.
static STOP: AtomicBool = AtomicBool::new(false);

/// Installs the signal handler (once per process; the binary's `main` calls it).
pub fn install() {
    INSTALL.call_once(|| {
        // Without a handler (another one installed first) an interruption just ends the
        // process, as it would have anyway.
        let _ = ctrlc::set_handler(|| {
            if STOPPERS.load(Ordering::SeqCst) > 0 && !STOP.swap(true, Ordering::SeqCst) {
                return;
            }
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

/// While it lives, an interruption asks the command to stop ([`stop_requested`]) instead
/// of ending the process; a second one ends it.
#[must_use = "the signals end the process again when the guard drops"]
pub struct Stop(());

/// Turns the next interruption into a stop request until the returned guard drops.
pub fn stop_on_interrupt() -> Stop {
    STOPPERS.fetch_add(1, Ordering::SeqCst);
    Stop(())
}

impl Drop for Stop {
    fn drop(&mut self) {
        STOPPERS.fetch_sub(1, Ordering::SeqCst);
    }
}

/// True once an interruption arrived while a [`Stop`] guard lived.
pub fn stop_requested() -> bool {
    STOP.load(Ordering::SeqCst)
}
