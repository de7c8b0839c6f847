//! Where the angle-locked lines' steady windows divide into the fitted ones and the checked
//! ones. A line is locked to the shaft's angle, not to the time, so its windows need not
//! divide where the segments do: when the rotation slow enough to read every line (the slot
//! order and 6·p_n below a third of the log's rate) lies on one side of the segments'
//! boundary, the line effects could be neither fitted nor checked there. A short log whose
//! slow holding comes late is the usual case. The windows then divide, anywhere in the log,
//! where the lesser side keeps the most slow revolutions: at a slow window's end, or in the
//! middle of a slow stretch that made one window only.

use crate::diagnose::steady::{
    better_boundary, lesser_side, slow_line_speed, slow_windows, steady_windows, SteadyWindow,
    STEADY_MIN_REVOLUTIONS,
};
use plant_model::Rig;

/// The steady windows (from row `start` on, none across the boundary) and the lines'
/// boundary: the segments' boundary `split` when each side of it holds at least
/// [`STEADY_MIN_REVOLUTIONS`] of slow rotation; else, of the slow windows' ends and the
/// middles of their stretches (a window and the rotation after it too short to make
/// another), the boundary whose windows leave the lesser side the most slow rotation, at
/// least that much; else `split`.
pub fn divided_windows(
    t: &[f64],
    theta: &[f64],
    period_s: f64,
    rig: &Rig,
    split: usize,
    start: usize,
) -> (Vec<SteadyWindow>, usize) {
    let limit = slow_line_speed(period_s, rig);
    let at = |b: usize| windows_at(t, theta, period_s, b, start);
    let slow_lesser =
        |windows: &[SteadyWindow], b: usize| lesser_side(&slow_windows(windows, limit), b);
    let windows = at(split);
    if slow_lesser(&windows, split) >= STEADY_MIN_REVOLUTIONS {
        return (windows, split);
    }
    let rows = t.len().min(theta.len());
    let mut candidates = Vec::new();
    for (k, w) in windows.iter().enumerate() {
        if w.speed_rad_s.abs() < limit {
            let stretch_end = windows.get(k + 1).map_or(rows, |n| n.rows.start);
            candidates.push(w.rows.end);
            candidates.push(w.rows.start + (stretch_end - w.rows.start) / 2);
        }
    }
    let mut best: Option<(usize, f64, Vec<SteadyWindow>)> = None;
    for b in candidates
        .into_iter()
        .filter(|b| (start + 1..rows).contains(b))
    {
        let w = at(b);
        let score = slow_lesser(&w, b);
        if best
            .as_ref()
            .is_none_or(|(b0, s0, _)| better_boundary((b, score), (*b0, *s0), split))
        {
            best = Some((b, score, w));
        }
    }
    match best {
        Some((b, score, w)) if score >= STEADY_MIN_REVOLUTIONS => (w, b),
        _ => (windows, split),
    }
}

/// The steady windows from row `start` on, found on each side of the boundary `b` apart.
fn windows_at(
    t: &[f64],
    theta: &[f64],
    period_s: f64,
    b: usize,
    start: usize,
) -> Vec<SteadyWindow> {
    let mut steady = steady_windows(&t[..b], &theta[..b], period_s)
        .into_iter()
        .filter(|w| w.rows.start >= start)
        .collect::<Vec<_>>();
    steady.extend(
        steady_windows(&t[b..], &theta[b..], period_s)
            .into_iter()
            .map(|mut w| {
                w.rows = w.rows.start + b..w.rows.end + b;
                w
            }),
    );
    steady
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// A 1 kHz angle turning at `speed(t)` for `seconds`. [s, rad]
    fn turning(seconds: f64, speed: impl Fn(f64) -> f64) -> (Vec<f64>, Vec<f64>) {
        let n = (seconds * 1e3) as usize;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let mut theta = vec![0.0; n];
        for k in 1..n {
            theta[k] = theta[k - 1] + speed(t[k]) * 1e-3;
        }
        (t, theta)
    }

    fn slow_each_side(windows: &[SteadyWindow], b: usize, limit: f64) -> (f64, f64) {
        let (mut before, mut after) = (0.0, 0.0);
        for w in windows.iter().filter(|w| w.speed_rad_s.abs() < limit) {
            assert!(
                w.rows.end <= b || w.rows.start >= b,
                "a window across the boundary"
            );
            if w.rows.end <= b {
                before += w.revolutions;
            } else {
                after += w.revolutions;
            }
        }
        (before, after)
    }

    #[test]
    fn late_slow_rotation_is_shared_between_fit_and_check() {
        // 6 s at 180 rad/s (the slot order 72 unreadable at 1 kHz: 72·180/2π = 2.1 kHz),
        // then 6.45 s at 7.7 rad/s: 7.9 revolutions, all after the middle row 6225.
        let rig = Rig::nominal();
        let limit = slow_line_speed(1e-3, &rig);
        assert!((limit - 2.0 * PI * 1000.0 / 3.0 / 72.0).abs() < 1e-9);
        let (t, theta) = turning(12.45, |t| if t < 6.0 { 180.0 } else { 7.7 });
        let split = t.len() / 2;
        let at_split = windows_at(&t, &theta, 1e-3, split, 0);
        assert_eq!(slow_each_side(&at_split, split, limit).0, 0.0);
        let (windows, b) = divided_windows(&t, &theta, 1e-3, &rig, split, 0);
        assert!(b > 6000, "the boundary {b} lies in the slow stretch");
        let (before, after) = slow_each_side(&windows, b, limit);
        // The stretch's 7.9 revolutions less what its chunks leave out, about half each.
        assert!(before >= 3.0 && after >= 3.0, "{before} | {after}");
    }

    #[test]
    fn one_slow_window_is_cut_in_the_middle_of_its_stretch() {
        // 6.5 s fast, then 2.5 s at 6.8 rad/s: 2.7 revolutions make one window of two and
        // a remainder too short for another, so no window's end divides them.
        let rig = Rig::nominal();
        let limit = slow_line_speed(1e-3, &rig);
        let (t, theta) = turning(9.0, |t| if t < 6.5 { 180.0 } else { 6.8 });
        let split = t.len() / 2;
        let at_split = windows_at(&t, &theta, 1e-3, split, 0);
        let slow: Vec<&SteadyWindow> = at_split
            .iter()
            .filter(|w| w.speed_rad_s.abs() < limit)
            .collect();
        assert_eq!(slow.len(), 1);
        let (windows, b) = divided_windows(&t, &theta, 1e-3, &rig, split, 0);
        assert!((7000..8500).contains(&b), "boundary {b}");
        let (before, after) = slow_each_side(&windows, b, limit);
        assert!(before >= 1.0 && after >= 1.0, "{before} | {after}");
    }

    #[test]
    fn a_boundary_with_slow_rotation_on_both_sides_stays() {
        let rig = Rig::nominal();
        let (t, theta) = turning(12.0, |t| if t < 2.0 { 180.0 } else { 7.0 });
        let split = t.len() / 2;
        let limit = slow_line_speed(1e-3, &rig);
        let (windows, b) = divided_windows(&t, &theta, 1e-3, &rig, split, 0);
        assert_eq!(b, split);
        // 7 rad/s from 2 s to the middle at 6 s and on to 12 s: 4 s (4.46 revolutions)
        // before, 6 s (6.68) after, each less at most a remainder too short for a window
        // (under one revolution) and a 0.1 s chunk cut at the speed change or the end.
        let (before, after) = slow_each_side(&windows, b, limit);
        let turns = |s: f64| 7.0 * s / (2.0 * PI);
        let lost = STEADY_MIN_REVOLUTIONS + turns(0.1);
        assert!(
            before <= turns(4.0) && before >= turns(4.0) - lost,
            "{before}"
        );
        assert!(after <= turns(6.0) && after >= turns(6.0) - lost, "{after}");
    }
}
