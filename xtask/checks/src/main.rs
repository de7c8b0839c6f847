//! The checks of `cargo xtask test` that need more than the task runner (`xtask`), each a
//! command of this executable, which `cargo xtask` runs:
//!
//! - `rooms [--root DIR]`: the files over 650 lines and the import circles between files of
//!   the product's crates ([`rooms`]);
//! - `fleet`: `eha fleet` against its Dask driver on a local two-worker cluster and against
//!   its shards ([`fleet_check`]);
//! - `can`: the CAN DBC file in sync with `firmware::can_protocol` ([`dbc`]), and cantools
//!   against the firmware's codec both ways ([`can_check`]);
//! - `fw-size`: the firmware for the STM32G474RE with warnings denied, its flash and
//!   static-RAM use against the budget ([`firmware_image`]);
//! - `pil`: the processor-in-the-loop run in QEMU ([`pil`]), its telemetry also piped into
//!   `eha watch` under tmux ([`watch_check`]);
//! - `dbc [--node N] [--out FILE]`: writes the DBC file.
//!
//! It is a workspace member so that the linted host build compiles it with the features the
//! whole workspace resolves: its dependencies are the workspace's, built once. The builds
//! it starts itself (`eha` for the fleet and PIL checks) run the compiler wrapper of the
//! `cargo xtask` that started it ([`xtask::compiler::WRAPPER_VAR`]).

mod can_check;
mod dbc;
mod firmware_image;
mod fleet_check;
mod pil;
mod rooms;
mod watch_check;

use anyhow::Result;
use xtask::setup;
use xtask::workspace::root;

/// What this executable does when its arguments name nothing it knows.
const USAGE: &str =
    "usage: xtask-checks <fw-size | pil | can | fleet | rooms [--root DIR] | dbc [--node N] [--out FILE]>";

fn main() {
    // Run directly (not through `cargo xtask`), the linted builds it starts name this
    // executable as their compiler wrapper.
    xtask::compiler::wrap_if_called();
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("fw-size") => firmware_image::firmware().map(|_| ()),
        Some("pil") => setup::ensure_target()
            .and_then(|()| setup::tools())
            .and_then(|()| pil::pil()),
        Some("dbc") => dbc::dbc(&args[1..]),
        Some("rooms") => rooms::rooms(&args[1..]),
        Some("can") => can(),
        Some("fleet") => setup::python().and_then(|p| fleet_check::check(&p)),
        _ => {
            eprintln!("{USAGE}");
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
