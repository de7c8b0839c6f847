//! The workspace the tasks run in: its root, Cargo's target directory, a `cargo` command
//! started at the root (plain, or linting the workspace's crates as it builds them), the
//! runner of one step that names the step when it fails, and the executables the linted
//! build makes that the tasks run (`eha`, the checks).

use crate::compiler;
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

/// Clippy's arguments as `cargo clippy -- -D warnings` hands them to `clippy-driver`: its
/// `CLIPPY_ARGS`, each argument followed by Clippy's separator.
const CLIPPY_ARGS: &str = "-D__CLIPPY_HACKERY__warnings__CLIPPY_HACKERY__";

/// `cargo` for the host's builds, linting as it builds: the workspace's own crates are
/// compiled by `clippy-driver` (rustc with Clippy's lints, every warning denied) instead of
/// rustc, the way `cargo clippy` runs it (`RUSTC_WORKSPACE_WRAPPER`, `CLIPPY_ARGS`), and the
/// dependencies by rustc as in any build. One compilation both lints the code and makes the
/// test binaries, where `cargo clippy` followed by `cargo test` checked every crate once more
/// without building it. Every host build of the tasks goes through here, so none of them
/// rebuilds what another built. Cargo fingerprints the wrapper: a plain `cargo test` in the
/// same target directory compiles the workspace's crates again (not their dependencies),
/// and so do the tasks after it.
///
/// Cargo runs `cargo xtask`'s own executable as the wrapper, which hands each call to
/// `clippy-driver` and compiles the unit tests of the optimised simulation libraries at a
/// lower optimisation level ([`crate::compiler`]): this process's, or the one
/// [`compiler::WRAPPER_VAR`] names when `cargo xtask` started this process (the checks'
/// executable), so every linted build has the same wrapper and none rebuilds another's.
pub fn linted_cargo() -> Result<Command> {
    let mut c = cargo();
    let wrapper = match std::env::var_os(compiler::WRAPPER_VAR) {
        Some(path) => PathBuf::from(path),
        None => std::env::current_exe().context("this task's executable, the compiler wrapper")?,
    };
    c.env("RUSTC_WORKSPACE_WRAPPER", wrapper)
        .env(compiler::DRIVER_VAR, clippy_driver()?)
        .env("CLIPPY_ARGS", CLIPPY_ARGS);
    Ok(c)
}

/// The `clippy-driver` of the toolchain running this task: beside its `cargo`, else where
/// rustup says it is.
fn clippy_driver() -> Result<PathBuf> {
    let name = format!("clippy-driver{}", std::env::consts::EXE_SUFFIX);
    if let Some(cargo) = std::env::var_os("CARGO") {
        let beside = Path::new(&cargo).with_file_name(&name);
        if beside.is_file() {
            return Ok(beside);
        }
    }
    match Command::new("rustup")
        .args(["which", "clippy-driver"])
        .output()
    {
        Ok(out) if out.status.success() => {
            Ok(PathBuf::from(String::from_utf8_lossy(&out.stdout).trim()))
        }
        _ => bail!(
            "{name} is missing: the host's builds are linted by Clippy as they compile. \
             Install it with `rustup component add clippy`"
        ),
    }
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
/// right after the host tests nothing is rebuilt, where `cargo build -p host-sim` would
/// resolve the dependencies' features without the workspace's dev-dependencies and compile
/// them all again.
pub fn eha_binary(step: &str) -> Result<PathBuf> {
    run(
        step,
        linted_cargo()?.args(["test", "--workspace", "--no-run"]),
    )?;
    Ok(debug_binary("eha"))
}

/// The executable `name` of the workspace's dev build (`target/debug/NAME`): what the last
/// build that made it left there.
pub fn debug_binary(name: &str) -> PathBuf {
    target_dir()
        .join("debug")
        .join(format!("{name}{}", std::env::consts::EXE_SUFFIX))
}
