//! Whether a bench log can be replayed on a rig in bounded time and to some purpose, checked
//! before `eha diagnose` starts: the replays integrate the rig at the PWM rate across the
//! log's whole time span, so their cost follows the span, not the rows; they drive the
//! model's piston from the logged position; and they resolve the pump's and motor's
//! periodic effects (tens of cycles per revolution) only from densely sampled data.
//!
//! - the span is at most [`MAX_SPAN_S`], the contract's longest typical log;
//! - the rows are at most [`MAX_REPLAYED_ROWS`], for bounded memory;
//! - the median sampling interval is at most [`MAX_MEDIAN_INTERVAL_S`];
//! - no interval exceeds [`GAP_FACTOR`] medians and [`MIN_GAP_S`] (a gap in the record:
//!   the replay would run blind through it and meet the log again somewhere else);
//! - the piston position, when logged, stays within the rig's stroke;
//! - the measured pressure, speed and q current vary: a signal constant over the whole log
//!   is a stuck or disconnected sensor (or a drive at rest), and the diagnosis's scores are
//!   fractions of each signal's variation.

use super::{BenchLog, BenchLogError, Problem, Signal};
use plant_model::Rig;
use std::path::Path;

/// Longest time span replayed: the contract's largest typical bench log. [s]
pub const MAX_SPAN_S: f64 = 600.0;

/// Most rows replayed: the diagnosis keeps every row's measured, simulated and residual
/// traces (some hundreds of bytes a row; `docs/memory.md` has the measured figures), so
/// that it stays under 1 GiB of memory; the whole [`MAX_SPAN_S`] at 3.3 kHz, or 200 s at
/// 10 kHz.
pub const MAX_REPLAYED_ROWS: usize = 2_000_000;

/// Longest median sampling interval (100 Hz): below it the pulsation orders of a pump
/// turning a few revolutions per second alias. [s]
pub const MAX_MEDIAN_INTERVAL_S: f64 = 0.01;

/// An interval longer than this many median intervals (and [`MIN_GAP_S`]) is a gap.
pub const GAP_FACTOR: f64 = 20.0;

/// Shortest interval counted as a gap, whatever the sampling rate. [s]
pub const MIN_GAP_S: f64 = 0.1;

/// How far past the rig's stroke, as a fraction of the half stroke, a logged position may
/// read: a piston pressed into an end stop compresses it (the rig's stops are springs), and
/// a position sensor's zero is set to a fraction of a millimetre. A log in millimetres, or
/// of another cylinder, reads far beyond. [1]
pub const STROKE_MARGIN: f64 = 0.05;

/// Checks `log` (read from `file`, named in errors) against the replays' needs on `rig`.
pub fn check(log: &BenchLog, rig: &Rig, file: &Path) -> Result<(), BenchLogError> {
    let at = |row: usize, column: &str, why: String| BenchLogError::Replay {
        file: file.to_path_buf(),
        row,
        t_s: log.t_s.get(row).copied().unwrap_or(f64::NAN),
        column: column.to_string(),
        why,
    };
    let n = log.len();
    if n < 2 {
        return Err(BenchLogError::Content {
            file: file.to_path_buf(),
            line: 0,
            column: Signal::Time.name().into(),
            problem: Problem::TooFewRows { rows: n },
        });
    }
    let span = log.t_s[n - 1] - log.t_s[0];
    if span > MAX_SPAN_S {
        return Err(at(
            n - 1,
            "t_s",
            format!(
                "the log spans {span:.1} s; the diagnosis replays at most {MAX_SPAN_S} s (its \
                 time grows with the span): cut the log to the part to explain"
            ),
        ));
    }
    if n > MAX_REPLAYED_ROWS {
        return Err(at(
            MAX_REPLAYED_ROWS,
            "t_s",
            format!(
                "the log has {n} rows; the diagnosis replays at most {MAX_REPLAYED_ROWS} (it \
                 keeps every row's traces, within 1 GiB of memory): cut the log to the part \
                 to explain, or log at a lower rate ({:.0} Hz holds the {MAX_SPAN_S} s)",
                MAX_REPLAYED_ROWS as f64 / MAX_SPAN_S
            ),
        ));
    }
    let mut dt: Vec<f64> = log.t_s.windows(2).map(|w| w[1] - w[0]).collect();
    let (_, median, _) = dt.select_nth_unstable_by(n / 2 - 1, f64::total_cmp);
    let median = *median;
    if median > MAX_MEDIAN_INTERVAL_S {
        return Err(at(
            0,
            "t_s",
            format!(
                "the log is sampled every {:.4} s ({:.1} Hz, the median interval); the \
                 diagnosis needs at least {:.0} Hz to resolve the pump's and motor's periodic \
                 effects (bench logs are typically 1 to 10 kHz)",
                median,
                1.0 / median,
                1.0 / MAX_MEDIAN_INTERVAL_S
            ),
        ));
    }
    let gap = (GAP_FACTOR * median).max(MIN_GAP_S);
    if let Some(k) = log.t_s.windows(2).position(|w| w[1] - w[0] > gap) {
        return Err(at(
            k + 1,
            "t_s",
            format!(
                "a gap of {:.3} s after t = {} s, where the log is sampled every {:.4} s: the \
                 replay cannot follow the drive through missing data; split the log at the gap",
                log.t_s[k + 1] - log.t_s[k],
                log.t_s[k],
                median
            ),
        ));
    }
    for signal in [Signal::Pressure, Signal::Speed, Signal::Iq] {
        let c = log.column(signal).unwrap_or_default();
        if let Some(&first) = c.first().filter(|v| c.iter().all(|x| x == *v)) {
            return Err(at(
                0,
                signal.name(),
                format!(
                    "holds {first} over the whole log: a stuck or disconnected sensor, or a \
                     drive at rest; the diagnosis compares the model with the signals' variation"
                ),
            ));
        }
    }
    if let Some(x) = &log.x_m {
        let h = rig.cylinder.half_stroke_m;
        let most = h * (1.0 + STROKE_MARGIN);
        if let Some(k) = x.iter().position(|v| v.abs() > most) {
            return Err(at(
                k,
                "x_m",
                format!(
                    "the piston position {} m lies outside the rig's stroke of ±{h} m \
                     (cylinder.half_stroke_m) by more than an end stop's give ({:.0} %): is \
                     the log of this rig (--rig), its position in metres from mid-stroke?",
                    x[k],
                    100.0 * STROKE_MARGIN
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A log of `n` rows at 10 kHz, every signal varying.
    fn log_of(n: usize) -> BenchLog {
        let ramp: Vec<f64> = (0..n).map(|k| (k % 1000) as f64).collect();
        BenchLog {
            t_s: (0..n).map(|k| k as f64 * 1e-4).collect(),
            p_ref_pa: vec![5e6; n],
            p_pa: ramp.iter().map(|r| 5e6 + r).collect(),
            speed_rad_s: ramp.iter().map(|r| r * 1e-3).collect(),
            iq_a: ramp.iter().map(|r| r * 1e-3).collect(),
            id_a: vec![0.0; n],
            ..BenchLog::default()
        }
    }

    #[test]
    fn a_piston_pressed_into_its_end_stop_is_replayed_and_one_in_millimetres_is_not() {
        let rig = Rig::nominal();
        let h = rig.cylinder.half_stroke_m;
        let file = Path::new("stroke.csv");
        let mut log = log_of(2000);
        // Against the stop at 1e5 N, the nominal stop's 2e8 N/m gives 0.5 mm.
        let pressed = h + 1e5 / rig.cylinder.end_stop_stiffness_n_per_m;
        log.x_m = Some(
            (0..2000)
                .map(|k| if k < 1000 { 0.0 } else { pressed })
                .collect(),
        );
        check(&log, &rig, file).unwrap();
        log.x_m = Some(vec![1e3 * h * 0.5; 2000]);
        let text = check(&log, &rig, file).unwrap_err().to_string();
        assert!(text.contains("x_m") && text.contains("stroke"), "{text}");
    }

    #[test]
    fn a_log_beyond_the_replayed_rows_is_refused_naming_the_bound() {
        let rig = Rig::nominal();
        let file = Path::new("long.csv");
        // 200 s at 10 kHz is within the span; one row more than the bound is refused.
        let e = check(&log_of(MAX_REPLAYED_ROWS + 1), &rig, file).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("2000001 rows") && text.contains("at most 2000000"),
            "{text}"
        );
        check(&log_of(MAX_REPLAYED_ROWS), &rig, file).unwrap();
    }
}
