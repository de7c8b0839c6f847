//! Placeholder for the closed-loop runs (issue 4): the signatures `cli` routes to. The lead
//! replaces this file with the real harness.

use crate::cli::{CliError, DemoArgs, SimulateArgs, SweepPrechargeArgs};
use plant_model::Rig;

/// `eha demo`.
pub fn run_demo(_rig: &Rig, _args: &DemoArgs) -> Result<(), CliError> {
    Err(CliError::NotYetImplemented {
        command: "demo",
        issue: 4,
    })
}

/// `eha simulate`.
pub fn run_simulate(_rig: &Rig, _args: &SimulateArgs) -> Result<(), CliError> {
    Err(CliError::NotYetImplemented {
        command: "simulate",
        issue: 4,
    })
}

/// `eha sweep-precharge`.
pub fn run_sweep_precharge(_rig: &Rig, _args: &SweepPrechargeArgs) -> Result<(), CliError> {
    Err(CliError::NotYetImplemented {
        command: "sweep-precharge",
        issue: 4,
    })
}
