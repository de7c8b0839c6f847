//! Timestamps a logger stamped off its samples: a drive that samples on its own clock and a
//! PC that stamps each row as it arrives (CAN or USB telemetry) write rows taken evenly with
//! times that scatter about them. Read at those times, the shaft's angle jumps back and
//! forth by ω·δt (36 mrad at 180 rad/s for 0.2 ms), and every relation that differentiates
//! it reads that as motion. A log sampled unevenly at the times it gives is the opposite
//! case, and the log itself tells which: the logged angle turns smoothly on the true time
//! base only.
//!
//! Each row is given the slot of an even grid its interval from the last row counts
//! (rows a logger lost leave their slots empty); where every stamp lies within
//! [`SLOT_REACH`] of its slot on the grid fitted to them by least squares, and the angle
//! interpolated between each row's neighbours is [`SMOOTHER_BY`] times closer to it on the
//! grid than on the logged times, the rows are read on the grid.

use crate::bench_log::BenchLog;
use crate::diagnose::facts::{evenly_sampled, median_period, unwrap_angle};

/// Farthest a stamp may lie from its slot for the log to be read on the grid, as a fraction
/// of the grid's period: beyond it two neighbouring stamps could trade slots. [1]
pub const SLOT_REACH: f64 = 0.35;

/// How many times closer the grid must bring each row's angle to its neighbours'
/// interpolation than the logged times do: a log sampled at its times turns as smoothly on
/// them as on the grid or more so, one stamped off its samples far less so. [1]
pub const SMOOTHER_BY: f64 = 2.0;

/// `log` with its times moved onto the even grid its rows were sampled on, when the logged
/// angle shows they were stamped off it (see the module docs); `None` when the log is
/// evenly sampled, has no angle, or is read best at its own times.
pub fn on_even_grid(log: &BenchLog) -> Option<BenchLog> {
    let t = &log.t_s;
    let theta = log.theta_m_rad.as_deref()?;
    let n = t.len().min(theta.len());
    let period = median_period(t);
    if n < 3 || evenly_sampled(t, period) {
        return None;
    }
    let grid = grid_times(&t[..n], period)?;
    let logged = interpolation_rms(&t[..n], &unwrap_angle(theta, t, &log.speed_rad_s));
    let even = interpolation_rms(&grid, &unwrap_angle(theta, &grid, &log.speed_rad_s));
    (even * SMOOTHER_BY < logged).then(|| BenchLog {
        t_s: grid,
        ..log.clone()
    })
}

/// The even grid's times of the rows at `t` whose median interval is `period` [s]: each
/// row's slot counted from its interval to the last one, the grid fitted to the stamps by
/// least squares; `None` when a stamp lies beyond [`SLOT_REACH`] of its slot. [s]
fn grid_times(t: &[f64], period: f64) -> Option<Vec<f64>> {
    let mut slots = Vec::with_capacity(t.len());
    let mut slot = 0.0f64;
    for (k, tk) in t.iter().enumerate() {
        if k > 0 {
            slot += ((tk - t[k - 1]) / period).round().max(1.0);
        }
        slots.push(slot);
    }
    let n = t.len() as f64;
    let (ms, ts) = (slots.iter().sum::<f64>() / n, t.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (m, tk) in slots.iter().zip(t) {
        sxy += (m - ms) * (tk - ts);
        sxx += (m - ms) * (m - ms);
    }
    let step = sxy / sxx;
    if !(step > 0.0 && step.is_finite()) {
        return None;
    }
    let grid: Vec<f64> = slots.iter().map(|m| ts + (m - ms) * step).collect();
    grid.iter()
        .zip(t)
        .all(|(g, tk)| (g - tk).abs() < SLOT_REACH * step)
        .then_some(grid)
}

/// RMS of each inner row's angle less the straight line through its neighbours at the
/// times `t`. [rad]
fn interpolation_rms(t: &[f64], theta: &[f64]) -> f64 {
    let mut sum = 0.0;
    for k in 1..t.len() - 1 {
        let f = (t[k] - t[k - 1]) / (t[k + 1] - t[k - 1]);
        let e = theta[k] - (theta[k - 1] + f * (theta[k + 1] - theta[k - 1]));
        sum += e * e;
    }
    (sum / (t.len() - 2) as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A shaft turning at 180 rad/s with a 2 rad/s, 7 Hz wobble, sampled at 1 kHz at the
    /// instants `sampled` and stamped at `stamped`.
    fn log(sampled: &[f64], stamped: &[f64]) -> BenchLog {
        let angle =
            |t: f64| 180.0 * t + 2.0 / (2.0 * std::f64::consts::PI * 7.0) * (44.0 * t).sin();
        let n = sampled.len();
        BenchLog {
            t_s: stamped.to_vec(),
            speed_rad_s: vec![180.0; n],
            theta_m_rad: Some(
                sampled
                    .iter()
                    .map(|t| angle(*t).rem_euclid(2.0 * std::f64::consts::PI))
                    .collect(),
            ),
            ..BenchLog::default()
        }
    }

    /// ±0.2 ms about each millisecond, from a fixed sequence.
    fn scattered(n: usize) -> Vec<f64> {
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        (0..n)
            .map(|k| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                k as f64 * 1e-3 + ((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.4e-3
            })
            .collect()
    }

    #[test]
    fn rows_sampled_evenly_and_stamped_off_them_are_read_on_the_grid() {
        let even: Vec<f64> = (0..2000).map(|k| k as f64 * 1e-3).collect();
        let read = on_even_grid(&log(&even, &scattered(2000))).expect("read on the grid");
        for (g, t) in read.t_s.iter().zip(&even) {
            // The grid fitted to the stamps: within a few microseconds of the sampling.
            assert!((g - t).abs() < 2e-5, "{g} vs {t}");
        }
    }

    #[test]
    fn rows_sampled_at_their_uneven_times_keep_them() {
        let t = scattered(2000);
        assert!(on_even_grid(&log(&t, &t)).is_none());
    }

    #[test]
    fn an_evenly_stamped_log_and_one_with_lost_rows_are_left_alone() {
        let even: Vec<f64> = (0..2000).map(|k| k as f64 * 1e-3).collect();
        assert!(on_even_grid(&log(&even, &even)).is_none());
        let kept: Vec<f64> = even
            .iter()
            .copied()
            .filter(|t| (t * 1e3) as u64 % 50 >= 5)
            .collect();
        assert!(on_even_grid(&log(&kept, &kept)).is_none());
    }
}
