//! The controller façade: one call per PWM period ([`Controller::on_current_sample`]) runs
//! the current loop, the speed and pressure loops at their divided rates, the calibration
//! sequence and the supervisor checks; [`Controller::command`] takes the commands.
//!
//! Order inside one call: encoder decode and speed observer → pressure loop (on its tick) → speed loop (on its
//! tick) → current loop → fault conditions → supervisor. A fault found in a call returns
//! disabled PWM from that same call.
//!
//! Start-up: in Disabled, with the bridge off, the first `calibration.offset_time_s` of
//! samples measure the phase-current offsets; no active mode is granted before
//! ([`crate::supervisor::Readiness`]). The encoder offset is the table's
//! `sensors.encoder_offset_rad`, relative to the index: on an incremental counter Speed
//! and Pressure wait until the index has been seen (or Calibrating has aligned the rotor)
//! in this power cycle. A configuration for a counter referenced from the start and
//! trusted offsets (`sensors.encoder_referenced_at_start`, `calibration.offsets_at_boot`
//! off: the simulator's) may enter Speed and Pressure straight from Disabled. Calibrating
//! measures both offsets again and replaces them; it ends in Disabled.
//!
//! Parameters ([`Command::SetParameter`]) and step tests ([`Command::StepTest`]) are
//! applied inside [`Controller::command`], which never runs during a control step: on the
//! target the command path and the current-loop interrupt share one critical-section
//! mutex, on the host they are sequential calls. A change therefore takes effect at the
//! start of the next step, with no pending-change buffer to keep; gains move bumplessly
//! ([`crate::pi::Pi::set_gains`]: the integral absorbs the change of the proportional term).
//!
//! Entering Pressure holds the measured pressure until a pressure setpoint is commanded;
//! the pressure loop starts bumplessly from the present speed reference. Entering Speed
//! uses the last commanded speed setpoint (0 if none).
mod apply;
mod calibrate;
mod calibration_state;
pub mod command;
mod commission;
mod compensate;
pub mod drive;
mod status;
#[cfg(test)]
mod tests;

pub use command::{Command, CommandError};
pub use drive::Controller;
