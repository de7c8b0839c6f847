//! The workspace the tasks run in: its root, Cargo's target directory, a `cargo` command
//! started at the root, and the runner of one step that names the step when it fails.

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The workspace root (one level above `xtask/`).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives one level below the workspace root")
        .to_path_buf()
}

/// `cargo` (the one running this task when known) in the workspace root.
pub fn cargo() -> Command {
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    c.current_dir(root());
    c
}

/// Cargo's target directory (`CARGO_TARGET_DIR` or `target/` at the root).
pub fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target"))
}

/// Runs `cmd` as the step `step`, failing with the step's name when it fails.
pub fn run(step: &str, cmd: &mut Command) -> Result<()> {
    eprintln!("\n=== {step}: {cmd:?}");
    let status = cmd
        .status()
        .with_context(|| format!("{step}: could not start {cmd:?}"))?;
    if !status.success() {
        bail!("{step} failed ({status})");
    }
    Ok(())
}

/// `eha` as the host tests build it (their integration tests run it), built if needed:
/// right after `cargo test --workspace` nothing is rebuilt, where `cargo build -p host-sim`
/// would resolve the dependencies' features without the workspace's dev-dependencies and
/// compile them all again.
pub fn eha_binary(step: &str) -> Result<PathBuf> {
    run(step, cargo().args(["test", "--workspace", "--no-run"]))?;
    Ok(target_dir().join("debug").join("eha"))
}
