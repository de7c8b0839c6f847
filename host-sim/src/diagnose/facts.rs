//! Facts about a bench log, computed once before any model runs: its sampling, the shaft
//! angle (logged, else integrated from the logged speed), the low-side pressure (logged,
//! else estimated where the q current shows it pressurised, else the rig's fill
//! pressure), whether the piston moves, each signal's noise level, the identification and
//! validation segments, and the stretches of steady rotation where angle-locked lines can
//! be measured.
//!
//! Every later stage reads these instead of asking the log again.

use crate::bench_log::{BenchLog, Signal};
pub use crate::diagnose::low_side::LowSide;
use crate::diagnose::speed_angle::{angle_count, integrated_angle, AngleSource};
use crate::diagnose::steady::{
    balanced_boundary, lesser_side, slow_line_speed, slow_windows, steady_windows, SteadyWindow,
    STEADY_MIN_REVOLUTIONS,
};
use crate::diagnose::{line_split, low_side, unseen_motion};
use plant_model::Rig;
use std::f64::consts::PI;
use std::ops::Range;

/// Piston travel above which the log shows the piston moving (well above a linear
/// transducer's noise, well below the slowest stroke's travel). [m]
pub const MOVING_PISTON_TRAVEL_M: f64 = 0.2e-3;

/// Start of a log left out of the scores: a speed observer or filter settling. [s]
pub const START_SKIP_S: f64 = 0.1;

/// Half-width of the piston position's smoothing. [s]
pub const POSITION_SMOOTHING_S: f64 = 10e-3;

/// Fraction of the largest second differences left out of the noise estimate (steps and
/// transients, not noise). [1]
const NOISE_TRIM: f64 = 0.02;

/// Variance a Gaussian keeps when its 2 % largest magnitudes are left out (the two-sided
/// 98 % quantile q = 2.326: 1 − 2·q·φ(q)/0.98); the trimmed estimate is divided by it. [1]
const NOISE_TRIM_VARIANCE: f64 = 0.8735;

/// Everything about the log that does not depend on a model.
#[derive(Clone, Debug)]
pub struct LogFacts {
    /// Rows.
    pub rows: usize,
    /// Median sampling interval. [s]
    pub period_s: f64,
    /// Whether every interval is within 1 % of the median (uniform sampling).
    pub uniform: bool,
    /// Shaft angle, unwrapped: the logged one or the logged speed integrated. [rad]
    pub theta_rad: Vec<f64>,
    /// Where `theta_rad` comes from: logged, or integrated from the logged speed
    /// ([`crate::diagnose::speed_angle`]), so that its absolute phase is unknown.
    pub angle: AngleSource,
    /// One encoder count of `theta_rad`, when it moves by whole counts (logged from the
    /// encoder, or counted back from a count-difference speed). [rad]
    pub angle_count_rad: Option<f64>,
    /// The rig's fill pressure, the low side's (port B) where the log does not hold it
    /// ([`LogFacts::p_low`]). [Pa]
    pub fill_low_pa: f64,
    /// The fill (boost) level the ports' check valves hold them at, as the port transducers
    /// read it: the median over the rows of the lower of the two port pressures (the
    /// unloaded port sits there), or the rig's fill pressure less the check valve's
    /// cracking when the low side is not logged. [Pa]
    pub fill_pa: f64,
    /// The level the port holds on its check valve row by row where a blocked cylinder's
    /// pump reverses into its pressurised low side ([`low_side::sucked_port_track`]);
    /// `None` elsewhere, where [`LogFacts::fill_pa`] holds for every row. [Pa]
    pub fill_track_pa: Option<Vec<f64>>,
    /// Whether the piston moves (`x_m` logged and travelling).
    pub piston_moves: bool,
    /// Whether the low side (logged or estimated) departs from the fill
    /// ([`low_side::apart`]): a pump reversing into a blocked cylinder's low side
    /// pressurises it.
    pub low_side_apart: bool,
    /// The low side's pressure where the log does not hold it but the q current shows it
    /// pressurised: port B's node integrated from the pump's displaced volume
    /// ([`crate::diagnose::low_side`]). [Pa]
    pub p_low_estimate: Option<Vec<f64>>,
    /// The logged piston position smoothed over ±[`POSITION_SMOOTHING_S`] (quadratic
    /// Savitzky–Golay), when the piston moves: the volume balance multiplies the position by
    /// the oil's stiffness A·β/V, 14 kPa per micrometre of a 71 cm² piston, so the
    /// transducer's noise would otherwise dominate the pressure it predicts. [m]
    pub x_smooth_m: Option<Vec<f64>>,
    /// The logged port pressure smoothed as the position is ([`Self::x_smooth_m`]), when
    /// the piston moves: the position's volume balance multiplies it by the oil's
    /// compliance V/β/A, so its noise would otherwise enter the predicted position and
    /// favour a stiffer oil. The balance is read between the two smoothed signals, the
    /// same filter on both sides of a linear relation. [Pa]
    pub p_smooth_pa: Option<Vec<f64>>,
    /// Whether the piston moves but `x_m` is not logged: the oil the pump displaced swings
    /// over far more than the high side can store and leak
    /// ([`unseen_motion::unseen_piston_motion`]). The pressure's volume balance then lacks
    /// its largest flow, and the hydraulic effects cannot be tested.
    pub piston_unseen: bool,
    /// First row of the validation segment (identification is `start..split`).
    pub split: usize,
    /// First row scored: the log's first [`START_SKIP_S`] hold the logger's and the
    /// estimators' start-up, not the rig's physics.
    pub start: usize,
    /// Noise RMS per logged signal, from the trimmed second differences. [unit]
    pub noise_rms: Vec<(Signal, f64)>,
    /// Steady-rotation windows (speed nearly constant, at least
    /// [`STEADY_MIN_REVOLUTIONS`]), in time order, none across the lines' boundary.
    pub steady: Vec<SteadyWindow>,
    /// First row of the steady windows the line effects are checked on (those before it are
    /// fitted): the segments' boundary unless the slow rotation lies on one side of it
    /// ([`line_split::divided_windows`]).
    pub lines_split: usize,
}

impl LogFacts {
    /// The low side's pressure of `log` (the log these facts are of): logged, estimated
    /// ([`LogFacts::p_low_estimate`]), or the rig's fill pressure. [Pa]
    pub fn p_low<'a>(&'a self, log: &'a BenchLog) -> LowSide<'a> {
        match &self.p_low_estimate {
            Some(p) if log.p_low_pa.is_none() => LowSide::Logged(p),
            _ => LowSide::of(log, self.fill_low_pa),
        }
    }

    /// The facts of a checked `log` (at least a few rows, time increasing) on `rig`.
    pub fn of(log: &BenchLog, rig: &Rig) -> LogFacts {
        let rows = log.len();
        let t = &log.t_s;
        let period_s = median_period(t);
        let uniform = evenly_sampled(t, period_s);
        let (theta_rad, angle, angle_count_rad) = match log.theta_m_rad.as_deref() {
            Some(th) => {
                let theta = unwrap_angle(th, t, &log.speed_rad_s);
                let count = angle_count(&theta);
                (theta, AngleSource::Logged, count)
            }
            None => integrated_angle(t, &log.speed_rad_s, uniform),
        };
        let fill_low_pa = rig.fill.pressure_pa;
        let p_low = LowSide::of(log, fill_low_pa);
        let piston_moves = log.x_m.as_deref().is_some_and(|x| {
            let (lo, hi) = x
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                    (l.min(*v), h.max(*v))
                });
            hi - lo > MOVING_PISTON_TRAVEL_M
        });
        let x_smooth_m =
            log.x_m.as_deref().filter(|_| piston_moves).map(|x| {
                savitzky_golay_smooth(x, rows_spanning(POSITION_SMOOTHING_S, period_s, 1))
            });
        let p_smooth_pa = piston_moves.then(|| {
            savitzky_golay_smooth(&log.p_pa, rows_spanning(POSITION_SMOOTHING_S, period_s, 1))
        });
        let piston_unseen =
            log.x_m.is_none() && unseen_motion::unseen_piston_motion(log, p_low, rig);
        let split = segment_split(t, &theta_rad, period_s, rig);
        let start = t
            .partition_point(|x| *x < t[0] + START_SKIP_S)
            .min(split / 4);
        // A blocked cylinder's low side the log does not hold, pressurised where the q
        // current says so.
        let p_low_estimate = (!piston_moves && !piston_unseen)
            .then(|| low_side::estimate(log, &theta_rad, None, rig, start..rows))
            .flatten();
        let noise_rms: Vec<(Signal, f64)> = log
            .columns()
            .filter(|(s, y)| *s != Signal::Time && !y.is_empty())
            .map(|(s, y)| (s, noise_rms(y)))
            .collect();
        let p_noise = noise_of(&noise_rms, Signal::Pressure).unwrap_or(0.0);
        let low = log.p_low_pa.as_deref().or(p_low_estimate.as_deref());
        let low_side_apart = low_side::apart(low, fill_low_pa);
        let fill_pa = match low {
            // A blocked cylinder's low side pressurised by the reversing pump is never at
            // the fill while the port is sucked down to it: the level the port holds there.
            Some(_) if low_side_apart && !piston_moves => {
                low_side::sucked_port_level(log, start, period_s, p_noise)
            }
            Some(pl) => {
                let mut lower: Vec<f64> = log.p_pa.iter().zip(pl).map(|(a, b)| a.min(*b)).collect();
                lower.sort_by(f64::total_cmp);
                lower[lower.len() / 2]
            }
            None => rig.fill.pressure_pa - rig.fill.check_cracking_pa,
        };
        let fill_track_pa = (low.is_some() && low_side_apart && !piston_moves).then(|| {
            let w_noise = noise_of(&noise_rms, Signal::Speed).unwrap_or(0.0);
            low_side::sucked_port_track(log, start, period_s, p_noise, w_noise, fill_pa)
        });
        let (steady, lines_split) =
            line_split::divided_windows(t, &theta_rad, period_s, rig, split, start);
        LogFacts {
            rows,
            period_s,
            uniform,
            theta_rad,
            angle,
            angle_count_rad,
            fill_low_pa,
            fill_pa,
            fill_track_pa,
            low_side_apart,
            p_low_estimate,
            piston_moves,
            x_smooth_m,
            p_smooth_pa,
            piston_unseen,
            split,
            start,
            noise_rms,
            steady,
            lines_split,
        }
    }

    /// The noise RMS of `signal` (its unit), if logged.
    pub fn noise(&self, signal: Signal) -> Option<f64> {
        noise_of(&self.noise_rms, signal)
    }

    /// Identification rows.
    pub fn identification(&self) -> Range<usize> {
        self.start..self.split
    }

    /// Validation rows.
    pub fn validation(&self) -> Range<usize> {
        self.split..self.rows
    }

    /// Consecutive windows of about `length_s` covering `rows` (the last one absorbs a
    /// remainder shorter than half a window), each at least two rows.
    pub fn windows(&self, rows: Range<usize>, length_s: f64) -> Vec<Range<usize>> {
        let len = ((length_s / self.period_s).round() as usize).max(2);
        let mut out = Vec::new();
        let mut start = rows.start;
        while start + 1 < rows.end {
            let mut end = (start + len).min(rows.end);
            if rows.end - end < len / 2 {
                end = rows.end;
            }
            out.push(start..end);
            start = end;
        }
        out
    }
}

/// Farthest the boundary between the identification and the validation segment moves
/// from the log's middle, as a fraction of its duration. [1]
pub const SPLIT_REACH: f64 = 0.2;

/// The first row of the validation segment: the log's middle, unless the steady rotation
/// slow enough to resolve every angle-locked line (the slot order below a third of the
/// log's rate) sits mostly on one side of it. A staircase or step whose first level is
/// reached at the speed limit holds all its slow rotation in its second half, and a line
/// effect could then be neither fitted nor checked: the boundary moves, within
/// [`SPLIT_REACH`] of the middle, to the end of the slow window that leaves the lesser side
/// the most such revolutions (at least twice what the middle leaves it).
fn segment_split(t: &[f64], theta: &[f64], period_s: f64, rig: &Rig) -> usize {
    let rows = t.len();
    let at = |f: f64| {
        let t_f = t[0] + f * (t[rows - 1] - t[0]);
        t.partition_point(|x| *x < t_f).clamp(1, rows - 1)
    };
    let limit = slow_line_speed(period_s, rig);
    let windows = steady_windows(t, theta, period_s);
    let slow = slow_windows(&windows, limit);
    let middle = at(0.5);
    let (lo, hi) = (at(0.5 - SPLIT_REACH), at(0.5 + SPLIT_REACH));
    let (best, score) = balanced_boundary(&slow, middle, lo..=hi);
    if score > 2.0 * lesser_side(&slow, middle) && score >= STEADY_MIN_REVOLUTIONS {
        best
    } else {
        middle
    }
}

/// Rows spanning `seconds` at the sampling `period_s`, at least `min_rows`: the spans of
/// differences and fits are set in time, so a faster log is not differentiated over a
/// shorter interval.
pub fn rows_spanning(seconds: f64, period_s: f64, min_rows: usize) -> usize {
    let rows = (seconds / period_s.max(f64::MIN_POSITIVE)).round();
    if rows.is_finite() && rows >= min_rows as f64 {
        rows.min(1e6) as usize
    } else {
        min_rows
    }
}

/// `y` smoothed by the quadratic Savitzky–Golay filter of half-width `m` rows (exact on a
/// parabola; the rows within `m` of either end keep a narrower window).
pub fn savitzky_golay_smooth(y: &[f64], m: usize) -> Vec<f64> {
    let n = y.len();
    let weights = |m: usize| -> Vec<f64> {
        let mf = m as f64;
        let den = (2.0 * mf - 1.0) * (2.0 * mf + 1.0) * (2.0 * mf + 3.0);
        (0..=2 * m)
            .map(|i| {
                let j = i as f64 - mf;
                3.0 * (3.0 * mf * mf + 3.0 * mf - 1.0 - 5.0 * j * j) / den
            })
            .collect()
    };
    let full = weights(m);
    (0..n)
        .map(|k| {
            let h = m.min(k).min(n - 1 - k);
            if h == 0 {
                return y[k];
            }
            let w = if h == m { full.clone() } else { weights(h) };
            w.iter().enumerate().map(|(i, c)| c * y[k + i - h]).sum()
        })
        .collect()
}

/// Whether every sampling interval of `t` is within 1 % of `period_s` (its median).
pub fn evenly_sampled(t: &[f64], period_s: f64) -> bool {
    t.windows(2)
        .all(|w| ((w[1] - w[0]) / period_s - 1.0).abs() < 0.01)
}

/// Median of the sampling intervals of `t` (at least two rows). [s]
pub fn median_period(t: &[f64]) -> f64 {
    let mut d: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    d.sort_by(f64::total_cmp);
    d.get(d.len() / 2)
        .copied()
        .unwrap_or(1e-3)
        .max(f64::MIN_POSITIVE)
}

/// `signal`'s noise RMS in the per-signal list `noise`, if it lists it.
fn noise_of(noise: &[(Signal, f64)], signal: Signal) -> Option<f64> {
    noise.iter().find(|(s, _)| *s == signal).map(|(_, v)| *v)
}

/// Noise RMS of a signal from its second differences, which cancel any trend and slope:
/// for white noise of variance σ², Δ²y has variance 6σ². The largest [`NOISE_TRIM`] of them
/// (steps, the start of a ramp) are left out and the Gaussian's loss from the trimming is
/// given back. A quantised signal whose noise is below its step reads the quantisation
/// noise (step/√12 per sample on average), which is what a model can at best reach. [unit]
pub fn noise_rms(y: &[f64]) -> f64 {
    if y.len() < 3 {
        return 0.0;
    }
    let mut d2: Vec<f64> = y
        .windows(3)
        .map(|w| (w[2] - 2.0 * w[1] + w[0]).powi(2))
        .collect();
    d2.sort_by(f64::total_cmp);
    let keep = ((1.0 - NOISE_TRIM) * d2.len() as f64).ceil() as usize;
    let kept = &d2[..keep.clamp(1, d2.len())];
    let var = kept.iter().sum::<f64>() / kept.len() as f64 / 6.0 / NOISE_TRIM_VARIANCE;
    var.sqrt()
}

/// Unwraps an angle logged wrapped (to [0, 2π) or any 2π range) or already unwrapped at
/// the times `t` [s], guided by the logged `speed` [rad/s]: each step is taken as the one of
/// its 2π-equivalents closest to what the speed turns over the interval (the trapezoid of
/// the two rows' speeds). Between rows a logger kept, that is the equivalent closest to
/// zero, right while the shaft turns less than half a revolution per interval (3 000 rad/s
/// at 1 kHz); across rows it lost (20 ms at 180 rad/s turn 3.6 rad) the speed tells how
/// far the shaft went where the wrapped angle cannot.
pub fn unwrap_angle(wrapped: &[f64], t: &[f64], speed: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(wrapped.len());
    let mut acc = wrapped.first().copied().unwrap_or(0.0);
    let mut prev = acc;
    for (k, &a) in wrapped.iter().enumerate() {
        let d = a - prev;
        let turned = match (t.get(k), speed.get(k)) {
            (Some(tk), Some(wk)) if k > 0 => {
                let e = 0.5 * (wk + speed[k - 1]) * (tk - t[k - 1]);
                if e.is_finite() {
                    e
                } else {
                    0.0
                }
            }
            _ => 0.0,
        };
        acc += d - 2.0 * PI * ((d - turned) / (2.0 * PI)).round();
        prev = a;
        out.push(acc);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A blocked cylinder's 1 kHz log at 3 MPa, its low side at `low` row by row.
    fn blocked_log(low: Vec<f64>) -> BenchLog {
        let n = low.len();
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let mut p = vec![3e6; n];
        p[n / 2] = 0.52e6;
        BenchLog {
            t_s: t.clone(),
            p_ref_pa: vec![3e6; n],
            p_pa: p,
            speed_rad_s: vec![1.0; n],
            iq_a: vec![0.5; n],
            id_a: vec![0.0; n],
            theta_m_rad: Some(t),
            p_low_pa: Some(low),
            ..BenchLog::default()
        }
    }

    #[test]
    fn a_low_side_two_megapascals_up_on_a_twentieth_of_the_rows_is_apart() {
        // The nominal rig fills at 0.5 MPa: 100 of 2000 rows at 2.5 MPa are 5 % of the
        // rows 2 MPa away; 10 of them (0.5 %) are not enough, nor is 1.4 MPa (0.9 MPa away).
        let rig = Rig::nominal();
        let with = |rows: usize, level: f64| {
            let mut low = vec![0.5e6; 2000];
            low[..rows].fill(level);
            blocked_log(low)
        };
        assert!(LogFacts::of(&with(100, 2.5e6), &rig).low_side_apart);
        assert!(!LogFacts::of(&with(10, 2.5e6), &rig).low_side_apart);
        assert!(!LogFacts::of(&with(100, 1.4e6), &rig).low_side_apart);
        assert!(!LogFacts::of(&with(0, 0.5e6), &rig).low_side_apart);
    }

    #[test]
    fn a_pressurised_low_side_floors_the_port_at_its_lowest_reading() {
        // The port dips once to 0.52 MPa while the low side sits at 2.5 MPa: its check
        // valve cannot hold it above that; at the fill the median of the lower port is it.
        let rig = Rig::nominal();
        let apart = LogFacts::of(&blocked_log(vec![2.5e6; 2000]), &rig);
        assert_eq!(apart.fill_pa, 0.52e6);
        let at_fill = LogFacts::of(&blocked_log(vec![0.5e6; 2000]), &rig);
        assert_eq!(at_fill.fill_pa, 0.5e6);
    }

    #[test]
    fn unwrapping_restores_a_steady_rotation() {
        // 0.3 rad a millisecond: 300 rad/s at 1 kHz.
        let t: Vec<f64> = (0..100).map(|k| k as f64 * 1e-3).collect();
        let truth: Vec<f64> = (0..100).map(|k| 1.0 + 0.3 * k as f64).collect();
        let wrapped: Vec<f64> = truth.iter().map(|a| a.rem_euclid(2.0 * PI)).collect();
        for (u, a) in unwrap_angle(&wrapped, &t, &[300.0; 100]).iter().zip(&truth) {
            assert!((u - a).abs() < 1e-9, "{u} vs {a}");
        }
        let back: Vec<f64> = truth.iter().map(|a| (-a).rem_euclid(2.0 * PI)).collect();
        let u = unwrap_angle(&back, &t, &[-300.0; 100]);
        assert!((u[99] - u[0] + 0.3 * 99.0).abs() < 1e-9);
    }

    #[test]
    fn unwrapping_follows_the_speed_across_rows_the_logger_lost() {
        // 180 rad/s at 1 kHz with rows 50–70 lost: the shaft turns 3.96 rad over the 22 ms
        // between rows 49 and 71, more than half a revolution, which the wrapped angle
        // alone would take as −2.32 rad.
        let kept: Vec<usize> = (0..50).chain(71..200).collect();
        let t: Vec<f64> = kept.iter().map(|&k| k as f64 * 1e-3).collect();
        let truth: Vec<f64> = t.iter().map(|t| 0.5 + 180.0 * t).collect();
        let wrapped: Vec<f64> = truth.iter().map(|a| a.rem_euclid(2.0 * PI)).collect();
        let u = unwrap_angle(&wrapped, &t, &vec![180.0; t.len()]);
        for (u, a) in u.iter().zip(&truth) {
            assert!((u - a).abs() < 1e-9, "{u} vs {a}");
        }
        // Without the speed the step across the gap is the short way round.
        let blind = unwrap_angle(&wrapped, &t, &[]);
        assert!((blind[50] - blind[49] - (3.96 - 2.0 * PI)).abs() < 1e-9);
    }

    #[test]
    fn noise_of_white_noise_on_a_ramp_is_its_standard_deviation() {
        // A deterministic uniform sequence of variance 1/12 on a steep ramp: the second
        // differences cancel the ramp, the estimate is the deviation within 5 %.
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let y: Vec<f64> = (0..20_000)
            .map(|k| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                let u = (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                1e3 * k as f64 + u
            })
            .collect();
        let sigma = (1.0f64 / 12.0).sqrt();
        let est = noise_rms(&y);
        // Uniform noise has lighter tails than a Gaussian: the trimming removes less and the
        // correction overshoots a little.
        assert!((est / sigma - 1.0).abs() < 0.12, "{est} vs {sigma}");
    }
}
