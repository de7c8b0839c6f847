//! The shaft angle of a log without `theta_m_rad`, integrated from its speed column, and
//! the encoder count an angle moves by ([`angle_count`]).
//!
//! A bench's speed column is one of two kinds, and the angles they integrate to differ by
//! half a row:
//!
//! - a count difference over the row's interval, ω_k = (θ_k − θ_{k−1})/(t_k − t_{k−1}) with θ
//!   the encoder's counted angle (what a logger computes from the counter it reads at each
//!   row): the mean speed over the interval that ends at t_k, whose running sum
//!   θ_k = θ_{k−1} + ω_k·(t_k − t_{k−1}) is the counted angle itself;
//! - a sample of a continuous estimate (an observer's, a filter's, or a difference taken at
//!   the control rate, far faster than the log's): the speed at t_k, which integrates by
//!   trapezoids.
//!
//! Taken for the other kind, the angle is half a row early or late, and whatever is read from
//! it follows: the pump's flow D_p·ω shifts by Δt/2, a flow error D_p·α·Δt/2 that a stiff
//! hydraulic node turns into a pressure residual many times its noise on every ramp. The first
//! kind shows itself ([`count_step`]): its increments ω_k·Δt_k are whole numbers of one
//! encoder count 2π/N, and they jitter by whole counts about the smooth motion (the counter's
//! rounding, whose second differences have an rms of about 0.7 of a count, a few at most,
//! where those of a lattice of printed digits are hundreds of its steps), and a whole number
//! of them makes a revolution. A continuous
//! estimate's increments lie on no lattice, or, sampled from a motion as smooth as a ramp,
//! on one without that jitter. Only a log sampled at even intervals is read as counted: where
//! rows are missing, a logger's difference over its own interval no longer spans the row's.

use std::f64::consts::PI;

/// Where a log's shaft angle comes from, and so how far the phases of the lines read
/// against it can be trusted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AngleSource {
    /// Logged (`theta_m_rad`): the lines' phases are against the true angle.
    Logged,
    /// Counted back from a count-difference speed: exact but for its unknown start, so the
    /// lines' phases combine across windows, but their absolute phase is unknown.
    Counted,
    /// Integrated from a sampled speed by trapezoids: it drifts, and only the lines'
    /// magnitudes are read.
    Integrated,
}

impl AngleSource {
    /// Whether the lines' phases combine across windows (the angle is logged or counted).
    pub fn combines_phases(self) -> bool {
        matches!(self, AngleSource::Logged | AngleSource::Counted)
    }

    /// Whether the lines' phases are against the true angle.
    pub fn is_logged(self) -> bool {
        self == AngleSource::Logged
    }
}

/// Fewest moving rows from which the counts' lattice is read.
const MIN_MOVING_ROWS: usize = 50;

/// Largest distance of an increment from the lattice, in counts, that still counts as on it
/// (the printed speed's rounding is far less).
const LATTICE_TOLERANCE: f64 = 0.1;

/// Share of the moving rows that must lie on the lattice: a continuous estimate puts about
/// a fifth there by chance.
const LATTICE_SHARE: f64 = 0.98;

/// Least rms of the increments' second differences, in counts, of a counter's rounding
/// (about 0.7 where the rounding is uniform, more where single counts come and go at a
/// crawl); a smoothly sampled speed's are a small fraction of its lattice's step. [1]
const MIN_ROUNDING_RMS: f64 = 0.2;

/// Largest rms of the increments' second differences, in counts, of a counter's rounding:
/// a shaft at rest on a count's edge (+1, −1, +1, …) gives 4. The lattice of the printed
/// digits or of the floating-point format, on which every logged value lies, puts the
/// motion's own changes at hundreds of its steps and more. [1]
const MAX_ROUNDING_RMS: f64 = 8.0;

/// Largest distance of 2π over the step from a whole number of counts per revolution. [1]
const COUNTS_PER_REV_TOLERANCE: f64 = 0.05;

/// Largest increment, in counts, the step is first refined on ([`on_lattice`]): its count
/// is rounded right by a step up to 1/16 off. [1]
const FEW_COUNTS: f64 = 8.0;

/// Most step sizes tried, an octave apart: from a double's rounding (1e-16 rad) to a
/// count of a coarse encoder (0.1 rad) is 50 octaves.
const MAX_TRIES: usize = 64;

/// The shaft angle the logged `speed` integrates to from 0 at the times `t`, by the rule its
/// kind asks for (module docs), which kind it was, and for a counted angle its count. Only
/// an `evenly_sampled` log (the facts' test) is read as counted. [rad]
pub fn integrated_angle(
    t: &[f64],
    speed: &[f64],
    evenly_sampled: bool,
) -> (Vec<f64>, AngleSource, Option<f64>) {
    let n = t.len().min(speed.len());
    let increments: Vec<f64> = (1..n).map(|k| speed[k] * (t[k] - t[k - 1])).collect();
    let count = if evenly_sampled {
        count_step(&increments)
    } else {
        None
    };
    let counted = count.is_some();
    let mut theta = Vec::with_capacity(n);
    let mut acc = 0.0;
    for k in 0..n {
        if k > 0 {
            acc += if counted {
                increments[k - 1]
            } else {
                0.5 * (speed[k] + speed[k - 1]) * (t[k] - t[k - 1])
            };
        }
        theta.push(acc);
    }
    let source = if counted {
        AngleSource::Counted
    } else {
        AngleSource::Integrated
    };
    (theta, source, count)
}

/// The angle of one encoder count when the logged angle `theta` (unwrapped) moves by whole
/// numbers of it, else `None`: the lattice [`count_step`] finds in its increments (a speed
/// column's count comes with [`integrated_angle`]). [rad]
pub fn angle_count(theta: &[f64]) -> Option<f64> {
    let increments: Vec<f64> = theta.windows(2).map(|w| w[1] - w[0]).collect();
    count_step(&increments)
}

/// The angle of one encoder count when every increment ω_k·Δt_k of the log is a whole
/// number of it (the speed is a count difference over the row), else `None`. [rad]
///
/// One count is the smallest step the increments take: the smallest increment, or the
/// smallest change between neighbours (at speed, where no increment is a single count).
/// Where the logged angle or speed was rounded (a single-precision angle's last bit), equal
/// counts differ by that rounding, a cluster of changes far below one count: the sizes are
/// then tried an octave apart, upwards, and the first on whose lattice the increments lie
/// is the count.
fn count_step(increments: &[f64]) -> Option<f64> {
    let moving: Vec<f64> = increments
        .iter()
        .copied()
        .filter(|d| d.is_finite() && *d != 0.0)
        .collect();
    if moving.len() < MIN_MOVING_ROWS {
        return None;
    }
    let mut steps: Vec<f64> = moving
        .iter()
        .map(|d| d.abs())
        .chain(moving.windows(2).map(|w| (w[1] - w[0]).abs()))
        .filter(|s| *s > 0.0)
        .collect();
    steps.sort_by(f64::total_cmp);
    // The sizes tried, each at least twice the last: one per octave through the rounding's
    // cluster, then the count above it.
    let mut last = 0.0;
    steps
        .into_iter()
        .filter(|s| {
            let next = *s >= 2.0 * last;
            if next {
                last = *s;
            }
            next
        })
        .take(MAX_TRIES)
        .find_map(|step| on_lattice(increments, &moving, step))
}

/// The step refined by least squares on the counts `step` assigns to the `moving`
/// increments, when they lie on its lattice with the counter's jitter (module docs).
///
/// The refinement is taken first on the increments of at most [`FEW_COUNTS`], whose counts
/// a step some percent off still rounds right, then on all: a candidate read from a
/// single-precision angle's rounding (a multi-turn angle of tens of radians is rounded to a
/// hundredth of a fine encoder's count) is off by that much, and rounded with it an
/// increment of sixty counts would be given sixty-one.
fn on_lattice(increments: &[f64], moving: &[f64], step: f64) -> Option<f64> {
    let counts = |step: f64| moving.iter().map(move |d| (d / step).round());
    let refined = |step: f64, most: f64| {
        let (num, den) = counts(step)
            .zip(moving)
            .filter(|(c, _)| c.abs() <= most)
            .fold((0.0, 0.0), |(num, den), (c, d)| (num + c * d, den + c * c));
        if den > 0.0 {
            num / den
        } else {
            step
        }
    };
    let step = refined(refined(step, FEW_COUNTS), f64::INFINITY);
    // A moving increment is at least one count.
    let on = counts(step)
        .zip(moving)
        .filter(|(c, d)| *c != 0.0 && (*d / step - c).abs() <= LATTICE_TOLERANCE)
        .count();
    if (on as f64) < LATTICE_SHARE * moving.len() as f64 {
        return None;
    }
    // The counter's rounding: second differences where the shaft moves.
    let (sum, n) = increments
        .windows(3)
        .filter(|w| w.iter().any(|d| *d != 0.0))
        .fold((0.0, 0usize), |(sum, n), w| {
            let dd = (w[2] - 2.0 * w[1] + w[0]) / step;
            (sum + dd * dd, n + 1)
        });
    let rms = if n > 0 { (sum / n as f64).sqrt() } else { 0.0 };
    // A whole number of counts per revolution: a speed printed to a few decimals lies on a
    // lattice of 10⁻ᵈ·Δt, which divides a revolution by no whole number.
    let per_rev = 2.0 * PI / step;
    let whole = (per_rev - per_rev.round()).abs() <= COUNTS_PER_REV_TOLERANCE;
    ((MIN_ROUNDING_RMS..=MAX_ROUNDING_RMS).contains(&rms) && whole).then_some(step)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::facts::{evenly_sampled, median_period};

    /// A shaft accelerating from rest and oscillating, θ(t) = 3·t² + 0.2·sin(40·t). [rad]
    fn motion(t: f64) -> f64 {
        3.0 * t * t + 0.2 * (40.0 * t).sin()
    }

    /// The counted angle of `motion` on a `q`-rad lattice, logged wrapped to [0, 2π) in
    /// single precision, at the times `t`. [rad]
    fn logged_wrapped(t: &[f64], q: f64) -> Vec<f64> {
        t.iter()
            .map(|&t| ((motion(t) / q).floor() * q).rem_euclid(2.0 * PI) as f32 as f64)
            .collect()
    }

    #[test]
    fn the_speed_integrates_to_the_angle_turned() {
        // A ramp 0 → 20 rad/s over 1 s turns ½·20·1 = 10 rad (trapezoids are exact on a ramp).
        let t: Vec<f64> = (0..1001).map(|k| k as f64 * 1e-3).collect();
        let w: Vec<f64> = t.iter().map(|&t| 20.0 * t).collect();
        let (th, ..) = integrated_angle(&t, &w, true);
        assert!((th[1000] - 10.0).abs() < 1e-9, "{}", th[1000]);
    }

    #[test]
    fn a_count_difference_integrates_back_to_the_counted_angle() {
        // An 8192-count encoder read every millisecond, the speed printed to 5 decimals as a
        // logger writes it: the angle is the counts' own, not half a row late.
        let counts_per_rev = 8192.0;
        let q = 2.0 * PI / counts_per_rev;
        let t: Vec<f64> = (0..4000).map(|k| k as f64 * 1e-3).collect();
        let counts: Vec<f64> = t.iter().map(|&t| (motion(t) / q).floor()).collect();
        let w: Vec<f64> = (0..t.len())
            .map(|k| {
                let c = if k == 0 {
                    0.0
                } else {
                    counts[k] - counts[k - 1]
                };
                (c * q / 1e-3 * 1e5).round() / 1e5
            })
            .collect();
        let increments: Vec<f64> = (1..t.len()).map(|k| w[k] * 1e-3).collect();
        let step = count_step(&increments).expect("a lattice");
        assert!((step / q - 1.0).abs() < 1e-4, "{step} against {q}");
        let (th, ..) = integrated_angle(&t, &w, true);
        for k in (0..t.len()).step_by(97) {
            let counted = (counts[k] - counts[0]) * q;
            assert!(
                (th[k] - counted).abs() < 1e-5,
                "row {k}: {} vs {counted}",
                th[k]
            );
        }
    }

    #[test]
    fn a_logged_encoder_angle_gives_its_count_and_a_smooth_one_none() {
        // A 16 384-count encoder's angle logged wrapped to [0, 2π) in single precision
        // every millisecond, unwrapped as the facts unwrap it, and the motion itself: one
        // count, 2π/16 384, and no lattice.
        let q = 2.0 * PI / 16_384.0;
        let t: Vec<f64> = (0..4000).map(|k| k as f64 * 1e-3).collect();
        let counted = crate::diagnose::facts::unwrap_angle(&logged_wrapped(&t, q), &t, &[]);
        let step = angle_count(&counted).expect("a lattice");
        assert!((step / q - 1.0).abs() < 1e-4, "{step} against {q}");
        // Logged unwrapped in single precision, the angle reaches 48 rad, where its rounding
        // is 1 % of a count: still the count.
        let multi_turn: Vec<f64> = t
            .iter()
            .map(|&t| ((motion(t) / q).floor() * q) as f32 as f64)
            .collect();
        let step = angle_count(&multi_turn).expect("a lattice");
        assert!((step / q - 1.0).abs() < 1e-4, "{step} against {q}");
        let smooth: Vec<f64> = t.iter().map(|&t| motion(t)).collect();
        assert_eq!(angle_count(&smooth), None);
    }

    #[test]
    fn a_continuous_estimate_is_not_taken_for_counts() {
        // The speed sampled from the motion itself: no lattice, trapezoids, and the angle
        // within the trapezoids' error of the motion (h²/12·max|θ'''| per unit time).
        let t: Vec<f64> = (0..4000).map(|k| k as f64 * 1e-3).collect();
        let w: Vec<f64> = t
            .iter()
            .map(|&t| 6.0 * t + 8.0 * (40.0 * t).cos())
            .collect();
        let increments: Vec<f64> = (1..t.len()).map(|k| w[k] * 1e-3).collect();
        assert_eq!(count_step(&increments), None);
        let (th, ..) = integrated_angle(&t, &w, true);
        let bound = 4.0 * 1e-6 / 12.0 * 0.2 * 40.0f64.powi(3);
        for k in (0..t.len()).step_by(97) {
            let truth = motion(t[k]) - motion(0.0);
            assert!(
                (th[k] - truth).abs() < bound,
                "row {k}: {} vs {truth}",
                th[k]
            );
        }
    }

    #[test]
    fn counts_read_from_a_single_precision_angle_are_still_counts() {
        // A logger differencing an angle it holds in single precision: equal counts differ
        // by the angle's last bit (5e-7 rad near 2π), far below one count of 10 000 per
        // revolution, and the step is the count above that cluster.
        let q = 2.0 * PI / 10_000.0;
        let t: Vec<f64> = (0..4000).map(|k| k as f64 * 1e-3).collect();
        let theta = logged_wrapped(&t, q);
        let increments: Vec<f64> = (1..t.len())
            .map(|k| {
                let d = theta[k] - theta[k - 1];
                d - 2.0 * PI * (d / (2.0 * PI)).round()
            })
            .collect();
        let step = count_step(&increments).expect("a lattice");
        assert!((step / q - 1.0).abs() < 1e-3, "{step} against {q}");
    }

    #[test]
    fn a_speed_printed_to_two_decimals_is_not_taken_for_counts() {
        // The speed of the motion sampled and printed to 0.01 rad/s: its increments lie on a
        // lattice of 1e-5 rad with a rounding jitter as a counter's, but 2π/1e-5 is no whole
        // number of counts.
        let t: Vec<f64> = (0..4000).map(|k| k as f64 * 1e-3).collect();
        let w: Vec<f64> = t
            .iter()
            .map(|&t| ((6.0 * t + 8.0 * (40.0 * t).cos()) * 100.0).round() / 100.0)
            .collect();
        let increments: Vec<f64> = (1..t.len()).map(|k| w[k] * 1e-3).collect();
        assert_eq!(count_step(&increments), None);
    }

    #[test]
    fn a_log_with_rows_missing_is_integrated_by_trapezoids() {
        // Every tenth row of a counted log dropped: the speed still spans one logger
        // interval, not the row's two, so the rule falls back to trapezoids.
        let q = 2.0 * PI / 8192.0;
        let all: Vec<f64> = (0..4000).map(|k| k as f64 * 1e-3).collect();
        let counts: Vec<f64> = all.iter().map(|&t| (motion(t) / q).floor()).collect();
        let keep: Vec<usize> = (0..all.len()).filter(|k| k % 10 != 5).collect();
        let t: Vec<f64> = keep.iter().map(|&k| all[k]).collect();
        let w: Vec<f64> = keep
            .iter()
            .map(|&k| {
                if k == 0 {
                    0.0
                } else {
                    (counts[k] - counts[k - 1]) * q / 1e-3
                }
            })
            .collect();
        let even = |t: &[f64]| evenly_sampled(t, median_period(t));
        let (_, source, _) = integrated_angle(&t, &w, even(&t));
        assert_eq!(source, AngleSource::Integrated);
        let mut w = vec![0.0];
        w.extend((1..all.len()).map(|k| (counts[k] - counts[k - 1]) * q / 1e-3));
        let (_, source, _) = integrated_angle(&all, &w, even(&all));
        assert_eq!(source, AngleSource::Counted);
    }

    #[test]
    fn a_sampled_ramp_is_not_taken_for_counts() {
        // A speed ramp sampled without rounding: its increments are multiples of α·Δt², a
        // lattice, but with no counter's jitter on it.
        let t: Vec<f64> = (0..1001).map(|k| k as f64 * 1e-3).collect();
        let w: Vec<f64> = t.iter().map(|&t| 20.0 * t).collect();
        let increments: Vec<f64> = (1..t.len()).map(|k| w[k] * 1e-3).collect();
        assert_eq!(count_step(&increments), None);
    }

    #[test]
    fn a_shaft_that_barely_moves_shows_no_lattice() {
        let increments = [0.0, 1e-3, 0.0, -1e-3, 0.0];
        assert_eq!(count_step(&increments), None);
    }
}
