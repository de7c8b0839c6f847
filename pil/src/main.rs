//! Processor-in-the-loop binary for QEMU's `mps2-an386` (Cortex-M4F, target
//! `thumbv7em-none-eabihf`).
//!
//! Runs the pressure-hold scenario through [`closed_loop::ClosedLoop`] — the firmware's f32
//! control core against the f64 plant model (emulated in software: the M4F's FPU is
//! single precision) — and sends the controller's telemetry as defmt frames through the
//! firmware's own [`firmware::TelemetryFrame::emit`], carried to the host by semihosting.
//! Beside the loop it measures the instructions per call of the current-, speed- and
//! pressure-loop steps with SysTick (see [`icount`]) and the stack's high-water mark (see
//! [`stack`]), and ends with one `PIL …` defmt line of figures and a semihosting exit code
//! (0 when the run completed).
//!
//! `cargo xtask test` builds it, runs it under `qemu-system-arm -icount shift=0`, decodes the
//! frames with the ELF and turns them into a bench log with `eha ingest`.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod firmware_paths;
#[cfg(target_os = "none")]
mod icount;
#[cfg(target_os = "none")]
mod stack;
#[cfg(target_os = "none")]
mod target;

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "the PIL binary runs on QEMU's Cortex-M4F: `cargo xtask test` builds it for \
         thumbv7em-none-eabihf and runs it in qemu-system-arm (-machine mps2-an386)"
    );
    std::process::exit(2);
}
