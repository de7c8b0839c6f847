//! The encoder's counts in the angle-locked lines: what rounding the shaft angle to whole
//! counts leaves in the angle's line at each order of a window.
//!
//! A logged encoder angle (or one counted back from a count-difference speed) is the
//! shaft's rounded to a count q = 2π/N. Its error is a sawtooth of period q in the angle;
//! read at the log's rate it folds onto the low orders. At a steady speed it folds onto a
//! few orders between the whole ones, which a window's lock-in averages out. Where the
//! speed ripples (a current-sensor offset's torque at the electrical order, say), the
//! sawtooth's phase from row to row is modulated and its folds spread into a comb of orders
//! a multiple of the ripple's order apart, which lands on whole orders. Weighed by the
//! shaft's J·(k·ω̄)² in the torque balance ([`super::lines`]), microradians there read as
//! milli-newton-metres of unexplained torque: a line no effect made.
//!
//! The comb is set by the motion, and the log holds the motion to within a count: the
//! window's angle smoothed (the lock-in's cubic in time and the angle's own first
//! [`SMOOTH_ORDERS`] orders, the lines that carry a speed ripple, by least squares) and
//! rounded onto the lattice again gives rounding errors whose lines the lock-in reads as it
//! reads the signals'. Where within its count the shaft was is not logged: the smoothed
//! angle is shifted by [`SHIFTS`] evenly spaced fractions of a count at the window's start,
//! and by [`DRIFTS`] of a count more at its end (the mean speed is known to a count over
//! the window, and the folds land on whole orders or between them by less). The RMS of the
//! lines over the shifts and drifts is the line the counts alone leave at each order:
//! noise for the torque balance, as the neighbouring orders' lines are.

use super::lock_in::{regressors, trend_and_lines, window_clock, TREND_TERMS};
use rustfft::num_complex::Complex64;
use std::ops::Range;

/// The angle's own orders kept in its smoothed motion (1 to this): the electrical order and
/// its harmonics of a four-pole-pair motor, the pump's slowest.
pub const SMOOTH_ORDERS: u32 = 8;

/// Fractions of a count the smoothed angle is shifted by at the window's start, evenly
/// spaced over one count.
pub const SHIFTS: usize = 8;

/// The further shifts at the window's end, growing linearly in time from none at its start:
/// the mean speed's uncertainty of about a count over the window. [count]
pub const DRIFTS: [f64; 3] = [-0.5, 0.0, 0.5];

/// The rounding errors to `count` (one encoder count, [rad]) of the angle `theta`
/// (unwrapped) smoothed over `rows` at times `t`, the first row's error first: one series
/// per shift and drift, for the window's lock-in to read beside its signals (it fits each
/// signal on its own). `None` where the window is too short for the smoothing's
/// fit. [rad]
pub fn rounding_errors(
    t: &[f64],
    theta: &[f64],
    rows: Range<usize>,
    count: f64,
) -> Option<Vec<Vec<f64>>> {
    let smooth = smoothed_angle(t, theta, rows.clone())?;
    let (t0, span) = window_clock(t, rows.clone());
    Some(
        (0..SHIFTS)
            .flat_map(|m| DRIFTS.map(|drift| (m as f64 / SHIFTS as f64, drift)))
            .map(|(start, drift)| {
                rows.clone()
                    .zip(&smooth)
                    .map(|(k, a)| {
                        let shifted = a / count + start + drift * (t[k] - t0) / span;
                        (shifted.floor() - shifted) * count
                    })
                    .collect()
            })
            .collect(),
    )
}

/// Per order, the RMS over the shifts and drifts of the lines of [`rounding_errors`]'
/// series (`lines[series][order]`): the line the counts alone leave there. [rad]
pub fn rms_over_shifts(lines: &[Vec<Complex64>]) -> Vec<f64> {
    let orders = lines.first().map_or(0, Vec::len);
    (0..orders)
        .map(|m| {
            let power: f64 = lines.iter().map(|shifted| shifted[m].norm_sqr()).sum();
            (power / lines.len() as f64).sqrt()
        })
        .collect()
}

/// `theta` over `rows` smoothed: its least-squares cubic in time and lines at orders 1 to
/// [`SMOOTH_ORDERS`], evaluated at each row. [rad]
fn smoothed_angle(t: &[f64], theta: &[f64], rows: Range<usize>) -> Option<Vec<f64>> {
    let orders: Vec<u32> = (1..=SMOOTH_ORDERS).collect();
    let c = trend_and_lines(t, theta, rows.clone(), &orders, &[(theta, 0)])?;
    let (t0, span) = window_clock(t, rows.clone());
    let mut phi = vec![0.0; TREND_TERMS + 2 * orders.len()];
    Some(
        rows.map(|k| {
            regressors(t[k], t0, span, theta[k], &orders, &mut phi);
            phi.iter().enumerate().map(|(i, p)| p * c[(i, 0)]).sum()
        })
        .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::lock_in::lock_in;
    use std::f64::consts::PI;

    /// The module's method as the window's lines use it, on the rounding's series alone:
    /// the line the counts leave at each of `orders`. [rad]
    fn count_line_rms(
        t: &[f64],
        theta: &[f64],
        rows: Range<usize>,
        orders: &[u32],
        count: f64,
    ) -> Option<Vec<f64>> {
        let errors = rounding_errors(t, theta, rows.clone(), count)?;
        let signals: Vec<(&[f64], usize)> =
            errors.iter().map(|e| (e.as_slice(), rows.start)).collect();
        Some(rms_over_shifts(&lock_in(t, theta, rows, orders, &signals)?))
    }

    /// A shaft at `w` rad/s with a speed ripple of `ripple` rad/s at order 4, read by a
    /// `counts`-count encoder every `dt` s: times, the counted angle and the true one. [rad]
    fn counted_shaft(w: f64, ripple: f64, counts: f64, dt: f64, n: usize) -> [Vec<f64>; 3] {
        let q = 2.0 * PI / counts;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        // θ = w·t + a·sin(4·w·t): the order-4 angle line a speed ripple of 4·w·a makes.
        let a = ripple / (4.0 * w);
        let truth: Vec<f64> = t
            .iter()
            .map(|&t| w * t + 0.37 + a * (4.0 * w * t).sin())
            .collect();
        let counted = truth.iter().map(|th| (th / q).floor() * q).collect();
        [t, counted, truth]
    }

    /// The lines the rounding leaves, read from the true angle (which the method does not
    /// see): the lock-in of counted minus true. [rad]
    fn true_rounding_lines(t: &[f64], counted: &[f64], truth: &[f64], orders: &[u32]) -> Vec<f64> {
        let err: Vec<f64> = counted.iter().zip(truth).map(|(c, a)| c - a).collect();
        let z = lock_in(t, counted, 0..t.len(), orders, &[(&err, 0)]).expect("lines");
        z[0].iter().map(|z| z.norm()).collect()
    }

    /// Mean of `lines` at the comb's orders (10, 14, …, 26 of 10 to 26) over their mean at
    /// the others.
    fn comb_contrast(lines: &[f64]) -> f64 {
        let (mut on, mut off) = (Vec::new(), Vec::new());
        for (i, l) in lines.iter().enumerate() {
            if i % 4 == 0 {
                on.push(*l)
            } else {
                off.push(*l)
            }
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        mean(&on) / mean(&off)
    }

    #[test]
    fn a_rippling_speed_folds_the_rounding_into_a_comb_the_method_finds() {
        // 10 000 counts read at 500 Hz near 36 rad/s with a 2.35 rad/s speed ripple at
        // order 4. The rounding advances about 114.66 counts a row; where that advance is
        // within a count over the window of a fraction with a small denominator, the folds
        // land on a comb of whole orders four apart (10, 14, …, 26 at 36.020243 rad/s), and
        // 4e-5 rad/s away they do not. The true lines (read from the true angle, which the
        // method does not see) show it; the method, from the counted angle alone, finds the
        // comb where it is, at its size to within a factor of two, and not where it is not.
        let orders: Vec<u32> = (10..=26).collect();
        let q = 2.0 * PI / 10_000.0;
        for (w, comb) in [(36.020243, true), (36.0202, false), (36.015, false)] {
            let [t, counted, truth] = counted_shaft(w, 2.35, 10_000.0, 2e-3, 7_000);
            let true_lines = true_rounding_lines(&t, &counted, &truth, &orders);
            let found = count_line_rms(&t, &counted, 0..t.len(), &orders, q).expect("lines");
            let (c_true, c_found) = (comb_contrast(&true_lines), comb_contrast(&found));
            if comb {
                assert!(c_true > 3.0 && c_found > 3.0, "{w}: {c_true} {c_found}");
                for i in (0..orders.len()).step_by(4) {
                    let ratio = found[i] / true_lines[i];
                    assert!(
                        (0.5..2.0).contains(&ratio),
                        "{w}, order {}: {ratio}",
                        orders[i]
                    );
                }
            } else {
                assert!(c_true < 2.0 && c_found < 2.0, "{w}: {c_true} {c_found}");
            }
            // Everywhere, the lines are of the rounding's white level, q/√12 a row spread
            // over the window's n rows (2/n of its power per component): within a factor
            // of three of it on average.
            let white = (2.0 * 2.0 / t.len() as f64 * q * q / 12.0).sqrt();
            let rms = (found.iter().map(|f| f * f).sum::<f64>() / found.len() as f64).sqrt();
            assert!(
                (white / 3.0..3.0 * white).contains(&rms),
                "{w}: {rms:e} vs {white:e}"
            );
        }
    }
}
