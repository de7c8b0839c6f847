//! The identification segment of a stroke out and back: it must see the piston travel both
//! ways.
//!
//! On a moving piston the cylinder's force balance (eq. 12) reads the Coulomb force
//! F_c·sign(v) beside the pressure transducer's zero, which adds a constant A·Δp to the
//! force. Along one way of travel the two are the same constant: the fit cannot tell them
//! apart, and the friction is read at the rig file's zero, wrong by as much as the zero's
//! tolerance on the piston (±30 kPa on 71 cm², ±213 N). The friction flips with the
//! direction and the zero does not, so a segment that holds both ways of travel separates
//! them. A stroke reversed once near mid-log leaves the first half one way only: the
//! boundary then moves into the travel back, far enough that the identification segment
//! holds [`RETURN_SHARE`] of it, within the reach the other rules of the split keep
//! ([`super::facts::SPLIT_REACH`]). The validation segment keeps the rest of the way back.

use super::steady::{steady_windows, SteadyWindow};

/// Share of the travel back (in shaft revolutions) the identification segment takes in. [1]
pub const RETURN_SHARE: f64 = 1.0 / 3.0;

/// Least travel back, relative to the travel out, that makes a stroke out and back: a
/// pressure test's pump turns back only briefly, on a falling setpoint. [1]
pub const RETURN_MIN: f64 = 0.5;

/// The boundary row for a log whose piston moves: `split` unless every steady window before
/// it turns one way and the log travels back the other way after it; then the end of the
/// window of the way back at which the identification holds [`RETURN_SHARE`] of it, or the
/// last such end at or before `reach_end`.
pub fn two_way_split(
    t: &[f64],
    theta: &[f64],
    period_s: f64,
    split: usize,
    reach_end: usize,
) -> usize {
    let windows = steady_windows(t, theta, period_s);
    let way = |w: &&SteadyWindow| w.speed_rad_s.signum();
    let mut before = windows.iter().filter(|w| w.rows.end <= split);
    let Some(out) = before.next().map(|w| way(&w)) else {
        return split;
    };
    if before.any(|w| way(&w) != out) {
        return split;
    }
    let travel = |dir: f64, from: usize| -> f64 {
        windows
            .iter()
            .filter(|w| w.rows.start >= from && way(w) == dir)
            .map(|w| w.revolutions)
            .sum()
    };
    let (back, gone) = (travel(-out, split), travel(out, 0));
    if back <= 0.0 || back < RETURN_MIN * gone {
        return split;
    }
    let mut taken = 0.0;
    let mut boundary = split;
    for w in windows
        .iter()
        .filter(|w| w.rows.start >= split && way(w) == -out)
    {
        if w.rows.end > reach_end {
            break;
        }
        taken += w.revolutions;
        boundary = w.rows.end;
        if taken >= RETURN_SHARE * back {
            break;
        }
    }
    boundary
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// A shaft at `speed` rad/s for `out_s`, reversed at once, back for `back_s`, sampled
    /// at 1 kHz: (t, θ).
    fn stroke(speed: f64, out_s: f64, back_s: f64) -> (Vec<f64>, Vec<f64>) {
        let n = ((out_s + back_s) * 1000.0) as usize;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
        let theta = t
            .iter()
            .map(|&t| {
                if t <= out_s {
                    speed * t
                } else {
                    speed * (2.0 * out_s - t)
                }
            })
            .collect();
        (t, theta)
    }

    #[test]
    fn a_stroke_reversed_at_the_middle_takes_a_third_of_the_way_back() {
        // 10 s out and 10 s back at 20 rad/s: 31.8 revolutions each way, in windows of
        // about a second. A third of the way back ends about 3.3 s after the reversal.
        let (t, theta) = stroke(20.0, 10.0, 10.0);
        let split = 10_000;
        let b = two_way_split(&t, &theta, 1e-3, split, 14_000);
        let back_revs = |row: usize| (theta[split] - theta[row]) / (2.0 * PI);
        let total = 20.0 * 10.0 / (2.0 * PI);
        // The steady windows miss at most a 0.1 s chunk at either end of the way back (the
        // reversal's, the log's last): at least a third of the rest is taken in, and at
        // most one window (1 s, 3.2 revolutions) more than a third of the whole.
        let chunk = 20.0 * 0.1 / (2.0 * PI);
        assert!(
            back_revs(b) >= (total - 2.0 * chunk) / 3.0,
            "{}",
            back_revs(b)
        );
        assert!(
            back_revs(b) <= total / 3.0 + 20.0 / (2.0 * PI),
            "{}",
            back_revs(b)
        );
        // The shaft turned both ways before the boundary.
        assert!(theta[b] < theta[split]);
    }

    #[test]
    fn the_boundary_stays_within_its_reach() {
        let (t, theta) = stroke(20.0, 10.0, 10.0);
        let b = two_way_split(&t, &theta, 1e-3, 10_000, 11_500);
        assert!(b > 10_000 && b <= 11_500, "{b}");
    }

    #[test]
    fn one_way_travel_and_a_brief_turn_back_leave_the_split() {
        // One way only.
        let t: Vec<f64> = (0..20_000).map(|i| i as f64 * 1e-3).collect();
        let theta: Vec<f64> = t.iter().map(|t| 20.0 * t).collect();
        assert_eq!(two_way_split(&t, &theta, 1e-3, 10_000, 14_000), 10_000);
        // 10 s out, 2 s back (a fifth of the way out), then still.
        let (mut t, mut theta) = stroke(20.0, 10.0, 2.0);
        let last = *theta.last().unwrap();
        for i in 0..8000 {
            t.push(12.0 + i as f64 * 1e-3);
            theta.push(last);
        }
        assert_eq!(two_way_split(&t, &theta, 1e-3, 10_000, 14_000), 10_000);
    }

    #[test]
    fn a_first_half_already_both_ways_keeps_its_split() {
        // Out 4 s, back 4 s, out again: the first 10 s hold both ways.
        let (mut t, mut theta) = stroke(20.0, 4.0, 4.0);
        let last = *theta.last().unwrap();
        for i in 1..12_000 {
            t.push(8.0 + i as f64 * 1e-3);
            theta.push(last + 20.0 * i as f64 * 1e-3);
        }
        assert_eq!(two_way_split(&t, &theta, 1e-3, 10_000, 14_000), 10_000);
    }
}
