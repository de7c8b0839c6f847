//! The command line of `eha` (`shared/contracts/eha-cli.md`): the subcommands, the rig every
//! subcommand runs on (`--rig FILE` or the nominal rig), and the process's exit status.
//!
//! Each subcommand owns its arguments and its `run_*` function in its own module; this one
//! only routes. What they report through (errors, and their outputs as one transaction:
//! files, folders, JSON, standard output) is [`crate::output`]. Exit status: 0 on success, 2 for bad input or arguments (clap's usage
//! errors among them), 1 for anything else; the message goes to standard error. Nothing
//! panics.

use crate::commission::CommissionArgs;
use crate::compensate::CompensateArgs;
use crate::diagnose::command::DiagnoseArgs;
use crate::fleet::FleetArgs;
use crate::ingest::IngestArgs;
use crate::output::file_kind::describe;
use crate::output::paths::{self, Declared};
use crate::output::{interrupt, CliError};
use crate::rig_command::{self, RigArgs};
use crate::rig_file;
use crate::simulate::demo::DemoArgs;
use crate::simulate::SimulateArgs;
use crate::study::precharge_sweep::SweepPrechargeArgs;
use crate::study::AccumulatorDesignArgs;
use crate::tune::TuneArgs;
use crate::watch::WatchArgs;
use clap::{Parser, Subcommand};
use plant_model::Rig;
use std::io::{self, Write};
use std::path::PathBuf;
use std::process::ExitCode;

/// Desktop simulator of the EHA drive: the firmware's control code in closed loop against
/// the plant model, the paper's accumulator study, and bench-log tools.
#[derive(Debug, Parser)]
#[command(name = "eha", version, about, max_term_width = 100)]
pub struct Cli {
    /// Rig file (TOML, the format `eha rig` prints) replacing the nominal rig.
    #[arg(long, global = true, value_name = "FILE")]
    pub rig: Option<PathBuf>,
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Print the rig (nominal unless --rig) in the rig-file format.
    Rig(RigArgs),
    /// Closed-loop run of the paper's low-speed pressure holding: summary, plots, bench log.
    Demo(DemoArgs),
    /// Run a named scenario in closed loop and write it as a bench log.
    Simulate(SimulateArgs),
    /// The paper's precharge study (Section 5.2, Figure 12).
    SweepPrecharge(SweepPrechargeArgs),
    /// The paper's accumulator selection method (Section 4.3, eq. 26–32) on the rig.
    AccumulatorDesign(AccumulatorDesignArgs),
    /// Commissioning on the simulated motor: identify it and derive the current-loop gains.
    Commission(CommissionArgs),
    /// Identify a loop's plant from a setpoint step in a bench log and propose PI gains.
    Tune(TuneArgs),
    /// Turn defmt telemetry (as printed by the host decoder) into a bench log.
    Ingest(IngestArgs),
    /// Live view of the drive's telemetry (traces, mode, fault, pulsation); --out logs it.
    Watch(WatchArgs),
    /// Say what the simulation gets wrong on a bench log, and why.
    Diagnose(DiagnoseArgs),
    /// Learn the angle-indexed torque feed-forward from bench logs: table, CAN frames,
    /// predicted pulsation.
    Compensate(CompensateArgs),
    /// Diagnose many bench logs on all cores, resumably: one table, each drive's trends
    /// and the dates its parameters cross their limits.
    Fleet(FleetArgs),
}

/// Parses the process's arguments, runs, reports; the binary's whole `main`.
pub fn main() -> ExitCode {
    interrupt::install();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // Usage errors go to stderr with status 2; --help and --version to stdout, 0,
            // unless standard output cannot take them (a closed pipe is no error).
            let code = ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2));
            if e.use_stderr() {
                let text = crate::values::shorten_long_words(&e.render().to_string());
                let _ = write!(io::stderr(), "{text}");
            } else if let Err(why) = e.print().and_then(|()| io::stdout().flush()) {
                if why.kind() != io::ErrorKind::BrokenPipe {
                    let _ = writeln!(
                        io::stderr(),
                        "eha: error: cannot write standard output: {}",
                        describe(&why)
                    );
                    return ExitCode::FAILURE;
                }
            }
            return code;
        }
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // An error the interruption's clean-up caused is not the process's to report.
            interrupt::wait_if_interrupted();
            let _ = writeln!(io::stderr(), "eha: error: {e}");
            ExitCode::from(e.exit_status())
        }
    }
}

impl Command {
    /// The files the subcommand reads and writes.
    pub fn paths(&self) -> Declared<'_> {
        match self {
            Command::Rig(a) => a.paths(),
            Command::Demo(a) => a.paths(),
            Command::Simulate(a) => a.paths(),
            Command::SweepPrecharge(a) => a.paths(),
            Command::AccumulatorDesign(a) => a.paths(),
            Command::Commission(a) => a.paths(),
            Command::Tune(a) => a.paths(),
            Command::Ingest(a) => a.paths(),
            Command::Watch(a) => a.paths(),
            Command::Diagnose(a) => a.paths(),
            Command::Compensate(a) => a.paths(),
            Command::Fleet(a) => a.paths(),
        }
    }
}

/// Runs a parsed command line: every path checked first, then the rig loaded, then the
/// subcommand.
pub fn run(cli: Cli) -> Result<(), CliError> {
    paths::check(&cli.command.paths().input("--rig", cli.rig.as_ref()))?;
    let rig = match &cli.rig {
        Some(path) => rig_file::load(path)?,
        None => Rig::nominal(),
    };
    match &cli.command {
        Command::Rig(a) => rig_command::run_rig(&rig, a),
        Command::AccumulatorDesign(a) => crate::study::run_accumulator_design(&rig, a),
        Command::Demo(a) => crate::simulate::demo::run_demo(&rig, a),
        Command::Simulate(a) => crate::simulate::run_simulate(&rig, a),
        Command::SweepPrecharge(a) => crate::study::precharge_sweep::run_sweep_precharge(&rig, a),
        Command::Commission(a) => crate::commission::run_commission(&rig, a),
        Command::Tune(a) => crate::tune::run_tune(&rig, a),
        Command::Ingest(a) => crate::ingest::run_ingest(a),
        Command::Watch(a) => crate::watch::run_watch(&rig, a),
        Command::Diagnose(a) => crate::diagnose::command::run_diagnose(&rig, a),
        Command::Compensate(a) => crate::compensate::run_compensate(&rig, a),
        Command::Fleet(a) => crate::fleet::run_fleet(&rig, cli.rig.as_deref(), a),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn clap_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn sweep_defaults_are_the_papers_precharges() {
        let cli = Cli::try_parse_from(["eha", "sweep-precharge"]).unwrap();
        match cli.command {
            Command::SweepPrecharge(a) => assert_eq!(a.values, [2e6, 4e6, 5e6, 10e6, 13e6]),
            c => panic!("{c:?}"),
        }
    }

    #[test]
    fn simulate_needs_scenario_and_out_unless_listing() {
        assert!(Cli::try_parse_from(["eha", "simulate", "--list"]).is_ok());
        assert!(Cli::try_parse_from(["eha", "simulate", "--scenario", "x"]).is_err());
        assert!(
            Cli::try_parse_from(["eha", "simulate", "--scenario", "x", "--out", "a.csv"]).is_ok()
        );
    }
}
