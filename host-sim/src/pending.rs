//! Placeholder for the subcommands of other issues: commissioning and tuning (issue 8),
//! diagnosis (issue 5). Each moves to its own module when its issue lands.
//! Those that take a bench log read and check it first, so a bad log is reported (exit 2)
//! already, before the missing feature is.

use crate::cli::{CliError, CommissionArgs, DiagnoseArgs, TuneArgs};
use plant_model::Rig;

/// `eha commission`.
pub fn run_commission(_rig: &Rig, _args: &CommissionArgs) -> Result<(), CliError> {
    Err(CliError::NotYetImplemented {
        command: "commission",
        issue: 8,
    })
}

/// `eha tune`.
pub fn run_tune(_rig: &Rig, args: &TuneArgs) -> Result<(), CliError> {
    crate::bench_log::read(&args.log)?;
    Err(CliError::NotYetImplemented {
        command: "tune",
        issue: 8,
    })
}

/// `eha diagnose`.
pub fn run_diagnose(_rig: &Rig, args: &DiagnoseArgs) -> Result<(), CliError> {
    crate::bench_log::read(&args.log)?;
    Err(CliError::NotYetImplemented {
        command: "diagnose",
        issue: 5,
    })
}
