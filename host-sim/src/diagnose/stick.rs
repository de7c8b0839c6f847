//! Where the logged piston rests and where it breaks away: the stick phase of Karnopp's
//! friction model (`plant_model::friction`) read from the position column.
//!
//! A stuck piston does not move at all, so a row rests when the position stayed, over it
//! and the `window` rows before it (the span of the velocity's central difference), within
//! what the transducer resolves:
//!
//! ```text
//!   max x − min x over rows k−W … k  ≤  max(STICK_NOISE_MULTIPLE·√2·σ_x, q, STICK_FLOOR_M)
//! ```
//!
//! with σ_x the position's white noise and q its quantisation step. The window looks back
//! only: a piston that broke away between rows k and k+1 still rests at row k, and row k+1,
//! whose sample has left the band, is the first it is seen moving. Over W rows a slow
//! stroke leaves the band (1 mm/s moves 10 µm in 10 ms) where a one-row difference on a
//! 1 µm transducer would not, and a piston turning round (speed through zero, not stuck)
//! moves ½·a·(W·Δt)² within the window, far beyond the band at any real acceleration.
//! σ_x is read from the median of the fourth differences ([`position_noise`]): a piston's
//! position is smooth on the scale of a few rows (the payload's mass filters it), so the
//! fourth difference of its motion is far below a transducer's noise while the second
//! difference of an oscillating payload is not; the median ignores the breakaway
//! transients.
//!
//! The window is at least as long as a piston creeping at [`CREEP_SPEED_M_S`] takes to
//! cross the band: on a noisy transducer (σ_x ≈ 1 µm makes the band ~6 µm) a steady stroke
//! at a few tenths of a millimetre a second stays within the band over the velocity's
//! short span, and a short window would read most of its rows as rests and every noise
//! excursion as a breakaway. A longer look-back does not delay a breakaway (the row that
//! leaves the band of the resting rows before it is seen moving at once); it only keeps a
//! rest shorter than the window from being seen.
//!
//! The test's cost on a noisy transducer: a piston creeping by less than the band reads as
//! resting, so a breakaway is seen when the motion has grown past it, and the force the
//! piston is seen to break away at is the force then. A sliding row read as resting
//! carries no residual in the cylinder relation as long as its force lies within the
//! breakaway level (sliding, it holds only the Coulomb force).

use std::ops::Range;

/// Multiple of the position difference's noise (√2·σ_x) a resting piston stays within:
/// four standard deviations, one noisy row in about 16 000 read as motion. [1]
pub const STICK_NOISE_MULTIPLE: f64 = 4.0;

/// Smallest position change read as motion, for a position logged without noise (a
/// simulator's): far below any transducer's resolution, far above the rounding of a
/// position written in full precision. [m]
pub const STICK_FLOOR_M: f64 = 1e-9;

/// The slowest motion a resting window must tell from a rest: the speed over which the
/// cylinder relation's Coulomb force has faded in (sliding, not stuck). [m/s]
pub const CREEP_SPEED_M_S: f64 = 1e-4;

/// Longest rest window, whatever the transducer's noise and the log's rate. [rows]
const MAX_WINDOW_ROWS: usize = 10_000;

/// Relative rounding of a count scaled to metres and printed in decimal (~1e-12), with a
/// wide margin: steps this close to a whole multiple of the smallest are counts. [1]
const COUNT_ROUNDING: f64 = 1e-6;

/// Median of |Δ⁴n| over the standard deviation of white noise n: √70 times the median of
/// a unit Gaussian's magnitude (0.6745). [1]
const MEDIAN_ABS_FOURTH_DIFFERENCE: f64 = 0.674_49 * 8.366_600_265_340_756;

/// A rest that ends in motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Breakaway {
    /// The last resting row; the piston is seen moving from the next one.
    pub row: usize,
    /// Direction of the motion that follows (+1 or −1).
    pub dir: f64,
}

/// The rows where the piston rests and its breakaways.
#[derive(Clone, Debug, PartialEq)]
pub struct Stick {
    /// Whether the piston rests at each row (the first window's rows are not judged).
    pub rests: Vec<bool>,
    /// Every rest that ends in motion, in time order.
    pub breakaways: Vec<Breakaway>,
    /// The position change per row read as motion. [m]
    pub threshold_m: f64,
}

impl Stick {
    /// The stick phases of the logged position `x` [m] sampled every `period_s` [s], a row
    /// resting when the position stayed within the band over the `window` rows before it,
    /// or over the rows a piston creeping at [`CREEP_SPEED_M_S`] takes to cross the band
    /// where that is longer.
    pub fn of(x: &[f64], window: usize, period_s: f64) -> Stick {
        let threshold_m = (STICK_NOISE_MULTIPLE * std::f64::consts::SQRT_2 * position_noise(x))
            .max(quantisation_step(x) * (1.0 + COUNT_ROUNDING))
            .max(STICK_FLOOR_M);
        let creep = (threshold_m / (CREEP_SPEED_M_S * period_s)).ceil();
        let window = if creep.is_finite() && creep > window as f64 {
            (creep as usize).min(MAX_WINDOW_ROWS)
        } else {
            window
        };
        let n = x.len();
        let rests: Vec<bool> = (0..n)
            .map(|k| {
                if k < window {
                    return false;
                }
                let (lo, hi) = x[k - window..=k]
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                        (l.min(*v), h.max(*v))
                    });
                hi - lo <= threshold_m
            })
            .collect();
        // A rest ends in a breakaway when the piston is still moving, and has left the
        // band, a window later (a noise spike leaves the band for one window and returns).
        let breakaways = runs(&rests)
            .into_iter()
            .filter_map(|run| {
                let row = run.end - 1;
                let last = row + window;
                if last >= n || rests[run.end..=last].iter().any(|r| *r) {
                    return None;
                }
                let moved = x[last] - x[row];
                (moved.abs() > threshold_m).then(|| Breakaway {
                    row,
                    dir: moved.signum(),
                })
            })
            .collect();
        Stick {
            rests,
            breakaways,
            threshold_m,
        }
    }
}

/// The maximal runs of `true` in `flags`.
fn runs(flags: &[bool]) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    let mut start = None;
    for (k, f) in flags.iter().chain(std::iter::once(&false)).enumerate() {
        match (*f, start) {
            (true, None) => start = Some(k),
            (false, Some(s)) => {
                out.push(s..k);
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// White-noise standard deviation of a smooth signal from the median magnitude of its
/// fourth differences (variance 70σ² for white noise). [unit of `x`]
pub fn position_noise(x: &[f64]) -> f64 {
    let mut d4: Vec<f64> = x
        .windows(5)
        .map(|w| (w[4] - 4.0 * w[3] + 6.0 * w[2] - 4.0 * w[1] + w[0]).abs())
        .collect();
    if d4.is_empty() {
        return 0.0;
    }
    let mid = d4.len() / 2;
    let (_, median, _) = d4.select_nth_unstable_by(mid, f64::total_cmp);
    *median / MEDIAN_ABS_FOURTH_DIFFERENCE
}

/// The quantisation step of `x`: its smallest nonzero change between rows when every change
/// is a whole multiple of it (a transducer's counts), else 0 (a signal logged as reals).
/// [unit of `x`]
pub fn quantisation_step(x: &[f64]) -> f64 {
    let steps: Vec<f64> = x
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 0.0)
        .collect();
    let Some(q) = steps.iter().copied().min_by(f64::total_cmp) else {
        return 0.0;
    };
    let whole = steps.iter().all(|d| {
        let m = d / q;
        (m - m.round()).abs() <= COUNT_ROUNDING * m.max(1.0)
    });
    if whole {
        q
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::test_noise::gaussian;

    /// The rest window of a 1 kHz log: twice the cylinder relation's five-row half-width.
    const REST_ROWS: usize = 10;

    #[test]
    fn the_fourth_difference_median_reads_white_noise_under_a_swinging_payload() {
        // A 40 Hz swing of 0.2 mm (a second difference of ~13 µm per row at 1 kHz) with
        // 1 µm of white noise: the noise is read within the median's sampling error.
        let x: Vec<f64> = gaussian(20_000, 7)
            .iter()
            .enumerate()
            .map(|(k, n)| {
                let t = k as f64 * 1e-3;
                2e-4 * (std::f64::consts::TAU * 40.0 * t).sin() + 1e-6 * n
            })
            .collect();
        let s = position_noise(&x);
        assert!((s / 1e-6 - 1.0).abs() < 0.05, "{s}");
    }

    #[test]
    fn a_piston_resting_then_breaking_away_is_read_row_by_row() {
        // At rest for 100 rows at 3 mm, then x − 3 mm = ½·a·(t − t_b)² from t_b = 99.6 ms
        // (between rows 99 and 100): row 99 is the last at rest, the motion is positive; the
        // first window's rows are not judged.
        let a = 0.1;
        let x: Vec<f64> = (0..200)
            .map(|k| {
                let t = k as f64 * 1e-3;
                3e-3 + if t > 0.0996 {
                    0.5 * a * (t - 0.0996).powi(2)
                } else {
                    0.0
                }
            })
            .collect();
        let s = Stick::of(&x, REST_ROWS, 1e-3);
        assert!(s.rests[..10].iter().all(|r| !*r) && s.rests[10..100].iter().all(|r| *r));
        assert!(s.rests[100..].iter().all(|r| !*r));
        assert_eq!(s.breakaways, vec![Breakaway { row: 99, dir: 1.0 }]);
    }

    #[test]
    fn a_transducers_counts_set_the_band_a_slow_stroke_moves_and_a_turn_is_no_stick() {
        // 1 µm counts. A stroke at 1 mm/s (the slow stroke's speed: a count per row); a swing of ±5 mm at
        // 1 Hz turning at 1.25 s and 1.75 s (speed through zero at 0.2 m/s²: ½·a·(10 ms)²
        // = 10 µm within the window); a rest with one count of toggling every seventh row.
        let q = 1e-6;
        let x: Vec<f64> = (0..3000)
            .map(|k| {
                let t = k as f64 * 1e-3;
                let exact = match k {
                    0..=999 => 1e-3 * t,
                    1000..=1999 => 1e-3 + 5e-3 * (std::f64::consts::TAU * (t - 1.0)).sin(),
                    _ if k % 7 == 0 => 1e-3 + 0.6 * q,
                    _ => 1e-3,
                };
                (exact / q).round() * q
            })
            .collect();
        let s = Stick::of(&x, REST_ROWS, 1e-3);
        // The swing's rounding reads as noise of a fraction of a count: the band is at
        // least a count and at most a few.
        assert!(
            s.threshold_m > 0.999 * q && s.threshold_m < 5.0 * q,
            "{}",
            s.threshold_m
        );
        assert!(s.rests[20..2000].iter().all(|r| !*r));
        // The rest is read once a piston creeping at 0.1 mm/s would have left the band of one
        // count: 1 µm in 10 ms, ten rows, and one more for the band's margin above a count.
        assert!(s.rests[2011..].iter().all(|r| *r));
        assert!(s.breakaways.is_empty(), "{:?}", s.breakaways);
    }

    #[test]
    fn a_slow_stroke_on_a_noisy_transducer_at_a_low_rate_is_no_string_of_sticks() {
        // 250 Hz, 1 µm counts over 1 µm of white noise (the band is about 4·√2 µm): 2 s at
        // rest, then a stroke at 0.3 mm/s, 1.2 µm a row, which stays within the band over
        // the velocity's few rows but not over the time a 0.1 mm/s creep takes to cross it.
        let (q, period, start) = (1e-6, 4e-3, 500);
        let x: Vec<f64> = gaussian(5500, 11)
            .iter()
            .enumerate()
            .map(|(k, n)| {
                let moved = 3e-4 * period * k.saturating_sub(start) as f64;
                ((2e-3 + moved + 1e-6 * n) / q).round() * q
            })
            .collect();
        let s = Stick::of(&x, 2, period);
        let band = s.threshold_m;
        assert!(band > 4e-6 && band < 8e-6, "{band}");
        // Sliding rows read as rests: none once the motion has crossed the band.
        let crossed = start + (band / (3e-4 * period)).ceil() as usize;
        let still = s.rests[crossed..].iter().filter(|r| **r).count();
        assert_eq!(still, 0, "{still} sliding rows read as rests");
        // One breakaway, where the motion leaves the resting rows' band.
        assert_eq!(s.breakaways.len(), 1, "{:?}", s.breakaways);
        let b = s.breakaways[0];
        assert!(
            b.dir > 0.0 && b.row + 1 >= start && b.row < crossed,
            "{b:?}"
        );
        // Rests between the first window and the start are read as rests.
        let rested = s.rests[100..start].iter().filter(|r| **r).count();
        assert!(rested >= 390, "{rested} of 400 resting rows");
    }
}
