//! `eha commission` (issue 8): the firmware's commissioning sequence in closed loop on the
//! rig's simulated motor, identified vs true values and the derived current-loop gains.

use crate::cli::{CliError, CommissionArgs};
use plant_model::Rig;

/// `eha commission`.
pub fn run_commission(_rig: &Rig, _args: &CommissionArgs) -> Result<(), CliError> {
    Err(CliError::NotYetImplemented {
        command: "commission",
        issue: 8,
    })
}
