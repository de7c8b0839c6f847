//! Interrupted runs leave all of a command's outputs or none: what is being staged
//! (temporary files, staging folders, [`super::transaction`]) registers here while it
//! exists, and Ctrl-C (SIGINT), SIGTERM or SIGHUP removes it before the process exits with
//! status 130, saying "no output written". The commit that moves the staged outputs into
//! place holds the signals off ([`held`]): a signal arriving meanwhile is handled once every
//! output is in place, and then says so. (SIGKILL cannot be caught; what it leaves are
//! hidden `.NAME.*.eha-tmp` files and `.NAME.*.eha-staging` folders beside the outputs, or
//! during a commit `.NAME.eha-old-*` copies of the outputs replaced.)
//!
//! A command whose normal end *is* an interruption (`eha watch`, stopped with Ctrl-C)
//! holds a [`Stop`] guard instead: the first signal then only raises the flag its loop
//! polls ([`stop_requested`]), so it finishes its output itself; a second signal ends the
//! process as above.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard, Once};
use std::time::Duration;

/// What an interruption must clean up, and what was already committed.
#[derive(Debug, Default)]
pub struct Pending {
    /// Paths to remove on interruption (files or folders), in the order registered.
    paths: Vec<PathBuf>,
    /// Transactions committed so far.
    committed: usize,
}

impl Pending {
    /// Forgets `path`: it was moved into place (or removed) and must stay as it is.
    pub fn forget(&mut self, path: &Path) {
        if let Some(i) = self.paths.iter().rposition(|q| q == path) {
            self.paths.remove(i);
        }
    }

    /// Registers `path` for removal on interruption until the returned guard drops (which
    /// must not happen inside [`held`]).
    pub fn register(&mut self, path: &Path) -> Guard {
        self.paths.push(path.to_path_buf());
        Guard(path.to_path_buf())
    }

    /// Counts a transaction whose outputs are all in place.
    pub fn committed(&mut self) {
        self.committed += 1;
    }
}

/// The one registry; its lock is what holds the signals off during a commit.
static PENDING: Mutex<Pending> = Mutex::new(Pending {
    paths: Vec::new(),
    committed: 0,
});
static INSTALL: Once = Once::new();
/// Live [`Stop`] guards.
static STOPPERS: AtomicUsize = AtomicUsize::new(0);
/// A signal arrived while a [`Stop`] guard lived.
static STOP: AtomicBool = AtomicBool::new(false);
/// A signal is being handled: the process is about to exit with status 130.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

fn lock() -> MutexGuard<'static, Pending> {
    PENDING
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Installs the signal handler (once per process; the binary's `main` calls it).
pub fn install() {
    INSTALL.call_once(|| {
        // Without a handler (another one installed first) an interruption just ends the
        // process, as it would have anyway.
        let _ = ctrlc::set_handler(|| {
            if STOPPERS.load(Ordering::SeqCst) > 0 && !STOP.swap(true, Ordering::SeqCst) {
                return;
            }
            INTERRUPTED.store(true, Ordering::SeqCst);
            // Waits for a commit under way to finish (or to roll back).
            let pending = lock();
            for p in pending.paths.iter().rev() {
                let _ = std::fs::remove_dir_all(p).or_else(|_| std::fs::remove_file(p));
            }
            eprintln!(
                "eha: {}",
                message(pending.committed, !pending.paths.is_empty())
            );
            std::process::exit(130);
        });
    });
}

/// What an interruption left: `committed` transactions in place, `removed` whether staged
/// outputs were just removed.
fn message(committed: usize, removed: bool) -> &'static str {
    match (committed, removed) {
        (0, _) => "interrupted; no output written",
        (_, false) => "interrupted after every output was written",
        (_, true) => {
            "interrupted; the outputs being written were removed (those written before are \
             complete)"
        }
    }
}

/// True once a signal is being handled (the process is about to exit with status 130).
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

/// Blocks for good when a signal is being handled, so that the handler's exit status and
/// message are the process's, not an error the clean-up caused on the main thread.
pub fn wait_if_interrupted() {
    while interrupted() {
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// Runs `f` with the signals held off: a signal arriving meanwhile is handled once `f`
/// returns, seeing what `f` registered, forgot and committed. (`f` must not drop a
/// [`Guard`]: that takes the same lock.)
pub fn held<T>(f: impl FnOnce(&mut Pending) -> T) -> T {
    f(&mut lock())
}

/// Removes `path` if the process is interrupted while the guard lives.
#[must_use = "the path is unregistered when the guard drops"]
pub struct Guard(PathBuf);

/// Registers `path` for removal on interruption until the returned guard drops.
pub fn remove_on_interrupt(path: &Path) -> Guard {
    lock().register(path)
}

impl Drop for Guard {
    fn drop(&mut self) {
        lock().forget(&self.0);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_message_says_whether_outputs_were_written() {
        assert!(message(0, true).contains("no output written"));
        assert!(message(0, false).contains("no output written"));
        assert!(message(1, false).contains("every output was written"));
        assert!(message(2, true).contains("removed"));
    }
}
