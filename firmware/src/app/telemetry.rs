//! The telemetry task: logs the frames the current-loop interrupt queues
//! ([`super::control`]) through defmt over RTT, as `EHA1 …` lines that `eha ingest` turns
//! into a bench log. One frame every [`firmware::Controller::telemetry_decimation`] PWM
//! periods (the `rates.telemetry_decimation` parameter, 20 by default: 1 kHz at 20 kHz
//! PWM; 1 during a step test), sampled by the interrupt itself, so the spacing is exact
//! and the time stamp (the controller's sample count) is the sample's.
//!
//! Nothing here can hold the current loop up. The interrupt only offers a frame to a
//! queue and never waits (a full queue drops the frame and counts it,
//! [`super::control::telemetry_dropped`]); this task runs in thread mode, below every
//! interrupt. defmt-rtt is built non-blocking with drop-on-contention (see
//! `firmware/Cargo.toml`): it never masks interrupts and never waits for the probe, even
//! when probe-rs has put the channel in blocking mode, so a frame that does not fit the
//! RTT buffer (4 KiB, `.cargo/config.toml`) is dropped. At full rate (20 000 frames/s,
//! about 60 bytes each) that depends on the probe's read rate; a gap shows as a jump of
//! `t_s` in the log, and `eha ingest` accepts uneven spacing.

use super::control;

/// Logs telemetry frames as they come.
#[embassy_executor::task]
pub async fn run() {
    loop {
        control::next_telemetry_frame().await.emit();
    }
}
