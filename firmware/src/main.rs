//! The STM32G474RE application of the EHA drive (target `thumbv7em-none-eabihf`).
//!
//! Build with `cargo fw` from the workspace root, or flash and watch the defmt log with
//! `cargo run --release` inside `firmware/` (probe-rs). The application itself is in
//! [`app`] (target only): the board mapping (NUCLEO-G474RE), the current-loop interrupt,
//! and the embassy tasks for CAN, telemetry and supervision. On the host this binary only
//! says how to build it, so `cargo test` and `cargo clippy --all-targets` work at the root.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod app;

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("the firmware binary runs on the STM32G474RE: build it with `cargo fw`, or `cargo run --release` inside firmware/");
    std::process::exit(2);
}
