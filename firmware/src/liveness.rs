//! Liveness of the current loop, as the board's supervision task judges it before it feeds
//! the independent watchdog: from the count of completed current-loop interrupts and the
//! time that has *actually* elapsed between two checks.
//!
//! The supervision task runs on the thread-mode executor every check period P (5 ms on the
//! board). Two things delay it without the loop being at fault, and a judgement that
//! assumed exactly P between checks would call both a stall:
//!
//! - A blocked executor. A parameter save erases flash from a task for about 50 ms; the
//!   loop's interrupt runs on, the supervision task does not, and its periodic timer then
//!   fires for every period it missed, back to back: the first check sees 50 ms worth of
//!   interrupts, the next ones see none at all.
//! - A debug halt. The core stops, and with it the PWM timer (so the loop, which it
//!   triggers) and, when the board freezes it too, the timer that keeps the executor's
//!   time: time and interrupt count stop together, and the judgement never sees the halt.
//!   A clock that ran on through the halt would show seconds without a single interrupt.
//!
//! So [`Liveness::check`] compares the interrupts counted with the rate the loop must keep
//! over the time elapsed since the last verdict, and gives no verdict at all over a span
//! shorter than its minimum (the back-to-back checks after a blocked executor), keeping
//! its reference point until a span is long enough. The loop is alive when it completed
//! at least half of the interrupts due.
//!
//! Detection bound. With checks every P and a minimum span of P/2, every regular check
//! judges the span since the previous one. A loop that stops at time s, a time Δ after the
//! previous verdict, leaves Δ·f of the P·f interrupts due by the next check: that check
//! calls the stall if Δ < P/2, otherwise the one after it, whose span has none. The stall
//! is therefore named at most 1.5·P after it began (7.5 ms at P = 5 ms, well inside the
//! 20 ms watchdog), plus however late the check itself is.

/// What one check concluded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The loop kept at least half its rate since the previous verdict.
    Alive,
    /// Too little time has elapsed since the previous verdict to judge; the reference
    /// point is kept.
    TooSoon,
    /// The loop fell below half its rate since the previous verdict.
    Stalled {
        /// Interrupts completed over the span.
        interrupts: u32,
        /// Interrupts due over the span at the nominal rate.
        expected: u64,
        /// The span judged. [µs]
        elapsed_us: u64,
    },
}

/// The judgement's state: the nominal rate and the reference point of the next verdict.
#[derive(Clone, Copy, Debug)]
pub struct Liveness {
    /// Nominal interrupt rate (the PWM rate). [Hz]
    rate_hz: u32,
    /// Shortest span judged. [µs]
    min_span_us: u64,
    /// Time of the previous verdict (or of the start). [µs]
    since_us: u64,
    /// Interrupt count at that time (wraps).
    since_count: u32,
}

impl Liveness {
    /// Starts the judgement at time `now_us` [µs] with the interrupt counter at `count`,
    /// for a loop at `rate_hz` [Hz], judging spans of at least `min_span_us` [µs].
    pub const fn new(rate_hz: u32, min_span_us: u64, now_us: u64, count: u32) -> Liveness {
        Liveness {
            rate_hz,
            min_span_us,
            since_us: now_us,
            since_count: count,
        }
    }

    /// One check at time `now_us` [µs] (a monotonic clock that stops in a debug halt) with
    /// the interrupt counter at `count` (wrapping).
    pub fn check(&mut self, now_us: u64, count: u32) -> Verdict {
        let elapsed_us = now_us.saturating_sub(self.since_us);
        if elapsed_us < self.min_span_us {
            return Verdict::TooSoon;
        }
        let interrupts = count.wrapping_sub(self.since_count);
        let expected = elapsed_us.saturating_mul(u64::from(self.rate_hz)) / 1_000_000;
        self.since_us = now_us;
        self.since_count = count;
        if 2 * u64::from(interrupts) >= expected {
            Verdict::Alive
        } else {
            Verdict::Stalled {
                interrupts,
                expected,
                elapsed_us,
            }
        }
    }
}

#[cfg(test)]
mod tests;
