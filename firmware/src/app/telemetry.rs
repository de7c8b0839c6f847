//! The telemetry task: the controller's telemetry frame through defmt over RTT, one frame
//! every [`firmware::Controller::telemetry_decimation`] PWM periods (the
//! `rates.telemetry_decimation` parameter, 20 by default: 1 kHz at 20 kHz PWM; 1 during a
//! step test), as `EHA1 …` lines that `eha ingest` turns into a bench log.
//!
//! The frame is copied inside a short critical section and logged outside it. Its time
//! stamp is the controller's sample count, so jitter of this task shifts which sample is
//! logged, never the time a sample is logged with (the bench log allows uneven spacing).
//! If the probe reads RTT slower than frames come, defmt-rtt drops them rather than
//! blocking: at full rate (20 000 frames/s of about 70 bytes) that depends on the probe,
//! and a gap shows as a jump of `t_s` in the log.

use embassy_time::{Duration, Instant, Timer};

use super::control;

/// Logs telemetry at `pwm_hz / decimation`, the decimation read anew every frame.
#[embassy_executor::task]
pub async fn run(pwm_hz: u32) {
    let mut next = Instant::now();
    loop {
        let Some((frame, decimation)) =
            control::with_controller(|c| (c.telemetry(), c.telemetry_decimation()))
        else {
            Timer::after_millis(1).await;
            continue;
        };
        frame.emit();
        let period_us = u64::from(decimation) * 1_000_000 / u64::from(pwm_hz.max(1));
        next += Duration::from_micros(period_us.max(1));
        // After a stall (a flash save) start afresh instead of bursting to catch up.
        let now = Instant::now();
        if next < now {
            next = now;
        }
        Timer::at(next).await;
    }
}
