//! `eha diagnose`: what the model gets wrong on a measured log, why, the extended model,
//! and the gain on data the fit never saw. A pipeline that reads top to bottom
//! ([`analysis`] lists the stages):
//!
//! - [`facts`]: facts about the log, computed once (sampling, angle, noise, segments,
//!   steady windows).
//! - The parity relations, each predicting one logged signal from the others over short
//!   windows re-started from the measurement, so nothing drifts: [`hydraulic`] (pressure
//!   from the shaft angle), [`mechanical`] (q current and speed from the torque balance),
//!   [`electrical`] (voltages, when logged), [`cylinder`] (pressure from the piston's
//!   force balance, when it moves).
//! - [`least_squares`] and [`calibration`]: the nominal model fitted to the log within the
//!   rig's tolerance bands, and with one effect's parameter released.
//! - [`lines`], [`angle_locked`], [`dead_time`]: the angle-locked lines of the steady
//!   windows and the effects that make them.
//! - [`candidates`], [`decision`]: every effect tested, and the one the log convicts.
//! - [`predictions`]: the contract's per-signal predictions and scores.
//! - [`signatures`], [`spectrum`]: the baseline residuals' time-domain signatures and
//!   order spectra, for the report.
//! - [`diagnosis`]: the contract's JSON; [`report`]: the markdown report; [`command`]: the
//!   CLI.

pub mod ambiguity;
pub mod analysis;
pub mod angle_locked;
pub mod back_emf;
pub mod calibration;
pub mod candidates;
pub mod command;
pub mod contributions;
pub mod cylinder;
pub mod dead_time;
pub mod decision;
pub mod diagnosis;
pub mod electrical;
pub mod facts;
pub mod hydraulic;
pub mod hydraulic_relation;
pub mod least_squares;
pub mod lines;
pub mod mechanical;
pub mod mechanical_relation;
pub mod predictions;
#[cfg(test)]
mod release_tests;
pub mod report;
pub mod result;
pub mod selection;
pub mod signatures;
pub mod spectrum;
pub mod stick;
#[cfg(test)]
mod test_noise;

pub use diagnosis::{Cause, Diagnosis, Extended, Fit, Gain};

/// Why a log could not be diagnosed.
#[derive(Debug, thiserror::Error)]
pub enum DiagnoseError {
    /// The log breaks the bench-log contract.
    #[error(transparent)]
    Log(#[from] crate::bench_log::BenchLogError),
    /// The rig file is invalid.
    #[error("cannot diagnose on this rig: {0}")]
    Rig(#[from] plant_model::RigError),
}

pub use analysis::{analyse, diagnose, Analysis};

/// Goodness of fit in percent, 100·(1 − ‖y − ŷ‖₂ / ‖y − mean(y)‖₂), of `simulated` (ŷ)
/// against `measured` (y): 100 is a perfect match, 0 is no better than the measured mean,
/// and it is unbounded below.
///
/// `None` when it is undefined: the two differ in length, are empty, hold a non-finite
/// value, or `measured` is constant.
pub fn fit_percent(measured: &[f64], simulated: &[f64]) -> Option<f64> {
    if measured.len() != simulated.len() || measured.is_empty() {
        return None;
    }
    if measured.iter().chain(simulated).any(|v| !v.is_finite()) {
        return None;
    }
    let mean = measured.iter().sum::<f64>() / measured.len() as f64;
    let spread = measured
        .iter()
        .map(|y| (y - mean) * (y - mean))
        .sum::<f64>();
    if spread <= 0.0 {
        return None;
    }
    let error = measured
        .iter()
        .zip(simulated)
        .map(|(y, s)| (y - s) * (y - s))
        .sum::<f64>();
    Some(100.0 * (1.0 - (error / spread).sqrt()))
}

/// Residual, measured − simulated, row by row (the shorter length when they differ).
pub fn residual(measured: &[f64], simulated: &[f64]) -> Vec<f64> {
    measured.iter().zip(simulated).map(|(y, s)| y - s).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_of_a_perfect_match_is_100_and_of_the_mean_is_0() {
        let y = [1.0, 2.0, 4.0, 8.0];
        assert_eq!(fit_percent(&y, &y), Some(100.0));
        assert_eq!(fit_percent(&y, &[3.75; 4]), Some(0.0));
    }

    #[test]
    fn fit_follows_the_normalised_error_norm() {
        // y − mean = (−1, 1), ‖·‖ = √2; error (0.5, 0.5), ‖·‖ = √0.5: fit = 100·(1 − 1/2).
        let fit = fit_percent(&[1.0, 3.0], &[0.5, 2.5]).unwrap();
        assert!((fit - 50.0).abs() < 1e-12, "{fit}");
        // The mirror image about the mean errs by twice the spread: −100 %.
        let fit = fit_percent(&[1.0, 3.0], &[3.0, 1.0]).unwrap();
        assert!((fit + 100.0).abs() < 1e-12, "{fit}");
    }

    #[test]
    fn fit_is_undefined_for_constant_or_mismatched_data() {
        assert_eq!(fit_percent(&[2.0; 3], &[2.0; 3]), None);
        assert_eq!(fit_percent(&[1.0, 2.0], &[1.0]), None);
        assert_eq!(fit_percent(&[], &[]), None);
        assert_eq!(fit_percent(&[1.0, f64::NAN], &[1.0, 2.0]), None);
    }

    #[test]
    fn residual_is_measured_minus_simulated() {
        assert_eq!(residual(&[3.0, 1.0], &[1.0, 2.0]), vec![2.0, -1.0]);
    }
}
