//! The low-speed pressure holding that `eha demo` and the precharge sweep run: one holding
//! run at the simulated bench-log rate, and its steady-state pulsation figures.
//!
//! Pulsation is measured on the plant's true port pressure over the steady window (the
//! measured pressure adds the transducer's noise and 477 Pa quantisation, which would
//! dominate the peak-to-peak at these amplitudes; both are in the bench log).

use crate::output::CliError;
use crate::pulsation::{amplitude_spectrum, dominant_line, peak_to_peak, sources, Source};
use crate::run::{run, Run, RunOptions, LOG_RATE_HZ};
use closed_loop::{by_name, Scenario};
use plant_model::Rig;

fn steady<'a>(run: &'a Run, scenario: &Scenario) -> (Vec<f64>, &'a [f64]) {
    let t0 = scenario.steady_from_s;
    let first = run.log.t_s.iter().position(|t| *t >= t0).unwrap_or(0);
    (
        run.p_true_pa[first..].to_vec(),
        &run.speed_true_rad_s[first..],
    )
}

/// Steady-state pulsation figures of a holding run.
pub(crate) struct Pulsation {
    pub(crate) mean_pa: f64,
    pub(crate) pp_pa: f64,
    pub(crate) speed_rad_s: f64,
    pub(crate) dominant_hz: f64,
    pub(crate) dominant_amp_pa: f64,
    pub(crate) cause: Option<Source>,
    pub(crate) spectrum: Vec<(f64, f64)>,
}

pub(crate) fn pulsation(run: &Run, scenario: &Scenario, rig: &Rig) -> Pulsation {
    let (p, w) = steady(run, scenario);
    let mean = p.iter().sum::<f64>() / p.len().max(1) as f64;
    let speed = w.iter().sum::<f64>() / w.len().max(1) as f64;
    let spectrum = amplitude_spectrum(&p, 1.0 / LOG_RATE_HZ);
    let rev_s = speed / (2.0 * std::f64::consts::PI);
    let (f, a, cause) =
        dominant_line(&spectrum, 0.5, rev_s, &sources(rig)).unwrap_or((0.0, 0.0, None));
    Pulsation {
        mean_pa: mean,
        pp_pa: peak_to_peak(&p),
        speed_rad_s: speed,
        dominant_hz: f,
        dominant_amp_pa: a,
        cause,
        spectrum,
    }
}

pub(crate) fn holding_run(
    plant: &Rig,
    controller: &Rig,
    duration_s: f64,
    metadata: Vec<(String, String)>,
) -> Result<Run, CliError> {
    let scenario = by_name("pressure-hold")
        .ok_or_else(|| CliError::Failed("pressure-hold scenario missing".into()))?;
    run(
        plant,
        controller,
        scenario,
        &RunOptions {
            duration_s,
            log_rate_hz: LOG_RATE_HZ,
            seed: 1,
            progress: true,
            metadata,
            compensation: None,
            integrator: Default::default(),
        },
    )
    .map_err(CliError::Failed)
    .and_then(|r| super::converged(r, None))
}
