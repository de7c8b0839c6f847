//! `cargo xtask test` — every check the project has, in the order CI runs them, on a fresh
//! machine too:
//!
//! 1. what it needs installed when missing ([`setup`]): the `thumbv7em-none-eabihf` target
//!    (rustup), the `flip-link` linker (cargo install), `qemu-system-arm` and `tmux`
//!    (apt-get), Python's `cantools`, `dask` and `distributed` (a virtual environment);
//! 2. `cargo fmt --check` and `cargo clippy --workspace --all-targets -D warnings`;
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

use anyhow::{bail, Context, Result};
use object::{Object, ObjectSection, SectionFlags};
use std::path::{Path, PathBuf};
use std::process::Command;

mod can_check;
mod dbc;
mod fleet_check;
mod pil;
mod rooms;
mod setup;
mod watch_check;

const TARGET: &str = "thumbv7em-none-eabihf";
/// 96 KiB: an STM32G431xB (128 KiB) still holds the image and the parameter store's pages.
const FLASH_BUDGET: u64 = 96 * 1024;
const RAM_BUDGET: u64 = 16 * 1024;
/// The STM32G474RE's RAM as `memory.x` describes it. With flip-link the stack has all of
/// it below the statics: at least this less [`RAM_BUDGET`].
const FIRMWARE_RAM: u64 = 128 * 1024;

fn main() {
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
                "usage: cargo xtask <test | fw-size | pil | can | fleet | rooms | dbc [--node N] [--out FILE]>"
            );
            std::process::exit(2);
        }
    };
    if let Err(e) = result {
        eprintln!("xtask: {e:#}");
        std::process::exit(1);
    }
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives one level below the workspace root")
        .to_path_buf()
}

fn cargo() -> Command {
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    c.current_dir(root());
    c
}

/// Cargo's target directory (`CARGO_TARGET_DIR` or `target/` at the root).
fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target"))
}

fn run(step: &str, cmd: &mut Command) -> Result<()> {
    eprintln!("\n=== {step}: {cmd:?}");
    let status = cmd
        .status()
        .with_context(|| format!("{step}: could not start {cmd:?}"))?;
    if !status.success() {
        bail!("{step} failed ({status})");
    }
    Ok(())
}

/// The Cortex-M4F target and the linker its images use (flip-link).
fn ensure_target() -> Result<()> {
    setup::linker()?;
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
        run(
            "install the Cortex-M4F target",
            Command::new("rustup").args(["target", "add", TARGET]),
        )?;
    }
    Ok(())
}

/// The DBC file in sync, then cantools against the firmware's codec.
fn can() -> Result<()> {
    let text = dbc::generate(dbc::DEFAULT_NODE)?;
    dbc::check_in_sync(&text, &root().join(dbc::FILE))?;
    can_check::check(&setup::python()?)
}

fn test() -> Result<()> {
    ensure_target()?;
    setup::tools()?;
    let python = setup::python()?;
    run("format", cargo().args(["fmt", "--all", "--", "--check"]))?;
    run(
        "lint",
        cargo().args([
            "clippy",
            "--workspace",
            "--all-targets",
            "--",
            "-D",
            "warnings",
        ]),
    )?;
    run("host tests", cargo().args(["test", "--workspace"]))?;
    fleet_check::check(&python)?;
    let text = dbc::generate(dbc::DEFAULT_NODE)?;
    dbc::check_in_sync(&text, &root().join(dbc::FILE))?;
    can_check::check(&python)?;
    firmware()?;
    pil::pil()?;
    eprintln!("\nxtask: all checks passed");
    Ok(())
}

/// Builds the firmware image with warnings denied and checks its size.
fn firmware() -> Result<(u64, u64)> {
    ensure_target()?;
    run(
        "firmware (warnings denied)",
        cargo().args([
            "build",
            "--release",
            "--package",
            "firmware",
            "--bin",
            "firmware",
            "--target",
            TARGET,
            "--config",
            &format!("target.{TARGET}.rustflags=[\"-D\", \"warnings\"]"),
        ]),
    )?;
    let target_dir = target_dir();
    let elf = target_dir.join(TARGET).join("release").join("firmware");
    let (flash, ram) = image_size(&elf)?;
    let json = format!(
        "{{\"flash_bytes\": {flash}, \"static_ram_bytes\": {ram}, \"flash_budget_bytes\": {FLASH_BUDGET}, \"ram_budget_bytes\": {RAM_BUDGET}}}\n"
    );
    std::fs::create_dir_all(&target_dir)?;
    std::fs::write(target_dir.join("firmware-size.json"), json)?;
    eprintln!(
        "firmware: flash {flash} B ({:.1} KiB of {} KiB), static RAM {ram} B ({:.1} KiB of {} KiB)",
        flash as f64 / 1024.0,
        FLASH_BUDGET / 1024,
        ram as f64 / 1024.0,
        RAM_BUDGET / 1024
    );
    if flash > FLASH_BUDGET || ram > RAM_BUDGET {
        bail!("the firmware exceeds its flash/RAM budget (see above)");
    }
    Ok((flash, ram))
}

/// Flash = allocated sections with contents (code, read-only data, .data's load image);
/// static RAM = writable allocated sections (.data, .bss, .uninit). Stack is not static.
fn image_size(elf: &Path) -> Result<(u64, u64)> {
    let data = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let file = object::File::parse(&*data).with_context(|| format!("parsing {}", elf.display()))?;
    let (mut flash, mut ram) = (0, 0);
    for s in file.sections() {
        let SectionFlags::Elf { sh_flags } = s.flags() else {
            continue;
        };
        const ALLOC: u64 = 0x2;
        const WRITE: u64 = 0x1;
        if sh_flags & ALLOC == 0 {
            continue;
        }
        let has_contents = s.kind() != object::SectionKind::UninitializedData;
        if sh_flags & WRITE != 0 {
            ram += s.size();
        }
        if has_contents {
            flash += s.size();
        }
    }
    Ok((flash, ram))
}
