//! The supervision task: feeds the independent watchdog only while the current-loop
//! interrupt is alive, blinks the status LED, and logs the interrupt's load.
//!
//! Every [`CHECK_PERIOD`] it compares the interrupt counter with the previous check; the
//! counter must have advanced by at least half the expected number of periods. If it has
//! not (the PWM timer, the ADC trigger or the interrupt stopped), the bridge is already
//! without a current loop: the task stops feeding the watchdog and the MCU resets within
//! its timeout, which releases the gate pins. Overruns inside the interrupt latch the
//! controller's watchdog fault (see [`super::control`]). A parameter save (bridge off)
//! masks the interrupt for one flash erase; the check spanning it is skipped.

use embassy_stm32::gpio::Output;
use embassy_stm32::peripherals::IWDG;
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_time::{Duration, Ticker};

use super::control;
use super::param_flash;

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
    let mut ticker = Ticker::every(CHECK_PERIOD);
    let mut checks: u32 = 0;
    watchdog.unleash();
    loop {
        ticker.next().await;
        let now = control::isr_count();
        let advanced = now.wrapping_sub(last);
        last = now;
        // A parameter save masks the loop with the bridge off on purpose (and stalls this
        // task with it): no verdict over such a window.
        let maintenance = param_flash::maintenance_windows();
        let saved = maintenance != last_maintenance;
        last_maintenance = maintenance;
        if advanced >= minimum || saved {
            watchdog.pet();
        } else {
            defmt::error!(
                "current loop stalled: {} interrupts in {} us (expected {}); watchdog not fed",
                advanced,
                CHECK_PERIOD.as_micros(),
                expected
            );
        }
        checks = checks.wrapping_add(1);
        if checks % REPORT_EVERY == 0 {
            led.toggle();
            defmt::debug!(
                "current loop: max {} cycles per interrupt, {} overruns, {} bridge breaks",
                control::isr_max_cycles(),
                control::overruns(),
                control::breaks()
            );
        }
    }
}
