//! `cargo xtask test` — every check the project has, in the order CI runs them, on a fresh
//! machine too:
//!
//! 1. what it needs installed when missing ([`setup`]): the `thumbv7em-none-eabihf` target
//!    (rustup), the `flip-link` linker (cargo install), `qemu-system-arm` and `tmux`
//!    (apt-get), Python's `cantools`, `dask` and `distributed` (a virtual environment),
//!    installed in a child process beside step 2's build ([`setup::beside`]);
//! 2. `cargo fmt --check`; every target of the workspace built for the host with Clippy's
//!    lints, warnings denied, in the same compilation ([`linted_cargo`]: what
//!    `cargo clippy --workspace --all-targets -- -D warnings` checks, without checking every
//!    crate a second time), the unit tests of the optimised simulation libraries compiled
//!    at a lower optimisation level ([`compiler`]);
//! 3. the host tests of the whole workspace, and `eha fleet` against its Dask driver on a
//!    local two-worker cluster and against its shards;
//! 4. the CAN DBC file: in sync with `firmware::can_protocol`, and cantools
//!    against the firmware's codec both ways;
//! 5. the firmware for the STM32G474RE with warnings denied, and its flash and static-RAM
//!    use against the budget (96 KiB / 16 KiB, so it also fits an STM32G431xB with the
//!    parameter pages), written to `target/firmware-size.json`;
//! 6. the processor-in-the-loop run in QEMU: the control core and the plant on
//!    the Cortex-M4F, telemetry through defmt and `eha ingest`, compared with the host run,
//!    instruction counts against `pil/budget.toml`, the stack's high-water mark against the
//!    firmware's stack (at least 4×), figures in `target/pil/report.json`;
//!    the same telemetry piped into `eha watch` under tmux: its screen
//!    checked, its bench log equal to `eha ingest`'s.
//!
//! `cargo xtask setup` does step 1 alone, `cargo xtask fw-size` step 5, `cargo xtask pil`
//! step 6, `cargo xtask can` step 4, `cargo xtask fleet` the fleet check of step 3; `cargo
//! xtask dbc [--node N] [--out FILE]` writes the DBC file; `cargo xtask rooms` lists the
//! files over 650 lines and the import circles between files.
//!
//! This executable does steps 1–3's builds and test runs itself, with only `anyhow` to
//! compile before it starts; the checks (the rooms, fleet, CAN, firmware and PIL steps) are
//! the executable of `xtask/checks`, which the linted build of step 2 makes with the rest of
//! the workspace ([`check`]). On their own, those commands build it with plain Cargo. The
//! Cortex-M4F images of steps 5 and 6 are built while the host tests run ([`images`]).

use anyhow::{bail, Context, Result};
use std::path::Path;
use std::process::Command;
use xtask::workspace::{cargo, debug_binary, linted_cargo, run};
use xtask::{compiler, images, setup};

/// The commands the checks' executable does, each on its own here.
const CHECKS: [&str; 6] = ["fw-size", "pil", "can", "fleet", "rooms", "dbc"];

/// The checks' executable (the package `xtask-checks`).
const CHECKS_EXE: &str = "xtask-checks";

fn main() {
    compiler::wrap_if_called();
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("test") => test(),
        Some("setup") => setup::everything(),
        Some(command) if CHECKS.contains(&command) => check_alone(&args),
        _ => {
            eprintln!(
                "usage: cargo xtask <test | setup | fw-size | pil | can | fleet | rooms [--root DIR] | dbc [--node N] [--out FILE]>"
            );
            std::process::exit(2);
        }
    };
    if let Err(e) = result {
        eprintln!("xtask: {e:#}");
        std::process::exit(1);
    }
}

/// One check on its own: the checks' executable built by plain Cargo (its dependencies'
/// features resolved for it alone, as `cargo run` would) and run with `args`, exiting
/// with its status.
fn check_alone(args: &[String]) -> Result<()> {
    run(
        "the checks' executable",
        cargo().args(["build", "--quiet", "--package", CHECKS_EXE]),
    )?;
    let status = checks_command(args, None)?
        .status()
        .with_context(|| format!("starting {}", debug_binary(CHECKS_EXE).display()))?;
    std::process::exit(status.code().unwrap_or(1));
}

/// The checks' executable with `args`, told which wrapper the linted builds run (this
/// executable, so the builds it starts reuse this one's) and, when known, the Python
/// interpreter with the checks' packages.
fn checks_command(args: &[String], python: Option<&Path>) -> Result<Command> {
    let exe = debug_binary(CHECKS_EXE);
    if !exe.is_file() {
        bail!(
            "{} is missing: the build before should have made it",
            exe.display()
        );
    }
    let mut cmd = Command::new(exe);
    cmd.args(args).env(
        compiler::WRAPPER_VAR,
        std::env::current_exe().context("this task's executable, the compiler wrapper")?,
    );
    if let Some(python) = python {
        cmd.env("EHA_PYTHON", python);
    }
    Ok(cmd)
}

/// Runs the check `command` of the checks' executable the linted build made.
fn check(command: &str, python: Option<&Path>) -> Result<()> {
    run(
        command,
        &mut checks_command(&[command.to_string()], python)?,
    )
}

fn test() -> Result<()> {
    let mut times = StepTimes::default();
    let installing = setup::beside()?;
    times.step("format", || {
        run("format", cargo().args(["fmt", "--all", "--", "--check"]))
    })?;
    // Every target: what the test runs need (`--all-targets` would build the examples a
    // second time, as tests), with the checks' executable (its integration test needs
    // it), then the benchmarks.
    times.step("lint, build", || {
        let step = "host build, Clippy's lints with warnings denied";
        run(
            step,
            linted_cargo()?.args(["test", "--workspace", "--no-run"]),
        )?;
        run(
            step,
            linted_cargo()?.args(["test", "--workspace", "--benches", "--no-run"]),
        )
    })?;
    // The host tests need tmux, the images the target and flip-link.
    times.step("setup", || setup::join(installing))?;
    let python = times.step("python", setup::python)?;
    times.step("rooms", || check("rooms", None))?;
    let images = images::ahead()?;
    times.step("host tests", || {
        run("host tests", linted_cargo()?.args(["test", "--workspace"]))
    })?;
    times.step("fleet", || check("fleet", Some(&python)))?;
    times.step("can", || check("can", Some(&python)))?;
    times.step("images", || {
        images::join(images);
        Ok(())
    })?;
    times.step("firmware", || check("fw-size", None))?;
    times.step("pil", || check("pil", None))?;
    eprintln!("\nxtask: step times\n{times}");
    eprintln!("\nxtask: all checks passed");
    Ok(())
}

/// How long each step of `cargo xtask test` took (wall clock), printed at the end so a CI
/// log shows where its time goes.
#[derive(Default)]
struct StepTimes(Vec<(&'static str, std::time::Duration)>);

impl StepTimes {
    /// Runs `f` as the step `name`, timing it.
    fn step<T>(&mut self, name: &'static str, f: impl FnOnce() -> Result<T>) -> Result<T> {
        let start = std::time::Instant::now();
        let out = f();
        self.0.push((name, start.elapsed()));
        out
    }
}

impl std::fmt::Display for StepTimes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let total: std::time::Duration = self.0.iter().map(|(_, d)| *d).sum();
        for (name, d) in &self.0 {
            writeln!(f, "  {name:<12} {:>7.1} s", d.as_secs_f64())?;
        }
        write!(f, "  {:<12} {:>7.1} s", "all", total.as_secs_f64())
    }
}
