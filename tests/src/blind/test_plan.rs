//! The bench test a blind log records, drawn as an independent bench draws its own
//! (`shared/data/foreign-logs-2/README.md`): which test, its setpoints, its length and the
//! rate it is logged at. The scenarios are `closed_loop::bench_test`'s; this module only
//! draws their parameters.
//!
//! - `step`: from 0.5 MPa a ramp to a level between 3.5 and 8 MPa, a hold, a step of
//!   ±1 MPa near mid-log, a hold;
//! - `staircase`: after the ramp, 3 to 5 pressure levels between 2 and 9 MPa, each held
//!   3 to 6 s;
//! - `sine`: a ramp to a level, a short hold, then a sinusoidal pressure setpoint of
//!   ±0.3 to 1.0 MPa at 0.05 to 0.5 Hz;
//! - `stroke`: the payload free, speed control at a constant speed between 8 and 40 rad/s,
//!   reversed once near mid-log so the piston comes back (at most 1.4 mm/s for 20 s:
//!   well inside the ±50 mm stroke).
//!
//! Lengths 15 to 40 s; log rates 500 Hz, 1 kHz or 2 kHz, one log in five at 5 or 10 kHz
//! (whole divisors of the drive's 20 kHz PWM, as a telemetry decimation is).

use super::stream::Stream;
use closed_loop::bench_test::{sine_test, staircase_test, step_test, stroke_test, SETTLE_S};
use closed_loop::Scenario;

/// The four tests.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum TestKind {
    /// A pressure step on the blocked cylinder.
    Step,
    /// A pressure staircase on the blocked cylinder.
    Staircase,
    /// A sinusoidal pressure on the blocked cylinder.
    Sine,
    /// The free payload stroked out and back under speed control.
    Stroke,
}

/// Every test.
pub const TESTS: [TestKind; 4] = [
    TestKind::Step,
    TestKind::Staircase,
    TestKind::Sine,
    TestKind::Stroke,
];

impl TestKind {
    /// Its name in the truth.
    pub fn name(self) -> &'static str {
        match self {
            TestKind::Step => "step",
            TestKind::Staircase => "staircase",
            TestKind::Sine => "sine",
            TestKind::Stroke => "stroke",
        }
    }

    /// The test called `name`.
    pub fn from_name(name: &str) -> Option<TestKind> {
        TESTS.into_iter().find(|t| t.name() == name)
    }
}

/// Shortest and longest log. [s]
pub const LENGTH_S: (f64, f64) = (15.0, 40.0);

/// The ordinary log rates. [Hz]
pub const RATES_HZ: [f64; 3] = [500.0, 1e3, 2e3];

/// The fast log rates, one log in [`FAST_SHARE`]. [Hz]
pub const FAST_RATES_HZ: [f64; 2] = [5e3, 10e3];

/// Share of logs taken at a fast rate. [1]
pub const FAST_SHARE: f64 = 0.2;

/// Draws the log rate. [Hz]
pub(super) fn draw_log_rate(s: &mut Stream) -> f64 {
    if s.unit() < FAST_SHARE {
        s.pick(&FAST_RATES_HZ)
    } else {
        s.pick(&RATES_HZ)
    }
}

/// A ramp from the start pressure takes 2 to 4 s (0.5–2.5 MPa/s: within what the pump
/// delivers into the absorber at its speed limit). [s]
fn draw_ramp(s: &mut Stream) -> f64 {
    s.uniform(2.0, 4.0)
}

/// Draws the scenario of `test`.
pub(super) fn draw_test(s: &mut Stream, test: TestKind) -> Scenario {
    let built = match test {
        TestKind::Step => {
            let length = s.uniform(LENGTH_S.0, LENGTH_S.1);
            let level = s.uniform(3.5e6, 8e6);
            let ramp = draw_ramp(s);
            let step_at = length * s.uniform(0.45, 0.55);
            step_test(level, ramp, step_at, s.sign() * 1e6, length)
        }
        TestKind::Staircase => draw_staircase(s),
        TestKind::Sine => {
            let length = s.uniform(LENGTH_S.0, LENGTH_S.1);
            let level = s.uniform(3.5e6, 8e6);
            let ramp = draw_ramp(s);
            let hold = s.uniform(1.0, 3.0);
            let amplitude = s.uniform(0.3e6, 1.0e6);
            // Log-uniform: as many slow sines as fast ones per decade.
            let frequency = 0.05 * (s.unit() * 10f64.ln()).exp();
            sine_test(level, ramp, hold, amplitude, frequency, length)
        }
        TestKind::Stroke => {
            let length = s.uniform(LENGTH_S.0, LENGTH_S.1);
            let speed = s.sign() * s.uniform(8.0, 40.0);
            let accel = s.uniform(0.3, 1.0);
            // Out as far as back: the equivalent full-speed times (r − settle − a/2) and
            // (length − r) equal; then moved by up to ±3 % of the length.
            let back = 0.5 * (length + SETTLE_S + 0.5 * accel);
            let reverse_at = back + length * s.uniform(-0.03, 0.03);
            stroke_test(speed, accel, reverse_at, length)
        }
    };
    // The drawn values are inside every builder's limits by construction.
    built.unwrap_or_else(|e| unreachable!("a drawn {} test is valid: {e:?}", test.name()))
}

/// A staircase of 3 to 5 levels, each at least 0.5 MPa from the one before and held 3 to
/// 6 s, whose whole length falls in [`LENGTH_S`] (drawn again until it does).
fn draw_staircase(s: &mut Stream) -> Result<Scenario, closed_loop::profile::ProfileError> {
    loop {
        let n = s.pick(&[3usize, 4, 5]);
        let ramp = draw_ramp(s);
        let mut levels = Vec::with_capacity(n);
        while levels.len() < n {
            let p = s.uniform(2e6, 9e6);
            let far = levels
                .last()
                .is_none_or(|&(q, _): &(f64, f64)| (p - q).abs() >= 0.5e6);
            if far {
                levels.push((p, s.uniform(3.0, 6.0)));
            }
        }
        let length = SETTLE_S + ramp + levels.iter().map(|l| l.1).sum::<f64>();
        if (LENGTH_S.0..=LENGTH_S.1).contains(&length) {
            return staircase_test(&levels, ramp);
        }
    }
}
