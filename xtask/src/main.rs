//! `cargo xtask test` — every check the project has, in the order CI runs them, on a fresh
//! machine too:
//!
//! 1. what it needs installed when missing ([`setup`]): the `thumbv7em-none-eabihf` target
//!    (rustup), the `flip-link` linker (cargo install), `qemu-system-arm` and `tmux`
//!    (apt-get), Python's `cantools`, `dask` and `distributed` (a virtual environment);
//! 2. `cargo fmt --check`; every target of the workspace built for the host with Clippy's
//!    lints, warnings denied, in the same compilation ([`workspace::linted_cargo`]: what
//!    `cargo clippy --workspace --all-targets -- -D warnings` checks, without checking every
//!    crate a second time), the unit tests of the optimised simulation libraries compiled
//!    at a lower optimisation level ([`compiler`]);
//! 3. the host tests of the whole workspace, and `eha fleet` against its Dask driver on a
//!    local two-worker cluster and against its shards ([`fleet_check`]);
//! 4. the CAN DBC file: in sync with `firmware::can_protocol` ([`dbc`]), and cantools
//!    against the firmware's codec both ways ([`can_check`]);
//! 5. the firmware for the STM32G474RE with warnings denied, and its flash and static-RAM
//!    use against the budget (96 KiB / 16 KiB, so it also fits an STM32G431xB with the
//!    parameter pages), written to `target/firmware-size.json`;
//! 6. the processor-in-the-loop run in QEMU ([`pil`]): the control core and the plant on
//!    the Cortex-M4F, telemetry through defmt and `eha ingest`, compared with the host run,
//!    instruction counts against `pil/budget.toml`, the stack's high-water mark against the
//!    firmware's stack (at least 4×), figures in `target/pil/report.json`;
//!    the same telemetry piped into `eha watch` under tmux ([`watch_check`]): its screen
//!    checked, its bench log equal to `eha ingest`'s.
//!
//! `cargo xtask fw-size` does step 5 alone, `cargo xtask pil` step 6, `cargo xtask can`
//! step 4, `cargo xtask fleet` the fleet check of step 3; `cargo xtask dbc [--node N]
//! [--out FILE]` writes the DBC file; `cargo xtask rooms` lists the files over 650 lines and
//! the import circles between files ([`rooms`]).

mod can_check;
mod compiler;
mod dbc;
mod firmware_image;
mod fleet_check;
mod pil;
mod rooms;
mod setup;
mod watch_check;
mod workspace;

use anyhow::Result;
use firmware_image::{ensure_target, firmware};
use workspace::{cargo, linted_cargo, root, run};

fn main() {
    compiler::wrap_if_called();
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("test") => test(),
        Some("fw-size") => firmware().map(|_| ()),
        Some("pil") => ensure_target()
            .and_then(|()| setup::tools())
            .and_then(|()| pil::pil()),
        Some("dbc") => dbc::dbc(&args[1..]),
        Some("rooms") => rooms::rooms(&args[1..]),
        Some("can") => can(),
        Some("fleet") => setup::python().and_then(|p| fleet_check::check(&p)),
        _ => {
            eprintln!(
                "usage: cargo xtask <test | fw-size | pil | can | fleet | rooms [--root DIR] | dbc [--node N] [--out FILE]>"
            );
            std::process::exit(2);
        }
    };
    if let Err(e) = result {
        eprintln!("xtask: {e:#}");
        std::process::exit(1);
    }
}

/// The DBC file in sync, then cantools against the firmware's codec.
fn can() -> Result<()> {
    let text = dbc::generate(dbc::DEFAULT_NODE)?;
    dbc::check_in_sync(&text, &root().join(dbc::FILE))?;
    can_check::check(&setup::python()?)
}

fn test() -> Result<()> {
    let mut times = StepTimes::default();
    times.step("setup", || {
        ensure_target()?;
        setup::tools()
    })?;
    let python = times.step("python", setup::python)?;
    times.step("format", || {
        run("format", cargo().args(["fmt", "--all", "--", "--check"]))
    })?;
    // Every target: what the test runs need (`--all-targets` would build the examples a
    // second time, as tests), then the benchmarks.
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
    times.step("rooms", || rooms::rooms(&[]))?;
    times.step("host tests", || {
        run("host tests", linted_cargo()?.args(["test", "--workspace"]))
    })?;
    times.step("fleet", || fleet_check::check(&python))?;
    times.step("can", || {
        let text = dbc::generate(dbc::DEFAULT_NODE)?;
        dbc::check_in_sync(&text, &root().join(dbc::FILE))?;
        can_check::check(&python)
    })?;
    times.step("firmware", || firmware().map(|_| ()))?;
    times.step("pil", pil::pil)?;
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
