//! The supervision task: feeds the independent watchdog only while the current-loop
//! interrupt is alive, breaks the bridge when it is not, blinks the status LED, and logs
//! what a bench engineer needs to see: the drive becoming ready, hardware breaks with
//! their source, and the interrupt's load.
//!
//! Every [`CHECK_PERIOD`] it compares the interrupt counter with the previous check; the
//! counter must have advanced by at least half the expected number of periods. If it has
//! not (the PWM timer, the ADC trigger or the interrupt stopped), the bridge has no current
//! loop: the task forces a break at once ([`super::safe_state::force_break`]) and stops
//! feeding the watchdog, which resets the MCU within its timeout; the next boot reports the
//! reset as fault 11. Overruns inside the interrupt latch the controller's watchdog fault
//! (see [`super::control`]). A parameter save blocks this task for one flash erase
//! (the loop keeps running, see [`super::param_flash`]); the check spanning it is skipped.

use embassy_stm32::gpio::Output;
use embassy_stm32::peripherals::IWDG;
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_time::{Duration, Ticker};
use firmware::Readiness;

use super::control;
use super::param_flash;
use super::safe_state;

/// Interval between liveness checks (well inside the watchdog timeout).
pub const CHECK_PERIOD: Duration = Duration::from_millis(5);
/// Checks between load reports and LED toggles (1 s).
const REPORT_EVERY: u32 = 200;

/// Runs the supervision loop; `pwm_hz` sets the expected interrupt rate.
#[embassy_executor::task]
pub async fn run(
    mut watchdog: IndependentWatchdog<'static, IWDG>,
    mut led: Output<'static>,
    pwm_hz: u32,
) {
    let expected = (u64::from(pwm_hz) * CHECK_PERIOD.as_micros() / 1_000_000) as u32;
    let minimum = (expected / 2).max(1);
    let mut last = control::isr_count();
    let mut last_maintenance = param_flash::maintenance_windows();
    let mut last_breaks = control::breaks();
    let mut readiness: Option<Readiness> = None;
    let mut ticker = Ticker::every(CHECK_PERIOD);
    let mut checks: u32 = 0;
    watchdog.unleash();
    loop {
        ticker.next().await;
        let now = control::isr_count();
        let advanced = now.wrapping_sub(last);
        last = now;
        // A parameter save stalls this task (not the loop) for an erase: no verdict over
        // such a window.
        let maintenance = param_flash::maintenance_windows();
        let saved = maintenance != last_maintenance;
        last_maintenance = maintenance;
        if advanced >= minimum || saved {
            watchdog.pet();
        } else {
            safe_state::force_break();
            defmt::error!(
                "current loop stalled: {} interrupts in {} us (expected {}); bridge broken, watchdog not fed",
                advanced,
                CHECK_PERIOD.as_micros(),
                expected
            );
        }
        let breaks = control::breaks();
        if breaks != last_breaks {
            last_breaks = breaks;
            report_break(control::last_break_sources());
        }
        readiness = report_readiness(readiness);
        checks = checks.wrapping_add(1);
        if checks % REPORT_EVERY == 0 {
            led.toggle();
            defmt::debug!(
                "current loop: max {} cycles per interrupt, {} overruns, {} bridge breaks, {} telemetry frames dropped",
                control::isr_max_cycles(),
                control::overruns(),
                breaks,
                control::telemetry_dropped()
            );
        }
    }
}

/// Logs a hardware break (fault 17) with what was active when the interrupt saw it.
fn report_break(sources: u8) {
    defmt::error!(
        "hardware break (fault 17): comparator U {=bool}, V {=bool}, W {=bool}, gate-driver fault line {=bool} (all false: forced, or gone within one period)",
        sources & 1 != 0,
        sources & 2 != 0,
        sources & 4 != 0,
        sources & 8 != 0
    );
}

/// Logs the drive's readiness when it changes (`previous`: what was logged last).
fn report_readiness(previous: Option<Readiness>) -> Option<Readiness> {
    let now = control::with_controller(|c| (c.readiness(), c.encoder_index_count()))?;
    let (readiness, index_count) = now;
    if previous == Some(readiness) {
        return previous;
    }
    if readiness.current_offsets {
        let offsets = control::with_controller(|c| c.current_offsets()).unwrap_or_default();
        defmt::info!(
            "ready: current offsets {=f32} {=f32} {=f32} counts",
            offsets[0],
            offsets[1],
            offsets[2]
        );
    } else {
        defmt::info!("not ready: measuring the current offsets (bridge off)");
    }
    if readiness.rotor_angle {
        match index_count {
            Some(c) => defmt::info!("ready: encoder index at counter {=u32}", c),
            None => defmt::info!("ready: rotor aligned, encoder index not yet seen"),
        }
    } else {
        defmt::info!("not ready: turn the shaft past the encoder index, or run Calibrating");
    }
    Some(readiness)
}
