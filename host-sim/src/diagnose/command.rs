//! `eha diagnose` (issue 5): the command around the diagnosis.

use crate::cli::{CliError, DiagnoseArgs};
use plant_model::Rig;

/// `eha diagnose`.
pub fn run_diagnose(_rig: &Rig, args: &DiagnoseArgs) -> Result<(), CliError> {
    crate::bench_log::read(&args.log)?;
    Err(CliError::NotYetImplemented {
        command: "diagnose",
        issue: 5,
    })
}
