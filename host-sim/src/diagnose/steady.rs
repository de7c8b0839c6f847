//! Stretches of steady rotation, where the angle-locked lines (eq. 16–20 at one order each)
//! can be read: the log cut into chunks, consecutive chunks at nearly the same mean speed
//! joined into windows of a revolution or more; and which of them turn slowly enough for
//! every line to stay below a third of the log's rate, counted on each side of a boundary.

use plant_model::Rig;
use std::f64::consts::PI;
use std::ops::{Range, RangeInclusive};

/// Shortest steady-rotation window for the angle-locked lines. [s]
pub const STEADY_WINDOW_S: f64 = 0.2;

/// Length a steady window grows to before it closes (with [`STEADY_TARGET_REVOLUTIONS`]):
/// longer windows resolve the lines better, shorter ones let a short log have any. [s]
pub const STEADY_TARGET_S: f64 = 1.0;

/// Revolutions a steady window grows to before it closes. [1]
pub const STEADY_TARGET_REVOLUTIONS: f64 = 2.0;

/// Longest steady-rotation window: at a slow holding speed it takes a few seconds to turn
/// [`STEADY_MIN_REVOLUTIONS`]. [s]
pub const STEADY_MAX_S: f64 = 4.0;

/// Chunk whose mean speed the steady windows are built from. [s]
pub const STEADY_CHUNK_S: f64 = 0.1;

/// Largest departure of a chunk's mean speed from its window's mean, relative to it: wide
/// enough to take the slow holding, whose pressure loop makes the shaft's speed wander by
/// a fifth about its mean, while a speed step or a stroke's start still cuts a window. [1]
pub const STEADY_SPREAD: f64 = 0.25;

/// Fewest mechanical revolutions a steady window must hold for its lines to be resolved
/// (over one revolution orders k and k ± 1 are orthogonal). [1]
pub const STEADY_MIN_REVOLUTIONS: f64 = 1.0;

/// A stretch of steady rotation.
#[derive(Clone, Debug, PartialEq)]
pub struct SteadyWindow {
    /// Rows.
    pub rows: Range<usize>,
    /// Mean shaft speed (signed). [rad/s]
    pub speed_rad_s: f64,
    /// Revolutions turned. [1]
    pub revolutions: f64,
}

/// Fastest steady rotation whose every angle-locked line (the slot order and 6·p_n) stays
/// below a third of the log's rate. [rad/s]
pub fn slow_line_speed(period_s: f64, rig: &Rig) -> f64 {
    let highest = rig
        .motor
        .cogging_fundamental_order()
        .max(6 * rig.motor.pole_pairs) as f64;
    2.0 * PI / period_s / 3.0 / highest
}

/// The windows slower than `limit` (those whose every line is read: [`slow_line_speed`]).
/// [rad/s]
pub fn slow_windows(windows: &[SteadyWindow], limit: f64) -> Vec<&SteadyWindow> {
    windows
        .iter()
        .filter(|w| w.speed_rad_s.abs() < limit)
        .collect()
}

/// Whether the boundary `c` (row, revolutions on its lesser side) beats `best`: more
/// revolutions, or as many and closer to `middle`.
pub fn better_boundary(c: (usize, f64), best: (usize, f64), middle: usize) -> bool {
    c.1 > best.1 || (c.1 == best.1 && c.0.abs_diff(middle) < best.0.abs_diff(middle))
}

/// Revolutions of `windows` on the lesser side of the boundary `split` (windows across it
/// count on neither side). [1]
pub fn lesser_side(windows: &[&SteadyWindow], split: usize) -> f64 {
    let (mut a, mut b) = (0.0, 0.0);
    for w in windows {
        if w.rows.end <= split {
            a += w.revolutions;
        } else if w.rows.start >= split {
            b += w.revolutions;
        }
    }
    f64::min(a, b)
}

/// Of the windows' ends within `reach`, and `middle`, the boundary that leaves the lesser
/// side the most revolutions (the one closer to `middle` on a tie), with those revolutions.
pub fn balanced_boundary(
    windows: &[&SteadyWindow],
    middle: usize,
    reach: RangeInclusive<usize>,
) -> (usize, f64) {
    windows
        .iter()
        .map(|w| w.rows.end)
        .filter(|s| reach.contains(s))
        .map(|s| (s, lesser_side(windows, s)))
        .fold((middle, lesser_side(windows, middle)), |b, c| {
            if better_boundary(c, b, middle) {
                c
            } else {
                b
            }
        })
}

/// Steady-rotation windows: the log cut into chunks of [`STEADY_CHUNK_S`], consecutive
/// chunks whose mean speeds stay within [`STEADY_SPREAD`] of the window's mean joined. A
/// window closes once it holds [`STEADY_TARGET_REVOLUTIONS`] and [`STEADY_TARGET_S`] (or
/// [`STEADY_MAX_S`]); one cut short by a change of speed or the segment's end is kept if
/// it holds at least [`STEADY_MIN_REVOLUTIONS`] and [`STEADY_WINDOW_S`].
pub fn steady_windows(t: &[f64], theta: &[f64], period_s: f64) -> Vec<SteadyWindow> {
    let n = t.len().min(theta.len());
    let chunk = ((STEADY_CHUNK_S / period_s).round() as usize).max(8);
    let speed =
        |r: &Range<usize>| (theta[r.end - 1] - theta[r.start]) / (t[r.end - 1] - t[r.start]);
    let turned = |r: &Range<usize>| (theta[r.end - 1] - theta[r.start]).abs() / (2.0 * PI);
    let length = |r: &Range<usize>| t[r.end - 1] - t[r.start];
    let mut out = Vec::new();
    let keep = |rows: Range<usize>, out: &mut Vec<SteadyWindow>| {
        if turned(&rows) >= STEADY_MIN_REVOLUTIONS && length(&rows) >= STEADY_WINDOW_S {
            out.push(SteadyWindow {
                speed_rad_s: speed(&rows),
                revolutions: turned(&rows),
                rows,
            });
        }
    };
    // The open window: its first row and its chunks' mean speeds.
    let mut open: Option<(usize, Vec<f64>)> = None;
    let mut start = 0;
    while start + chunk <= n {
        let c = start..start + chunk;
        let w = speed(&c);
        start += chunk;
        if let Some((s0, mut speeds)) = open.take() {
            let mean = speeds.iter().sum::<f64>() / speeds.len() as f64;
            if w != 0.0
                && (w - mean).abs() <= STEADY_SPREAD * mean.abs()
                && w.signum() == mean.signum()
            {
                speeds.push(w);
                let rows = s0..c.end;
                if (turned(&rows) >= STEADY_TARGET_REVOLUTIONS && length(&rows) >= STEADY_TARGET_S)
                    || length(&rows) >= STEADY_MAX_S
                {
                    keep(rows, &mut out);
                } else {
                    open = Some((s0, speeds));
                }
                continue;
            }
            keep(s0..c.start, &mut out);
        }
        if w != 0.0 {
            open = Some((c.start, vec![w]));
        }
    }
    if let Some((s0, _)) = open {
        keep(s0..(start).min(n), &mut out);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steady_windows_are_found_where_the_speed_is_constant() {
        // 2 s at 0 rad/s, then 6 s at 10 rad/s (1.6 revolutions per second).
        let t: Vec<f64> = (0..8000).map(|k| k as f64 * 1e-3).collect();
        let th: Vec<f64> = t
            .iter()
            .map(|&t| if t < 2.0 { 0.0 } else { 10.0 * (t - 2.0) })
            .collect();
        let w = steady_windows(&t, &th, 1e-3);
        assert!(!w.is_empty());
        for s in &w {
            assert!(t[s.rows.start] >= 2.0, "{:?}", s.rows);
            assert!((s.speed_rad_s - 10.0).abs() < 0.1, "{}", s.speed_rad_s);
        }
    }
}
