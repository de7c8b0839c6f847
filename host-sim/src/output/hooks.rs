//! Test hooks into the write phase, so that the tests can interrupt a command or fill its
//! disk at a point they choose rather than at one a timer happens to hit. Off unless the
//! environment names a point; the binary then behaves as a user's would at that instant.
//!
//! - `EHA_TEST_INTERRUPT_AT=POINT`: the process sends itself SIGINT at `POINT` and waits
//!   for the handler ([`super::interrupt`]) to end it;
//! - `EHA_TEST_FULL_AT=staged:N`: staging the `N`-th output fails as a full disk does
//!   (`ENOSPC`) after its bytes were written.
//!
//! The points of a transaction ([`super::transaction::Outputs`]), counted from 1 over the
//! process: `staged:N` once the `N`-th output is staged (written whole beside its place),
//! `committed:N` once the `N`-th is moved into place (the signals held off), and `done`
//! once all are in place, before standard output is written.

use std::io;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::OnceLock;
use std::time::Duration;

/// Outputs staged so far in this process.
static STAGED: AtomicUsize = AtomicUsize::new(0);
/// A hook sent the signal while the signals were held off.
static RAISED: AtomicBool = AtomicBool::new(false);

fn setting(name: &str) -> Option<&'static str> {
    static INTERRUPT: OnceLock<Option<String>> = OnceLock::new();
    static FULL: OnceLock<Option<String>> = OnceLock::new();
    let cell = match name {
        "EHA_TEST_INTERRUPT_AT" => &INTERRUPT,
        _ => &FULL,
    };
    cell.get_or_init(|| std::env::var(name).ok()).as_deref()
}

/// Counts an output staged and returns its number, failing as a full disk when
/// `EHA_TEST_FULL_AT` names it.
pub fn staged() -> io::Result<usize> {
    let n = STAGED.fetch_add(1, Ordering::SeqCst) + 1;
    if setting("EHA_TEST_FULL_AT") == Some(format!("staged:{n}").as_str()) {
        #[cfg(unix)]
        return Err(io::Error::from_raw_os_error(libc::ENOSPC));
        #[cfg(not(unix))]
        return Err(io::Error::from(io::ErrorKind::StorageFull));
    }
    Ok(n)
}

/// Interrupts the process at `point` when `EHA_TEST_INTERRUPT_AT` names it. `held`: the
/// signals are held off here (a commit), so the handler runs once they are released
/// ([`released`]) and this returns at once; otherwise this waits for the handler to end
/// the process.
pub fn reached(point: &str, held: bool) {
    if setting("EHA_TEST_INTERRUPT_AT") != Some(point) {
        return;
    }
    #[cfg(unix)]
    // SAFETY: raise(3) only sends the calling thread a signal; the handler runs on the
    // thread `ctrlc` started.
    unsafe {
        libc::raise(libc::SIGINT);
    }
    if held {
        RAISED.store(true, Ordering::SeqCst);
    } else {
        wait_for_the_handler();
    }
}

/// The signals were released: a signal a hook sent while they were held is handled now,
/// and this waits for the handler to end the process.
pub fn released() {
    if RAISED.load(Ordering::SeqCst) {
        wait_for_the_handler();
    }
}

fn wait_for_the_handler() {
    std::thread::sleep(Duration::from_secs(60));
    eprintln!("eha: test hook: the signal handler did not end the process within 60 s");
    std::process::exit(99);
}
