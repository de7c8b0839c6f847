//! `eha tune` (issue 8): identify a loop's plant from a setpoint step in a bench log and
//! propose PI gains that meet a target.

use crate::cli::{CliError, TuneArgs};
use plant_model::Rig;

/// `eha tune`.
pub fn run_tune(_rig: &Rig, args: &TuneArgs) -> Result<(), CliError> {
    crate::bench_log::read(&args.log)?;
    Err(CliError::NotYetImplemented {
        command: "tune",
        issue: 8,
    })
}
