//! The telemetry task: the controller's telemetry frame through defmt over RTT, one frame
//! every [`TELEMETRY_DECIMATION`] PWM periods, as `EHA1 …` lines that `eha ingest` turns
//! into a bench log.
//!
//! The frame is copied inside a short critical section and logged outside it. Its time
//! stamp is the controller's sample count, so jitter of this task shifts which sample is
//! logged, never the time a sample is logged with (the bench log allows uneven spacing).
//! If the probe reads RTT slower than frames come, defmt-rtt drops them rather than
//! blocking.

use embassy_time::{Duration, Ticker};

use super::control;

/// PWM periods per telemetry frame: 20 gives 1 kHz at the default 20 kHz PWM.
pub const TELEMETRY_DECIMATION: u32 = 20;

/// Logs telemetry at `pwm_hz / TELEMETRY_DECIMATION`.
#[embassy_executor::task]
pub async fn run(pwm_hz: u32) {
    let period_us = u64::from(TELEMETRY_DECIMATION) * 1_000_000 / u64::from(pwm_hz.max(1));
    let mut ticker = Ticker::every(Duration::from_micros(period_us.max(1)));
    loop {
        ticker.next().await;
        if let Some(frame) = control::with_controller(|c| c.telemetry()) {
            frame.emit();
        }
    }
}
