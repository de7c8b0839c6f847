//! The judgement inside a simulated board: the loop's interrupts at 20 kHz, the
//! supervision task woken by embassy's periodic timer (`Ticker`: a missed period fires at
//! once, so a blocked executor is followed by a burst of back-to-back checks), an executor
//! that a parameter save blocks, a debug halt that stops the core, the PWM timer and —
//! when frozen — the executor's clock. Wall time advances in 10 µs steps.

use super::*;
use std::vec::Vec;

/// PWM and interrupt rate of the board. [Hz]
const RATE_HZ: u32 = 20_000;
/// The supervision task's check period. [µs]
const P_US: u64 = 5_000;
/// How long one check keeps the task busy. [µs]
const CHECK_US: u64 = 20;
/// Simulation step. [µs]
const STEP_US: u64 = 10;

/// What the board does over a run (all times in wall-clock µs).
#[derive(Clone, Default)]
struct Board {
    /// A debug halt: the core, TIM1 (so the loop) and the IWDG stop.
    halt: Option<(u64, u64)>,
    /// TIM15, the executor's clock, stops in the halt as well.
    clock_frozen: bool,
    /// Spans in which the executor runs nothing (a parameter save's flash erase).
    blocked: Vec<(u64, u64)>,
    /// The loop stops for good at this loop time (its own time, halts excluded).
    loop_stops: Option<u64>,
}

/// One check: wall time, the interrupts since the previous check, the verdict.
#[derive(Clone, Copy, Debug)]
struct Check {
    wall_us: u64,
    since_previous: u32,
    verdict: Verdict,
}

impl Board {
    fn halted_before(&self, w: u64) -> u64 {
        match self.halt {
            Some((a, b)) if w > a => w.min(b) - a,
            _ => 0,
        }
    }

    fn halted(&self, w: u64) -> bool {
        self.halt.is_some_and(|(a, b)| (a..b).contains(&w))
    }

    /// The executor's clock (TIM15).
    fn clock(&self, w: u64) -> u64 {
        if self.clock_frozen {
            w - self.halted_before(w)
        } else {
            w
        }
    }

    /// Interrupts completed by wall time `w`: one per PWM period of loop time.
    fn count(&self, w: u64) -> u32 {
        let t = w - self.halted_before(w);
        let t = self.loop_stops.map_or(t, |s| t.min(s));
        (t * u64::from(RATE_HZ) / 1_000_000) as u32
    }

    fn executor_free(&self, w: u64) -> bool {
        !self.halted(w) && !self.blocked.iter().any(|(a, b)| (*a..*b).contains(&w))
    }

    /// Runs the supervision task's loop until wall time `until`: `Ticker::every(P)`, then
    /// `ticker.next().await` and one check per pass.
    fn run(&self, until: u64) -> Vec<Check> {
        let mut judge = Liveness::new(RATE_HZ, P_US / 2, self.clock(0), self.count(0));
        let mut expires = P_US;
        let mut checks = Vec::new();
        let mut previous = self.count(0);
        let mut w = 0;
        while w <= until {
            if self.clock(w) >= expires && self.executor_free(w) {
                expires += P_US;
                let count = self.count(w);
                checks.push(Check {
                    wall_us: w,
                    since_previous: count.wrapping_sub(previous),
                    verdict: judge.check(self.clock(w), count),
                });
                previous = count;
                w += CHECK_US;
            } else {
                w += STEP_US;
            }
        }
        checks
    }
}

fn stalls(checks: &[Check]) -> Vec<Check> {
    checks
        .iter()
        .filter(|c| matches!(c.verdict, Verdict::Stalled { .. }))
        .copied()
        .collect()
}

/// The longest wall time between two `Alive` verdicts (the watchdog is fed on those).
fn longest_unfed(checks: &[Check]) -> u64 {
    let alive: Vec<u64> = checks
        .iter()
        .filter(|c| c.verdict == Verdict::Alive)
        .map(|c| c.wall_us)
        .collect();
    alive.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0)
}

#[test]
fn a_parameter_save_blocking_the_executor_is_not_a_stall() {
    // The erase of the two pages of a slot (about 2 × 22 ms), at every phase of the check
    // period, and longer blocks.
    for length in [22_000, 44_000, 50_000, 100_000] {
        for phase in (0..P_US).step_by(250) {
            let start = 1_000_000 + phase;
            let board = Board {
                blocked: vec![(start, start + length)],
                ..Board::default()
            };
            let checks = board.run(2_000_000);
            assert!(
                stalls(&checks).is_empty(),
                "{length} µs block at phase {phase}: {:?}",
                stalls(&checks)
            );
            // The burst after the block: the checks the timer missed, back to back. Each
            // sees no or one interrupt since the previous one — what a check that assumed
            // P between checks (needing P·f/2 = 50) called a stalled loop.
            let first = checks
                .iter()
                .position(|c| c.wall_us >= start + length)
                .expect("checks after the block");
            let mut burst = vec![checks[first]];
            for c in &checks[first + 1..] {
                if c.wall_us - burst[burst.len() - 1].wall_us > CHECK_US {
                    break;
                }
                burst.push(*c);
            }
            let missed = (length / P_US) as usize;
            assert!(burst.len() >= missed, "{length} µs: burst {burst:?}");
            assert!(burst.iter().skip(1).all(|c| c.since_previous <= 1));
            assert_eq!(burst[0].verdict, Verdict::Alive);
            assert!(burst[1..].iter().all(|c| c.verdict == Verdict::TooSoon));
            // Outside the block the watchdog is fed at least every two periods.
            let after: Vec<Check> = checks
                .iter()
                .filter(|c| c.wall_us > start + length)
                .copied()
                .collect();
            assert!(longest_unfed(&after) <= 2 * P_US + CHECK_US);
        }
    }
}

#[test]
fn a_debug_halt_is_not_a_stall_when_the_executor_clock_stops_with_the_core() {
    let halt = Some((1_002_345, 31_002_345));
    let frozen = Board {
        halt,
        clock_frozen: true,
        ..Board::default()
    };
    let checks = frozen.run(32_000_000);
    assert!(stalls(&checks).is_empty(), "{:?}", stalls(&checks));
    // Before and after the halt the loop is judged alive at every period.
    let resumed: Vec<Check> = checks
        .iter()
        .filter(|c| c.wall_us > 31_002_345)
        .copied()
        .collect();
    assert!(resumed.len() >= 190);
    assert!(longest_unfed(&resumed) <= P_US + CHECK_US);
    // The control: TIM15 running on through the halt (no DBGMCU freeze bit) makes the
    // first check after it see 30 s without an interrupt.
    let running = Board {
        halt,
        clock_frozen: false,
        ..Board::default()
    };
    let stalled = stalls(&running.run(32_000_000));
    assert!(!stalled.is_empty());
    assert!(stalled[0].wall_us >= 31_002_345 && stalled[0].wall_us < 31_003_000);
}

#[test]
fn a_stopped_loop_is_named_within_one_and_a_half_check_periods() {
    // 1.5·P from the derivation in the module docs; the simulation adds the check's own
    // duration and step, and one PWM period for the interrupt in flight.
    let bound = P_US + P_US / 2 + CHECK_US + STEP_US + 1_000_000 / u64::from(RATE_HZ);
    let mut worst = 0;
    for phase in (0..2 * P_US).step_by(50) {
        let stop = 500_000 + phase;
        let board = Board {
            loop_stops: Some(stop),
            ..Board::default()
        };
        let checks = board.run(stop + 30_000);
        assert!(checks
            .iter()
            .filter(|c| c.wall_us <= stop)
            .all(|c| c.verdict == Verdict::Alive));
        let first = stalls(&checks)[0];
        let latency = first.wall_us - stop;
        assert!(latency <= bound, "stop at {stop}: named after {latency} µs");
        worst = worst.max(latency);
    }
    // The bound is reached, not just respected: a stop just after half a period goes
    // unnoticed by the next check.
    assert!(worst > P_US + P_US / 2 - 100, "worst {worst} µs");
}

#[test]
fn a_stall_inside_a_save_is_named_at_the_first_check_after_it() {
    let board = Board {
        blocked: vec![(1_000_500, 1_050_500)],
        loop_stops: Some(1_010_000),
        ..Board::default()
    };
    let checks = board.run(1_100_000);
    let first = stalls(&checks)[0];
    assert!(first.wall_us >= 1_050_500 && first.wall_us < 1_050_600);
    match first.verdict {
        Verdict::Stalled {
            interrupts,
            expected,
            ..
        } => {
            // The previous verdict was at 1.000 s: 10 ms of the 50.5 ms span ran, 200 of
            // the 1010 interrupts due.
            assert_eq!((interrupts, expected), (200, 1010));
        }
        v => panic!("{v:?}"),
    }
}

#[test]
fn the_loop_must_keep_half_its_rate_over_the_span_judged() {
    let mut j = Liveness::new(RATE_HZ, 2_500, 0, u32::MAX - 10);
    // 5 ms at 40 % of 20 kHz: 40 interrupts of 100.
    assert!(matches!(
        j.check(5_000, (u32::MAX - 10).wrapping_add(40)),
        Verdict::Stalled {
            interrupts: 40,
            expected: 100,
            elapsed_us: 5_000
        }
    ));
    // The counter wraps: 60 of 100 is alive.
    assert_eq!(j.check(10_000, 89), Verdict::Alive);
    // A span shorter than the minimum is not judged, and keeps its start.
    assert_eq!(j.check(11_000, 89), Verdict::TooSoon);
    assert_eq!(j.check(12_000, 89), Verdict::TooSoon);
    assert_eq!(j.check(12_500, 89 + 25), Verdict::Alive);
    // A clock that went backwards is a span of zero.
    assert_eq!(j.check(0, 200), Verdict::TooSoon);
}
