//! The supervision task: feeds the independent watchdog only while the current-loop
//! interrupt is alive, breaks the bridge when it is not, blinks the status LED, and logs
//! what a bench engineer needs to see: the drive becoming ready, hardware breaks with
//! their source, the interrupt's load and the stack's high-water mark.
//!
//! Every [`CHECK_PERIOD`] it judges the interrupt counter against the time actually
//! elapsed since its last verdict ([`firmware::liveness`]: at least half the interrupts
//! due at the PWM rate). A parameter save blocks this task for about 50 ms while the loop
//! runs on: the first check after it sees 50 ms of interrupts, and the checks its timer
//! then fires back to back are too close together to be judged. A debug halt stops the
//! executor's clock (TIM15) with the loop's timer (DBGMCU, [`super::safe_state`]), so it
//! is invisible to the judgement. A loop that falls below half its rate (the PWM timer,
//! the ADC trigger or the interrupt stopped) has no current control: the task forces a
//! break at once ([`super::safe_state::force_break`]) and stops feeding the watchdog,
//! which resets the MCU within its timeout; the next boot reports the reset as fault 11.
//! The stall is named at most 1.5 check periods after it began (7.5 ms). Overruns inside
//! the interrupt latch the controller's watchdog fault (see [`super::control`]).
//!
//! Once a second it also scans the stack's paint ([`firmware::stack`]): the high-water
//! mark goes to the log when it grows and to the CAN `Diagnostics` frame
//! ([`stack_use`]).

use core::sync::atomic::{AtomicU32, Ordering};

use embassy_stm32::gpio::Output;
use embassy_stm32::peripherals::IWDG;
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_time::{Duration, Instant, Ticker};
use firmware::liveness::{Liveness, Verdict};
use firmware::stack::StackUse;
use firmware::Readiness;

use super::control;
use super::safe_state;

/// Interval between liveness checks (well inside the watchdog timeout).
pub const CHECK_PERIOD: Duration = Duration::from_millis(5);
/// Checks between load reports, stack scans and LED toggles (1 s).
const REPORT_EVERY: u32 = 200;

// The runtime paints the stack with the value the scan looks for.
const _: () = assert!(cortex_m_rt::STACK_PAINT_VALUE == firmware::stack::PAINT);

static STACK_PEAK: AtomicU32 = AtomicU32::new(0);
static STACK_SIZE: AtomicU32 = AtomicU32::new(0);

/// The stack's use as last scanned (zero before the first scan).
pub fn stack_use() -> StackUse {
    StackUse {
        peak_bytes: STACK_PEAK.load(Ordering::Relaxed),
        size_bytes: STACK_SIZE.load(Ordering::Relaxed),
    }
}

/// Scans the painted stack region, `_stack_end` (its bottom; with flip-link the start of
/// RAM) up to `_stack_start` (its top, where the stack begins).
fn scan_stack() -> StackUse {
    extern "C" {
        static _stack_end: u32;
        static _stack_start: u32;
    }
    // Only the symbols' addresses are taken.
    let (bottom, top) = (
        core::ptr::addr_of!(_stack_end) as usize,
        core::ptr::addr_of!(_stack_start) as usize,
    );
    let words = top.saturating_sub(bottom) / 4;
    let base = bottom as *const u32;
    // SAFETY: the region is RAM the runtime painted; words below the stack pointer are
    // free memory, read (volatile) but never referenced.
    StackUse::measure(words, |k| unsafe { core::ptr::read_volatile(base.add(k)) })
}

/// Runs the supervision loop; `pwm_hz` sets the expected interrupt rate.
#[embassy_executor::task]
pub async fn run(
    mut watchdog: IndependentWatchdog<'static, IWDG>,
    mut led: Output<'static>,
    pwm_hz: u32,
) {
    let mut liveness = Liveness::new(
        pwm_hz,
        CHECK_PERIOD.as_micros() / 2,
        Instant::now().as_micros(),
        control::isr_count(),
    );
    let mut last_breaks = control::breaks();
    let mut readiness: Option<Readiness> = None;
    let mut ticker = Ticker::every(CHECK_PERIOD);
    let mut checks: u32 = 0;
    report_stack();
    watchdog.unleash();
    loop {
        ticker.next().await;
        match liveness.check(Instant::now().as_micros(), control::isr_count()) {
            Verdict::Alive => watchdog.pet(),
            Verdict::TooSoon => {}
            Verdict::Stalled {
                interrupts,
                expected,
                elapsed_us,
            } => {
                safe_state::force_break();
                defmt::error!(
                    "current loop stalled: {} interrupts in {} us (expected {}); bridge broken, watchdog not fed",
                    interrupts,
                    elapsed_us,
                    expected
                );
            }
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
            report_stack();
            defmt::debug!(
                "current loop: max {} cycles per interrupt, {} overruns, {} bridge breaks, {} telemetry frames dropped, {} NMIs",
                control::isr_max_cycles(),
                control::overruns(),
                breaks,
                control::telemetry_dropped(),
                safe_state::nmis()
            );
        }
    }
}

/// Scans the stack; logs its high-water mark when it has grown.
fn report_stack() {
    let now = scan_stack();
    if now.peak_bytes > STACK_PEAK.load(Ordering::Relaxed) {
        defmt::info!(
            "stack: high-water mark {=u32} B of {=u32} B ({=f32}x margin)",
            now.peak_bytes,
            now.size_bytes,
            now.margin()
        );
    }
    STACK_PEAK.fetch_max(now.peak_bytes, Ordering::Relaxed);
    STACK_SIZE.store(now.size_bytes, Ordering::Relaxed);
}

/// Logs a hardware break (fault 17) with its sources as the interrupt latched them.
fn report_break(sources: u8) {
    defmt::error!(
        "hardware break (fault 17): comparator U {=bool}, V {=bool}, W {=bool}, gate-driver fault line {=bool}, system break (lockup or flash ECC) {=bool}, NMI {=bool} (all false: forced by software)",
        sources & 1 != 0,
        sources & 2 != 0,
        sources & 4 != 0,
        sources & 8 != 0,
        sources & 16 != 0,
        sources & 32 != 0
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
