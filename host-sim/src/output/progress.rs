//! Progress on standard error for runs that take long (indicatif): drawn only on a
//! terminal, so pipes and logs stay clean.

use indicatif::{ProgressBar, ProgressStyle};
use std::time::Duration;

/// A spinner with `message` and the elapsed time, ticking until finished.
pub fn spinner(message: String) -> ProgressBar {
    let b = ProgressBar::new_spinner();
    b.set_style(
        ProgressStyle::with_template("{spinner} {msg} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    b.set_message(message);
    b.enable_steady_tick(Duration::from_millis(200));
    b
}

/// A bar of `len` units with `message`, the share done in per cent and the elapsed time.
pub fn percent(len: u64, message: &str) -> ProgressBar {
    let b = ProgressBar::new(len);
    b.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {percent:>3}% {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    b.set_message(message.to_string());
    b.enable_steady_tick(Duration::from_millis(200));
    b
}

/// A bar of `steps` steps with `message`, the step under way and the elapsed time.
pub fn steps(steps: u64, message: String) -> ProgressBar {
    let b = ProgressBar::new(steps);
    b.set_style(
        ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} {prefix} {elapsed}")
            .map(|s| s.progress_chars("=> "))
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    b.set_message(message);
    b.enable_steady_tick(Duration::from_millis(200));
    b
}
