//! The diagnosis's three subsystem predictors, one interface: given a rig (the nominal one
//! or one with a candidate effect switched on), the signals each replay predicts for the
//! log's first rows.
//!
//! - [`Predictor::Hydraulics`] ([`super::replay`]): the pressure `p_pa` from the logged shaft
//!   angle and piston position: every volume the pump and the piston displace is the
//!   logged one, so what remains is the oil's and the absorber's compliance, the leakage and
//!   the transducer.
//! - [`Predictor::Cylinder`]: the same with the piston simulated under its load from the
//!   logged start (only when the log shows it moving), so that the cylinder's friction
//!   reaches the pressure. The payload on its oil spring is a resonance at some 40 Hz with
//!   almost no damping, whose phase a simulation loses within a second at a few percent of
//!   stiffness error: every other hydraulic effect is fitted on the prescribed piston, where
//!   it shows without that noise.
//! - [`Predictor::Motor`]: the shaft speed `speed_rad_s` from the logged currents, and the
//!   q current `iq_a` the model needed to follow the logged shaft motion.
//! - [`Predictor::InnerLoops`] ([`super::closed_replay`]): speed and q current of the
//!   speed and current loops replayed on the logged speed reference (in pressure control,
//!   the pressure loop's output), the shaft phase-locked to the logged angle and the
//!   cogging torque applied at the logged angle. Angle-locked torque ripple (cogging, flux
//!   harmonics, a current offset's first harmonic) is fitted here: the speed loop's answer
//!   to it is what the log shows, and only the loop itself predicts that answer's amplitude
//!   and phase; the motor replay, driven by the logged current sampled at 1 kHz, sees a
//!   65 Hz ripple with a timing error of a fraction of a sample, i.e. tenths of a radian.
//! - [`Predictor::PressureLoop`] ([`super::closed_replay::replay_pressure_hold`]): the pump
//!   speed of the whole loop holding the log's final pressure hold, replayed from that
//!   hold's start (pressure control only). In a hold the pump turns just fast enough to
//!   replace the leakage, so the speed the pressure loop settles at measures the leakage
//!   directly; the hydraulic replay sees the same leakage only through a pressure drift
//!   over the absorber's compliance, a time constant of tens of seconds, and in a fill only
//!   as a few percent of the flow, which the rig's tolerances mimic.
//! - [`Predictor::Electrical`] ([`super::electrical`]): the commanded `ud_v`, `uq_v`.

use super::closed_replay::{replay_closed_loop_rows, replay_pressure_hold, Reference};
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
    /// Pressure from the shaft angle and the piston position.
    Hydraulics,
    /// Pressure from the shaft angle, the piston simulated under its load.
    Cylinder,
    /// Shaft speed from the currents.
    Motor,
    /// Commanded voltages from the currents and the speed.
    Electrical,
    /// Speed and current of the speed and current loops from the logged speed reference.
    InnerLoops,
    /// Pump speed of the whole loop holding the log's final pressure hold.
    PressureLoop,
}

impl Predictor {
    /// The logged signals it predicts, by bench-log column name.
    pub fn signals(self) -> &'static [&'static str] {
        match self {
            Predictor::Hydraulics | Predictor::Cylinder => &["p_pa"],
            Predictor::Motor | Predictor::InnerLoops => &["speed_rad_s", "iq_a"],
            Predictor::PressureLoop => &["speed_rad_s"],
            Predictor::Electrical => &["ud_v", "uq_v"],
        }
    }

    /// What drives it, for the report.
    pub fn describe(self) -> &'static str {
        match self {
            Predictor::Hydraulics => {
                "hydraulics driven by the logged shaft angle and piston position"
            }
            Predictor::Cylinder => "hydraulics driven by the logged shaft angle, payload simulated",
            Predictor::Motor => "motor and shaft driven by the logged currents",
            Predictor::Electrical => "stator voltages from the logged currents and speed",
            Predictor::PressureLoop => "the whole loop replayed over the final pressure hold",
            Predictor::InnerLoops => {
                "speed and current loops replayed on the logged speed reference"
            }
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
        Predictor::Hydraulics | Predictor::Cylinder => {
            let options = ReplayOptions {
                rows,
                piston_free: predictor == Predictor::Cylinder && piston_moves(log),
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
        Predictor::InnerLoops => {
            match replay_closed_loop_rows(log, rig, rows, Reference::SpeedReference) {
                Some(c) => vec![("speed_rad_s", c.speed_rad_s), ("iq_a", c.iq_a)],
                None => Vec::new(),
            }
        }
        Predictor::PressureLoop => match replay_pressure_hold(log, rig, rows) {
            Some(speed) => vec![("speed_rad_s", speed)],
            None => Vec::new(),
        },
        Predictor::Electrical => match replay_electrical(log, rig, rows) {
            Some(e) => vec![("ud_v", e.ud_v), ("uq_v", e.uq_v)],
            None => Vec::new(),
        },
    })
}
