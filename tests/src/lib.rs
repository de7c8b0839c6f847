//! Cross-crate closed-loop tests live in `tests/tests/`; this library holds what they share:
//! step-response measures on sampled traces and the way a run is set up.
//!
//! Every measure works on a trace of `(t, y)` pairs in time order (t in seconds, y in the
//! quantity's unit) and is defined the textbook way, so a test's expected numbers come from
//! the design formulas, not from this code.

pub mod blind;
pub mod campaign;
pub mod fleet;
pub mod fuzz;
pub mod integrator_accuracy;

use closed_loop::{controller_config, ClosedLoop, Sample, Scenario};
use plant_model::Rig;

/// A sampled trace: time [s] and value [unit of the quantity].
pub type Trace = Vec<(f64, f64)>;

/// The first time `y` reaches `level` going in the direction of `level − y(t0)`, linearly
/// interpolated between samples; `None` when it never does. [s]
pub fn first_crossing(trace: &[(f64, f64)], level: f64) -> Option<f64> {
    let (_, y0) = *trace.first()?;
    let rising = level >= y0;
    trace.windows(2).find_map(|w| {
        let ((ta, ya), (tb, yb)) = (w[0], w[1]);
        let reached = if rising { yb >= level } else { yb <= level };
        if !reached {
            return None;
        }
        if (yb - ya).abs() < f64::EPSILON {
            Some(tb)
        } else {
            Some(ta + (tb - ta) * (level - ya) / (yb - ya))
        }
    })
}

/// The time after which `y` stays within `final_value ± band` to the end of the trace,
/// measured from `t_from`: the sample time following the last sample outside the band, or
/// `t_from` when none is. [s]
pub fn settling_time(trace: &[(f64, f64)], final_value: f64, band: f64, t_from: f64) -> f64 {
    let last_out = trace
        .iter()
        .rposition(|(t, y)| *t >= t_from && (y - final_value).abs() > band);
    match last_out {
        Some(k) => trace.get(k + 1).map_or(trace[k].0, |s| s.0) - t_from,
        None => 0.0,
    }
}

/// Overshoot of a step from `initial` to `final_value` as a fraction of the step: the
/// largest excursion beyond `final_value` (0 when there is none). [1]
pub fn overshoot(trace: &[(f64, f64)], initial: f64, final_value: f64) -> f64 {
    let step = final_value - initial;
    trace
        .iter()
        .map(|(_, y)| (y - final_value) / step)
        .fold(0.0, f64::max)
}

/// Mean of `y` over `t0 <= t < t1`; NaN when no sample falls in the window.
pub fn mean_between(trace: &[(f64, f64)], t0: f64, t1: f64) -> f64 {
    let (sum, n) = trace
        .iter()
        .filter(|(t, _)| *t >= t0 && *t < t1)
        .fold((0.0, 0usize), |(s, n), (_, y)| (s + y, n + 1));
    sum / n as f64
}

/// The part of a trace with `t0 <= t < t1`.
pub fn window(trace: &[(f64, f64)], t0: f64, t1: f64) -> Trace {
    trace
        .iter()
        .copied()
        .filter(|(t, _)| *t >= t0 && *t < t1)
        .collect()
}

/// The closed loop for `scenario` on `rig` at the PWM (current-loop) rate `pwm_hz`: the
/// plant's inverter and the controller's configuration (built from the rig, as the drive
/// engineer would) both at that rate, speed and pressure loops at their default rates.
pub fn closed_loop_at(rig: &Rig, scenario: &Scenario, pwm_hz: f64, seed: u64) -> ClosedLoop {
    let mut rig = rig.clone();
    rig.inverter.pwm_frequency_hz = pwm_hz;
    let config = controller_config(&rig);
    match ClosedLoop::new(&rig, &config, scenario, seed) {
        Ok(l) => l,
        Err(e) => panic!("closed loop for {} at {pwm_hz} Hz: {e}", scenario.name),
    }
}

/// Runs `l` until `t_end` [s] and returns `pick` of every sample, with the plant's time.
pub fn record(l: &mut ClosedLoop, t_end: f64, pick: impl Fn(&Sample) -> f64) -> Trace {
    let mut out = Vec::new();
    l.run(t_end, 1, |s| out.push((s.truth.t_s, pick(s))));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn exp_trace() -> Trace {
        // 1 − e^{−t} sampled every 1 ms for 10 s.
        (0..10_000)
            .map(|k| {
                let t = k as f64 * 1e-3;
                (t, 1.0 - (-t).exp())
            })
            .collect()
    }

    #[test]
    fn measures_of_a_first_order_step() {
        let tr = exp_trace();
        // 63.2 % at t = τ = 1 s; 2 % band reached at ln 50 = 3.912 s; no overshoot.
        let t63 = first_crossing(&tr, 1.0 - (-1.0f64).exp()).unwrap();
        assert!((t63 - 1.0).abs() < 1e-6, "{t63}");
        let ts = settling_time(&tr, 1.0, 0.02, 0.0);
        assert!((ts - 50f64.ln()).abs() < 1.1e-3, "{ts}");
        assert_eq!(overshoot(&tr, 0.0, 1.0), 0.0);
        assert!((mean_between(&tr, 0.0, 1.0) - (-1.0f64).exp()).abs() < 1e-3);
    }

    #[test]
    fn overshoot_of_a_falling_step() {
        let tr = vec![(0.0, 5.0), (1.0, 2.0), (2.0, 0.5), (3.0, 1.0)];
        // Step 5 → 1, undershoot to 0.5 = 12.5 % of the step of −4.
        assert!((overshoot(&tr, 5.0, 1.0) - 0.125).abs() < 1e-12);
        assert_eq!(first_crossing(&tr, 2.0), Some(1.0));
    }
}
