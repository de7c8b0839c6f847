//! The Cortex-M4F images, the firmware and the PIL binary: their release builds with
//! warnings denied, one command for each wherever it runs, so a build made ahead finds the
//! check's own build fresh.
//!
//! `cargo xtask test` builds both ([`ahead`]) while the host tests run: the host tests use
//! `target/debug`, these builds `target/release` and `target/thumbv7em-none-eabihf`, so
//! neither waits on the other's lock, and each fills the cores the other leaves idle (the
//! long single-threaded tests, the images' serial link). Their output is kept and shown
//! when they are joined; the checks then build them again, which finds them fresh.

use crate::beside::{self, Beside, Unjoined};
use crate::setup::TARGET;
use crate::workspace::{cargo, run};
use anyhow::Result;
use std::process::Command;

/// The images, each a package with a binary of the same name.
pub const IMAGES: [&str; 2] = ["firmware", "pil"];

/// `cargo build` of the image `package` for [`TARGET`], release, warnings denied.
pub fn build_command(package: &str) -> Command {
    let mut c = cargo();
    c.args(["build", "--release", "--package", package, "--bin", package])
        .args(["--target", TARGET, "--config"])
        .arg(format!("target.{TARGET}.rustflags=[\"-D\", \"warnings\"]"));
    c
}

/// Builds the image `package` as the step `step`.
pub fn build(step: &str, package: &str) -> Result<()> {
    run(step, &mut build_command(package))
}

/// Starts building every image of [`IMAGES`] ([`beside`], output in
/// `target/images-ahead.log`). Cargo's lock on the target's build directory runs them one
/// after the other; dropped unjoined (a step before failed), they are stopped.
pub fn ahead() -> Result<Beside> {
    beside::start(
        "the Cortex-M4F images, built beside the host tests",
        "images-ahead.log",
        IMAGES.map(build_command),
        Unjoined::Kill,
    )
}

/// Waits for the images' builds and shows their output. A failed build is reported, not
/// returned: the check that builds the image again fails with the compiler's message.
pub fn join(ahead: Beside) {
    let failed = ahead.join();
    if !failed.is_empty() {
        eprintln!(
            "xtask: building the images ahead failed ({}); their checks build them again",
            failed.join(", ")
        );
    }
}
