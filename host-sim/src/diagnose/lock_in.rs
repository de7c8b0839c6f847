//! The amplitude of the pump's torque ripple (eq. 20) re-estimated by lock-in regression
//! after the simplex. In holding its q-current line is below the current's noise per
//! sample, and the replay's own quantisation makes the identification cost wander by as
//! much as the amplitude moves it: the simplex stops anywhere in a ±25 % valley. The
//! replay's response to the ripple is linear in its amplitude, and both it and the ripple
//! in the log are periodic in the logged angle while the noise and the quantisation's
//! wander are not: projected on the ripple's orders, the measured residual over the
//! replay's response is the amplitude ratio — the least-squares estimate of a known
//! waveform's scale in noise.

use super::candidates::{Candidate, Structure};
use super::fit::{CandidateFit, Target};
use super::predict::{predict, Predictor};
use super::replay::unwrap_angle;
use plant_model::pump::ripple_order;

/// Harmonics of the ripple's fundamental order the projection keeps. [1]
pub const HARMONICS: u32 = 4;

/// `f` with the ripple's amplitude from the lock-in regression on the q current over the
/// target's rows, when `f` is a piston ripple on the inner loops and the regression is
/// defined; `f` unchanged otherwise.
pub fn refine_ripple_amplitude(target: &Target<'_>, f: CandidateFit) -> CandidateFit {
    let z = match (&f.candidate, f.candidate.structure) {
        (
            Candidate {
                name: "piston_ripple",
                predictor: Predictor::InnerLoops,
                ..
            },
            Structure::Pistons(z),
        ) => z,
        _ => return f,
    };
    let Some(ratio) = amplitude_ratio(target, &f, z) else {
        return f;
    };
    let mut u = f.u.clone();
    u[0] += ratio.ln();
    let cost = target.cost(&f.candidate, &u);
    // The cost only ranks the candidate; an implausible amplitude keeps the simplex's.
    if !cost.is_finite() || cost == f64::MAX {
        return f;
    }
    CandidateFit { u, cost, ..f }
}

/// The measured ripple over the one the replay answers at the fitted point: the scale to
/// apply to the fitted amplitude; `None` when the log lacks the angle, the replay fails or
/// the projection is empty or of the wrong sign.
fn amplitude_ratio(target: &Target<'_>, f: &CandidateFit, z: u32) -> Option<f64> {
    let log = target.log;
    let theta = unwrap_angle(log.theta_m_rad.as_deref()?);
    let with = f.candidate.rig_at(&f.u, target.rig);
    let mut without = with.clone();
    without.pump.piston_ripple = false;
    let iq = |rig| -> Option<Vec<f64>> {
        let p = predict(log, rig, Predictor::InnerLoops, target.rows, 0.0).ok()?;
        p.into_iter().find(|(n, _)| *n == "iq_a").map(|(_, y)| y)
    };
    let (iq_with, iq_without) = (iq(&with)?, iq(&without)?);
    let rows: Vec<usize> = (target.from..target.rows.min(log.len()))
        .filter(|&k| k < iq_with.len() && k < iq_without.len())
        .collect();
    let order = f64::from(ripple_order(z));
    let basis = nalgebra::DMatrix::from_fn(rows.len(), 2 * HARMONICS as usize, |r, c| {
        let phase = order * f64::from(c as u32 / 2 + 1) * theta[rows[r]];
        if c % 2 == 0 {
            phase.cos()
        } else {
            phase.sin()
        }
    });
    let response = nalgebra::DVector::from_iterator(
        rows.len(),
        rows.iter().map(|&k| iq_with[k] - iq_without[k]),
    );
    let coefficients = basis.clone().svd(true, true).solve(&response, 1e-12).ok()?;
    let response = &basis * coefficients;
    let residual = nalgebra::DVector::from_iterator(
        rows.len(),
        rows.iter().map(|&k| log.iq_a[k] - iq_without[k]),
    );
    // ⟨P r, P Δ⟩ = ⟨r, P Δ⟩: the residual's projection is implicit.
    let ratio = residual.dot(&response) / response.norm_squared();
    (ratio.is_finite() && ratio > 0.0).then_some(ratio)
}
