//! A setpoint step in a logged or simulated response: where it is, and its overshoot and
//! settling time (the usual time-domain step specifications, e.g. Ogata, *Modern Control
//! Engineering*, 5.3).
//!
//! The step is found in the loop's reference column: the reference holds a value, leaves it
//! (at once for a speed command, along the setpoint ramp for pressure) and holds a new value.
//! A loop output that merely varies — the speed reference in pressure mode — never holds, so
//! it is not taken for a step.
//!
//! Definitions, for a step from `r0` to `r1` starting (reference leaving `r0`) at `t0`:
//! - the response is first averaged over a centred window ([`Signal::smoothing_s`]) so that
//!   sensor quantisation and the speed estimate's encoder ripple do not count as motion;
//! - overshoot `= max(0, max sign(r1 − r0)·(y − r1)) / |r1 − r0|` [%];
//! - settling time: from `t0` until the response last leaves the 2 % band
//!   `|y − r1| ≤ 0.02·|r1 − r0|`; none when it is still outside at the end of the window.

/// Band around the final value the settling time is measured to. [1 of the step]
pub const SETTLING_BAND: f64 = 0.02;

/// Which response a step is measured on; sets the smallest step and the smoothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Signal {
    /// Pressure [Pa] against the pressure setpoint.
    Pressure,
    /// Shaft speed [rad/s] against the speed reference.
    Speed,
}

impl Signal {
    /// Smallest reference change taken for a step: well above the transducer's noise
    /// (pressure, ~10 kPa) and the speed estimate's ripple (~0.5 rad/s). [Pa] or [rad/s]
    pub fn min_step(self) -> f64 {
        match self {
            Signal::Pressure => 0.2e6,
            Signal::Speed => 5.0,
        }
    }

    /// Width of the centred moving average the response is smoothed with: 5 ms spans
    /// several periods of the speed estimate's encoder ripple (~2 ms), 10 ms the pressure
    /// loop's own feedback filter (1/150 rad/s = 6.7 ms). [s]
    pub fn smoothing_s(self) -> f64 {
        match self {
            Signal::Pressure => 0.010,
            Signal::Speed => 0.005,
        }
    }

    /// How long the reference must hold a value before and after the step. [s]
    fn hold_s(self) -> f64 {
        0.020
    }

    /// Two reference samples are "the same value" within this. [Pa] or [rad/s]
    fn tolerance(self) -> f64 {
        match self {
            Signal::Pressure => 1.0,
            Signal::Speed => 1e-3,
        }
    }
}

/// A step found in a reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// Reference before the step. [Pa] or [rad/s]
    pub from: f64,
    /// Reference after the step (its final, held value). [Pa] or [rad/s]
    pub to: f64,
    /// Index of the first sample whose reference has left `from`.
    pub start: usize,
    /// Index of the first sample at which the reference holds `to`.
    pub reached: usize,
    /// One past the last sample of the step's window (the reference leaves `to` there,
    /// or the log ends).
    pub end: usize,
}

/// Why no step was found.
#[derive(Clone, Debug, PartialEq)]
pub enum StepError {
    /// The reference holds values, but never changes between two of them by at least the
    /// smallest step.
    NoStep,
    /// The reference never holds a value (a loop output, not a setpoint).
    NoHold,
}

/// Finds the first step of `reference` (sampled at `t` [s]): the first two consecutive
/// holds (stretches of at least 20 ms at one value) that differ by at least the smallest
/// step.
pub fn find(t: &[f64], reference: &[f64], signal: Signal) -> Result<Step, StepError> {
    let n = reference.len().min(t.len());
    let holds = holds(&t[..n], &reference[..n], signal);
    if holds.is_empty() {
        return Err(StepError::NoHold);
    }
    holds
        .windows(2)
        .find(|w| (reference[w[1].0] - reference[w[0].0]).abs() >= signal.min_step())
        .map(|w| Step {
            from: reference[w[0].0],
            to: reference[w[1].0],
            start: w[0].1,
            reached: w[1].0,
            end: w[1].1,
        })
        .ok_or(StepError::NoStep)
}

/// The stretches `first..end` over which `reference` keeps one value for at least the
/// signal's hold time.
fn holds(t: &[f64], reference: &[f64], signal: Signal) -> Vec<(usize, usize)> {
    let n = reference.len();
    let mut out = Vec::new();
    let mut k = 0;
    while k < n {
        let v = reference[k];
        let end = (k..n)
            .find(|&j| (reference[j] - v).abs() > signal.tolerance())
            .unwrap_or(n);
        if t[end - 1] - t[k] >= signal.hold_s() {
            out.push((k, end));
        }
        k = end;
    }
    out
}

/// Overshoot and settling of one step response.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepMetrics {
    /// Peak beyond the final reference, as a fraction of the step. [%]
    pub overshoot_percent: f64,
    /// Time from the step's start until the response stays in the 2 % band; `None` when it
    /// has not settled by the end of the window. [s]
    pub settling_s: Option<f64>,
}

/// What a response must meet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    /// Largest overshoot. [%]
    pub overshoot_percent: f64,
    /// Longest 2 % settling time. [s]
    pub settling_s: f64,
}

impl StepMetrics {
    /// Whether these meet `target`.
    pub fn meets(&self, target: &Target) -> bool {
        self.overshoot_percent <= target.overshoot_percent
            && self.settling_s.is_some_and(|s| s <= target.settling_s)
    }

    /// How far beyond the target the worse of the two is (≤ 1 when the target is met;
    /// an unsettled response counts as infinitely slow).
    pub fn violation(&self, target: &Target) -> f64 {
        let os = self.overshoot_percent / target.overshoot_percent.max(1e-9);
        let ts = self
            .settling_s
            .map_or(f64::INFINITY, |s| s / target.settling_s);
        os.max(ts)
    }
}

/// Overshoot and settling of `response` for `step` (both sampled at `t` [s]).
pub fn metrics(t: &[f64], response: &[f64], step: &Step, signal: Signal) -> StepMetrics {
    let smooth = centred_mean(t, response, signal.smoothing_s());
    let size = step.to - step.from;
    let sign = size.signum();
    let window = step.start..step.end.min(smooth.len());
    let peak = smooth[window.clone()]
        .iter()
        .map(|y| sign * (y - step.to))
        .fold(0.0, f64::max);
    let band = SETTLING_BAND * size.abs();
    let last_out = window
        .clone()
        .rev()
        .find(|&k| (smooth[k] - step.to).abs() > band);
    let settling_s = match last_out {
        None => Some(0.0),
        Some(k) if k + 1 >= window.end => None,
        Some(k) => Some(t[k + 1] - t[step.start]),
    };
    StepMetrics {
        overshoot_percent: 100.0 * peak / size.abs(),
        settling_s,
    }
}

/// The least part of a step a response must come toward its new setpoint for the step to
/// be one the loop followed: half (a loop with integral action reaches all of it; a slow
/// one, at its speed limit, at least half within its window). [1 of the step]
pub const MIN_FOLLOWED: f64 = 0.5;

/// How far `response` (smoothed as for [`metrics`]) came toward `step.to` within the
/// step's window, as a part of the step: 0 where it stayed at its value before the step,
/// 1 where it reached the new setpoint (negative where it went the other way).
pub fn followed(t: &[f64], response: &[f64], step: &Step, signal: Signal) -> f64 {
    let width = signal.smoothing_s();
    let smooth = centred_mean(t, response, width);
    let size = step.to - step.from;
    let end = step.end.min(smooth.len());
    // The value before the step: the last average taken wholly before it.
    let Some(t0) = t.get(step.start) else {
        return 0.0;
    };
    let last_before = t[..step.start].partition_point(|x| *x <= t0 - 0.5 * width);
    let Some(&before) = smooth.get(last_before.saturating_sub(1)) else {
        return 0.0;
    };
    smooth
        .get(step.start..end)
        .unwrap_or_default()
        .iter()
        .map(|y| (y - before) / size)
        .fold(f64::NEG_INFINITY, f64::max)
}

/// Centred moving average of `y` over `width` seconds (shorter at the ends), by prefix sums.
pub fn centred_mean(t: &[f64], y: &[f64], width: f64) -> Vec<f64> {
    let n = y.len().min(t.len());
    let mut prefix = Vec::with_capacity(n + 1);
    prefix.push(0.0);
    for v in &y[..n] {
        prefix.push(prefix.last().copied().unwrap_or(0.0) + v);
    }
    let half = 0.5 * width;
    let (mut lo, mut hi) = (0usize, 0usize);
    (0..n)
        .map(|k| {
            while t[lo] < t[k] - half {
                lo += 1;
            }
            while hi < n && t[hi] <= t[k] + half {
                hi += 1;
            }
            (prefix[hi] - prefix[lo]) / (hi - lo) as f64
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn times(n: usize, dt: f64) -> Vec<f64> {
        (0..n).map(|k| k as f64 * dt).collect()
    }

    #[test]
    fn second_order_step_matches_the_analytic_overshoot_and_settling() {
        // y = 1 − e^(−ζωt)(cos ω_d t + ζ/√(1−ζ²) sin ω_d t): overshoot e^(−πζ/√(1−ζ²)),
        // here ζ = 0.5 → 16.3 %; the 2 % settling is found by scanning the exact envelope.
        let (zeta, wn) = (0.5_f64, 50.0_f64);
        let wd = wn * (1.0 - zeta * zeta).sqrt();
        let t = times(20_000, 5e-5);
        let t0 = 0.1;
        let r: Vec<f64> = t.iter().map(|&x| if x >= t0 { 1.0 } else { 0.0 }).collect();
        let exact = |x: f64| {
            let s = x - t0;
            if s < 0.0 {
                0.0
            } else {
                1.0 - (-zeta * wn * s).exp()
                    * ((wd * s).cos() + zeta / (1.0 - zeta * zeta).sqrt() * (wd * s).sin())
            }
        };
        let y: Vec<f64> = t.iter().map(|&x| exact(x)).collect();
        let step = find(&t, &r, Signal::Speed).unwrap_err();
        // A unit step is below the speed loop's smallest step; scale to 50 rad/s.
        assert_eq!(step, StepError::NoStep);
        let r50: Vec<f64> = r.iter().map(|v| 50.0 * v).collect();
        let y50: Vec<f64> = y.iter().map(|v| 50.0 * v).collect();
        let step = find(&t, &r50, Signal::Speed).unwrap();
        assert_eq!((step.from, step.to, step.end), (0.0, 50.0, t.len()));
        let m = metrics(&t, &y50, &step, Signal::Speed);
        let os = 100.0 * (-std::f64::consts::PI * zeta / (1.0 - zeta * zeta).sqrt()).exp();
        assert!((m.overshoot_percent - os).abs() < 0.3, "{m:?} vs {os}");
        let last_out = t
            .iter()
            .rev()
            .find(|&&x| (exact(x) - 1.0).abs() > 0.02)
            .unwrap();
        let ts = last_out - t0;
        let got = m.settling_s.unwrap();
        assert!((got - ts).abs() < 0.01, "{got} vs {ts}");
    }

    #[test]
    fn ramped_setpoint_is_one_step_and_a_varying_reference_is_none() {
        let t = times(4000, 5e-4);
        // 3 → 5 MPa ramped at 10 MPa/s from 0.5 s.
        let r: Vec<f64> = t
            .iter()
            .map(|&x| 3e6 + (1e7 * (x - 0.5)).clamp(0.0, 2e6))
            .collect();
        let s = find(&t, &r, Signal::Pressure).unwrap();
        assert_eq!((s.from, s.to), (3e6, 5e6));
        assert!((t[s.start] - 0.5).abs() < 1e-3 && (t[s.reached] - 0.7).abs() < 1e-3);
        // A setpoint that starts a little off (the ramp starts from the measured pressure)
        // is the same step.
        let mut r2 = r.clone();
        r2[0] = 2_998_829.0;
        assert_eq!(find(&t, &r2, Signal::Pressure), Ok(s));
        // A loop output (never holding a value) is not a step.
        let w: Vec<f64> = t.iter().map(|&x| 3.0 + 40.0 * (7.0 * x).sin()).collect();
        assert_eq!(find(&t, &w, Signal::Speed), Err(StepError::NoHold));
        // A constant reference has no step.
        assert_eq!(
            find(&t, &vec![5e6; t.len()], Signal::Pressure),
            Err(StepError::NoStep)
        );
    }

    #[test]
    fn a_response_that_stays_put_did_not_follow_the_step() {
        // A first-order response with time constant τ comes 1 − e^(−T/τ) of the way in T.
        let t = times(4000, 5e-4);
        let r: Vec<f64> = t.iter().map(|&x| if x > 0.5 { 5e6 } else { 3e6 }).collect();
        let s = find(&t, &r, Signal::Pressure).unwrap();
        let tau = 0.1;
        let y: Vec<f64> = t
            .iter()
            .map(|&x| 3e6 + 2e6 * (1.0 - (-(x - 0.5).max(0.0) / tau).exp()))
            .collect();
        let reached = 1.0 - (-(t[t.len() - 1] - 0.5) / tau).exp();
        let f = followed(&t, &y, &s, Signal::Pressure);
        assert!((f - reached).abs() < 0.01, "{f} vs {reached}");
        let flat = vec![3e6; t.len()];
        assert_eq!(followed(&t, &flat, &s, Signal::Pressure), 0.0);
        let away: Vec<f64> = y.iter().map(|v| 6e6 - v).collect();
        assert!(followed(&t, &away, &s, Signal::Pressure) < 0.0);
    }

    #[test]
    fn a_response_still_outside_the_band_at_the_end_has_not_settled() {
        let t = times(2000, 5e-4);
        let r: Vec<f64> = t
            .iter()
            .map(|&x| if x > 0.1 { 50.0 } else { 0.0 })
            .collect();
        let y: Vec<f64> = t
            .iter()
            .map(|&x| {
                if x > 0.1 {
                    50.0 + 10.0 * (60.0 * x).sin()
                } else {
                    0.0
                }
            })
            .collect();
        let s = find(&t, &r, Signal::Speed).unwrap();
        let m = metrics(&t, &y, &s, Signal::Speed);
        assert_eq!(m.settling_s, None);
        assert!(!m.meets(&Target {
            overshoot_percent: 100.0,
            settling_s: 10.0
        }));
        assert!((m.overshoot_percent - 20.0).abs() < 1.0, "{m:?}");
    }
}
