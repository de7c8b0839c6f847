//! The Cortex-M4F images, the firmware and the PIL binary: their release builds with
//! warnings denied, one command for each wherever it runs, so a build made ahead finds the
//! check's own build fresh.
//!
//! `cargo xtask test` builds both ([`ahead`]) while the host tests run: the host tests use
//! `target/debug`, these builds `target/release` and `target/thumbv7em-none-eabihf`, so
//! neither waits on the other's lock, and each fills the cores the other leaves idle (the
//! long single-threaded tests, the images' serial link). Their output is kept and shown
//! when they are joined; the checks then build them again, which finds them fresh.

use crate::setup::TARGET;
use crate::workspace::{cargo, run, target_dir};
use anyhow::{Context, Result};
use std::path::PathBuf;
use std::process::{Child, Command};

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

/// The images' builds started ahead, their processes and the file their output goes to.
/// Dropped before [`Ahead::join`] (a step before failed), it stops them.
pub struct Ahead {
    builds: Vec<Child>,
    log: PathBuf,
}

/// Starts building every image of [`IMAGES`], their output written to
/// `target/images-ahead.log`. Cargo's lock on the target's build directory runs them one
/// after the other.
pub fn ahead() -> Result<Ahead> {
    let log = target_dir().join("images-ahead.log");
    std::fs::create_dir_all(target_dir())?;
    let file =
        std::fs::File::create(&log).with_context(|| format!("creating {}", log.display()))?;
    let mut ahead = Ahead {
        builds: Vec::new(),
        log,
    };
    for package in IMAGES {
        let mut cmd = build_command(package);
        cmd.stdout(file.try_clone()?).stderr(file.try_clone()?);
        let child = cmd
            .spawn()
            .with_context(|| format!("could not start {cmd:?}"))?;
        ahead.builds.push(child);
    }
    Ok(ahead)
}

impl Ahead {
    /// Waits for the builds and shows their output. A failed build is reported, not
    /// returned: the check that builds the image again fails with the compiler's message.
    pub fn join(mut self) {
        let mut failed = Vec::new();
        for mut child in std::mem::take(&mut self.builds) {
            match child.wait() {
                Ok(status) if status.success() => {}
                Ok(status) => failed.push(status.to_string()),
                Err(e) => failed.push(e.to_string()),
            }
        }
        eprintln!("\n=== the Cortex-M4F images, built beside the host tests:");
        match std::fs::read_to_string(&self.log) {
            Ok(text) => eprint!("{text}"),
            Err(e) => eprintln!("({}: {e})", self.log.display()),
        }
        if !failed.is_empty() {
            eprintln!(
                "xtask: building the images ahead failed ({}); their checks build them again",
                failed.join(", ")
            );
        }
    }
}

impl Drop for Ahead {
    fn drop(&mut self) {
        for child in &mut self.builds {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}
