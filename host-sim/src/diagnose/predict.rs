//! The diagnosis's three subsystem predictors, one interface: given a rig (the nominal one
//! or one with a candidate effect switched on), the signals each replay predicts for the
//! log's first rows.
//!
//! - [`Predictor::Hydraulics`] ([`super::replay`]): the pressure `p_pa` from the logged shaft
//!   angle; the piston simulated under its load when the log shows it moving (so cylinder
//!   friction reaches the pressure), blocked when it does not move or is not logged.
//! - [`Predictor::Motor`]: the shaft speed `speed_rad_s` from the logged currents, and the
//!   q current `iq_a` the model needed to follow the logged shaft motion.
//! - [`Predictor::Electrical`] ([`super::electrical`]): the commanded `ud_v`, `uq_v`.

use super::electrical::replay_electrical;
use super::replay::{replay_with, ReplayError, ReplayKind, ReplayOptions};
use crate::bench_log::BenchLog;
use plant_model::Rig;

/// Piston travel above which the log shows the piston moving (well above the position
/// noise of a rig's linear transducer, well below the slowest stroke's travel). [m]
pub const MOVING_PISTON_TRAVEL_M: f64 = 0.2e-3;

/// Which subsystem replay predicts a signal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Predictor {
    /// Pressure from the shaft angle.
    Hydraulics,
    /// Shaft speed from the currents.
    Motor,
    /// Commanded voltages from the currents and the speed.
    Electrical,
}

impl Predictor {
    /// The logged signals it predicts, by bench-log column name.
    pub fn signals(self) -> &'static [&'static str] {
        match self {
            Predictor::Hydraulics => &["p_pa"],
            Predictor::Motor => &["speed_rad_s", "iq_a"],
            Predictor::Electrical => &["ud_v", "uq_v"],
        }
    }

    /// What drives it, for the report.
    pub fn describe(self) -> &'static str {
        match self {
            Predictor::Hydraulics => "hydraulics driven by the logged shaft angle",
            Predictor::Motor => "motor and shaft driven by the logged currents",
            Predictor::Electrical => "stator voltages from the logged currents and speed",
        }
    }
}

/// Whether the log shows the piston moving.
pub fn piston_moves(log: &BenchLog) -> bool {
    log.x_m.as_deref().is_some_and(|x| {
        let (lo, hi) = x
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                (l.min(*v), h.max(*v))
            });
        hi - lo > MOVING_PISTON_TRAVEL_M
    })
}

/// Predicted signals of one predictor, aligned with the log's first rows.
pub type Predicted = Vec<(&'static str, Vec<f64>)>;

/// Runs `predictor` on the first `rows` rows of `log` with `rig`; `phase_a_offset_a` is a
/// current-sensor offset the motor replay assumes in the log.
pub fn predict(
    log: &BenchLog,
    rig: &Rig,
    predictor: Predictor,
    rows: usize,
    phase_a_offset_a: f64,
) -> Result<Predicted, ReplayError> {
    Ok(match predictor {
        Predictor::Hydraulics => {
            let options = ReplayOptions {
                rows,
                piston_free: piston_moves(log),
                phase_a_offset_a: 0.0,
            };
            let r = replay_with(log, rig, ReplayKind::Hydraulics, &options)?;
            vec![("p_pa", r.p_pa)]
        }
        Predictor::Motor => {
            let options = ReplayOptions {
                rows,
                piston_free: false,
                phase_a_offset_a,
            };
            let r = replay_with(log, rig, ReplayKind::Motor, &options)?;
            vec![("speed_rad_s", r.speed_rad_s), ("iq_a", r.iq_needed_a)]
        }
        Predictor::Electrical => match replay_electrical(log, rig, rows) {
            Some(e) => vec![("ud_v", e.ud_v), ("uq_v", e.uq_v)],
            None => Vec::new(),
        },
    })
}
