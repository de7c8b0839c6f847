//! `cargo xtask dbc [--node N] [--out FILE]`: the DBC description of the drive's CAN
//! protocol, generated from `firmware::can_protocol` and the tables it names — identifiers
//! from `can_protocol::id`, data lengths from `Function::dlc`, wire scalings from the
//! protocol's `*_PER_LSB` constants, value tables from the firmware's enumerations
//! (modes, fault codes, functions, reject reasons, step-test loops, parameter ids by name),
//! parameter units and bounds from `firmware::parameters`.
//!
//! Every command and reply has a message; signals are little endian (Intel). Where a
//! field's meaning depends on another, the message is multiplexed: `SetParameter` and
//! `Parameter` by the parameter id (one value signal per parameter, in its unit and
//! bounds), `StepTest` by the loop (amplitude in A, rad/s or Pa), `Reject` by the refused
//! function (the bound in that command's wire unit, or an `f32` in SI units for the
//! configuration functions). The byte positions are written in [`commands`] and
//! [`replies`]; the cantools check ([`crate::can_check`]) holds them to the firmware's own
//! encoder and decoder, value for value, both ways.
//!
//! The checked-in `eha.dbc` is for node 1 (the application's `board::CAN_NODE`); for
//! another node pass `--node`, or decode with `cantools decode -m 0x7F0`, which matches
//! identifiers without their node bits.
//!
//! The model of a message ([`signal`]), the value tables ([`values`]), the commands
//! ([`commands`]) and replies ([`replies`]), and the file's text ([`render`]).

mod commands;
mod render;
mod replies;
mod signal;
mod values;

pub use render::{generate, messages};
pub use replies::ReplyKind;
pub use signal::{ascii, shortest};
pub use values::{parameter_signal, words};

use anyhow::{bail, Result};

/// The node the checked-in file describes (the application's `board::CAN_NODE`).
pub const DEFAULT_NODE: u8 = 1;
/// The checked-in file, relative to the workspace root.
pub const FILE: &str = "eha.dbc";

/// `cargo xtask dbc [--node N] [--out FILE] [--check]`.
pub fn dbc(args: &[String]) -> Result<()> {
    let mut node = DEFAULT_NODE;
    let mut out = xtask::workspace::root().join(FILE);
    let mut check = false;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--node" => {
                let v = it.next().map(String::as_str).unwrap_or("");
                node = v
                    .parse()
                    .map_err(|_| anyhow::anyhow!("--node: `{v}` is not a node number 0..=15"))?;
            }
            "--out" => match it.next() {
                Some(p) => out = p.into(),
                None => bail!("--out needs a file"),
            },
            "--check" => check = true,
            other => bail!("dbc: unknown argument `{other}` (--node N, --out FILE, --check)"),
        }
    }
    let text = generate(node)?;
    if check {
        return check_in_sync(&text, &out);
    }
    std::fs::write(&out, text)?;
    eprintln!("xtask: wrote {} (node {node})", out.display());
    Ok(())
}

/// Fails when the checked-in file differs from what the firmware's definitions give.
pub fn check_in_sync(text: &str, file: &std::path::Path) -> Result<()> {
    let on_disk = std::fs::read_to_string(file).unwrap_or_default();
    if on_disk != text {
        bail!(
            "{} is out of sync with firmware::can_protocol: run `cargo xtask dbc` and commit it",
            file.display()
        );
    }
    eprintln!(
        "xtask: {} is in sync with firmware::can_protocol",
        file.display()
    );
    Ok(())
}
