//! What `cargo xtask test` needs beyond Rust, installed when missing so the README's one
//! command works on a fresh machine (Debian or Ubuntu, as root or with sudo-less apt):
//!
//! - the Cortex-M4F target [`TARGET`] of the firmware and the PIL image, with rustup;
//! - `flip-link`, the linker of the Cortex-M images (`.cargo/config.toml`), with
//!   `cargo install --locked` at the version [`FLIP_LINK_VERSION`];
//! - `qemu-system-arm` (QEMU's Cortex-M4F, `mps2-an386`) for the processor-in-the-loop run;
//! - `tmux`, the terminal `eha watch`'s screen test runs the live view in;
//! - Python's `cantools`, `dask` and `distributed` (pinned in `xtask/requirements.txt`) in a
//!   virtual environment under the target directory, for the DBC check and the fleet's Dask
//!   driver. `EHA_PYTHON` names an interpreter that has them already instead; a missing or
//!   broken one is an error, never a skip.
//!
//! apt-get runs only when something is missing, after `apt-get update`.
//!
//! `cargo xtask test` runs it all ([`everything`]) in a child process beside the linted
//! host build ([`beside`]), which needs none of it: on a fresh machine its time is mostly
//! waiting on the network and the package manager, which the build's compilations fill.

use crate::beside::{self, Beside, Unjoined};
use anyhow::{bail, Context, Result};
use std::path::PathBuf;
use std::process::{Command, Stdio};

/// Tools found on `PATH` by name, the argument that makes each print its version and exit
/// successfully (QEMU refuses tmux's `-V`), and the Debian package that has each.
const TOOLS: [(&str, &str, &str); 2] = [
    ("qemu-system-arm", "--version", "qemu-system-arm"),
    ("tmux", "-V", "tmux"),
];

fn found(program: &str, arg: &str) -> bool {
    Command::new(program)
        .arg(arg)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Installs `packages` with apt-get (after `apt-get update`).
fn apt_install(packages: &[&str]) -> Result<()> {
    if !found("apt-get", "--version") {
        bail!(
            "{} missing and there is no apt-get to install them with: install them with your \
             system's package manager",
            packages.join(", ")
        );
    }
    crate::workspace::run("apt-get update", Command::new("apt-get").arg("update"))?;
    crate::workspace::run(
        "apt-get install",
        Command::new("apt-get")
            .env("DEBIAN_FRONTEND", "noninteractive")
            .args(["install", "-y", "--no-install-recommends"])
            .args(packages),
    )
}

/// The flip-link release the images are linked with.
pub const FLIP_LINK_VERSION: &str = "0.1.12";

/// Installs flip-link with cargo when it is missing (it prints its usage and exits 0 when
/// run without arguments).
pub fn linker() -> Result<()> {
    let installed = Command::new("flip-link")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !installed {
        crate::workspace::run(
            "install flip-link (the Cortex-M images' linker)",
            Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into())).args([
                "install",
                "flip-link",
                "--locked",
                "--version",
                FLIP_LINK_VERSION,
            ]),
        )?;
    }
    Ok(())
}

/// The firmware's and the PIL's target.
pub const TARGET: &str = "thumbv7em-none-eabihf";
/// The Cortex-M4F target and the linker its images use (flip-link).
pub fn ensure_target() -> Result<()> {
    linker()?;
    let out = Command::new("rustup")
        .args(["target", "list", "--installed"])
        .output()
        .context(
            "rustup is needed to install the thumbv7em-none-eabihf target (https://rustup.rs)",
        )?;
    if !String::from_utf8_lossy(&out.stdout)
        .lines()
        .any(|l| l.trim() == TARGET)
    {
        crate::workspace::run(
            "install the Cortex-M4F target",
            Command::new("rustup").args(["target", "add", TARGET]),
        )?;
    }
    Ok(())
}

/// Installs the tools of [`TOOLS`] that are missing.
pub fn tools() -> Result<()> {
    let missing: Vec<&str> = TOOLS
        .iter()
        .filter(|(cmd, version, _)| !found(cmd, version))
        .map(|(_, _, pkg)| *pkg)
        .collect();
    if !missing.is_empty() {
        apt_install(&missing)?;
    }
    Ok(())
}

/// What the checks import: cantools (the DBC check), dask.distributed (the fleet check).
const IMPORTS: &str = "import cantools, dask.distributed";

/// The versions of the checks' packages as `python` imports them, or `None` when it
/// cannot import them.
fn packages(python: &std::path::Path) -> Option<String> {
    let script = format!(
        "{IMPORTS}; print('cantools', cantools.__version__, 'dask', dask.__version__, \
         'distributed', dask.distributed.__version__)"
    );
    let out = Command::new(python)
        .args(["-c", &script])
        .stderr(Stdio::null())
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// `python` when it has the checks' packages, their versions shown so a run's log says
/// what it checked against.
fn with_packages(python: PathBuf) -> Option<PathBuf> {
    let versions = packages(&python)?;
    eprintln!("{}: {versions}", python.display());
    Some(python)
}

/// A Python interpreter with `cantools`, `dask` and `distributed`: `EHA_PYTHON`, or the
/// target directory's virtual environment (made and filled from `xtask/requirements.txt`
/// when missing).
pub fn python() -> Result<PathBuf> {
    if let Some(p) = std::env::var_os("EHA_PYTHON") {
        let p = PathBuf::from(p);
        return with_packages(p.clone()).with_context(|| {
            format!(
                "EHA_PYTHON={} cannot `{IMPORTS}` (pip install -r xtask/requirements.txt)",
                p.display()
            )
        });
    }
    let venv = crate::workspace::target_dir().join("py-venv");
    let python = venv.join("bin").join("python");
    if let Some(python) = with_packages(python.clone()) {
        return Ok(python);
    }
    let make = || {
        Command::new("python3")
            .args(["-m", "venv"])
            .arg(&venv)
            .status()
            .is_ok_and(|s| s.success())
    };
    if !make() {
        // Debian splits venv and pip out of python3.
        apt_install(&["python3", "python3-venv", "python3-pip"])?;
        if !make() {
            bail!("python3 -m venv {} failed", venv.display());
        }
    }
    crate::workspace::run(
        "cantools, dask and distributed into the checks' virtual environment",
        Command::new(&python)
            .args(["-m", "pip", "install", "--quiet", "-r"])
            .arg(
                crate::workspace::root()
                    .join("xtask")
                    .join("requirements.txt"),
            ),
    )
    .context("installing the checks' Python packages with pip")?;
    let shown = python.display().to_string();
    with_packages(python).with_context(|| format!("{shown} cannot `{IMPORTS}` after pip install"))
}

/// Everything above: the target, the linker, the tools, the Python environment (`cargo
/// xtask setup`).
pub fn everything() -> Result<()> {
    ensure_target()?;
    tools()?;
    python().map(|_| ())
}

/// Starts [`everything`] in a child process (`cargo xtask setup`, this executable,
/// [`beside`], output in `target/setup.log`); dropped unjoined (a step before failed), it
/// is waited for.
pub fn beside() -> Result<Beside> {
    let exe = std::env::current_exe().context("this task's executable, for its setup")?;
    let mut setup = Command::new(exe);
    setup.arg("setup");
    beside::start(
        "setup, run beside the build",
        "setup.log",
        [setup],
        Unjoined::Wait,
    )
}

/// Waits for the setup started by [`beside`], shows its output and fails when it did.
pub fn join(setup: Beside) -> Result<()> {
    let failed = setup.join();
    if !failed.is_empty() {
        bail!("setup failed ({}; its output above)", failed.join(", "));
    }
    Ok(())
}
