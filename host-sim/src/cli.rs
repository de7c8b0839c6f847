//! The command line of `eha` (`shared/contracts/eha-cli.md`): the subcommands and their
//! flags, the rig every subcommand runs on (`--rig FILE` or the nominal rig), JSON output
//! (`--json PATH`, `-` for standard output, files written atomically) and error reporting.
//!
//! Exit status: 0 on success, 2 for bad input or arguments (clap's usage errors, a bad rig
//! file, a bad bench log, a value out of range), 1 for anything else (a file that cannot be
//! written, a feature not built yet); the message goes to standard error. Nothing panics.
//!
//! Subcommands are routed in [`run`]; `rig` and `accumulator-design` are implemented here,
//! the closed-loop ones in [`crate::simulate`], `ingest` in [`crate::ingest`], `commission`
//! and `tune` in [`crate::commission`] and [`crate::tune`], `diagnose` in
//! [`crate::diagnose::command`].

use crate::bench_log::BenchLogError;
use crate::rig_file::{self, RigFileError};
use crate::study::accumulator_design;
use clap::{Args, Parser, Subcommand, ValueEnum};
use plant_model::effects::EFFECT_NAMES;
use plant_model::{Effect, Rig};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
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
    /// Say what the simulation gets wrong on a bench log, and why.
    Diagnose(DiagnoseArgs),
}

/// `eha rig`.
#[derive(Debug, Args)]
pub struct RigArgs {
    /// Also write the rig as JSON (`-`: standard output, instead of the TOML).
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
}

/// `eha demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Output folder for plots and the bench log.
    #[arg(long, value_name = "DIR", default_value = "eha-out")]
    pub out: PathBuf,
}

/// `eha simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Scenario name (`--list` names them).
    #[arg(long, value_name = "NAME", required_unless_present = "list")]
    pub scenario: Option<String>,
    /// Bench log to write.
    #[arg(long, value_name = "LOG.csv", required_unless_present = "list")]
    pub out: Option<PathBuf>,
    /// Absorber precharge (gauge), replacing the rig's. [Pa]
    #[arg(long, value_name = "PA", value_parser = positive_f64)]
    pub precharge: Option<f64>,
    /// Rig file of the simulated actuator when it is not the one the controller is
    /// configured from (`--rig`, `--precharge`): a bench whose absorber or shaft differs
    /// from what the engineer believes, as `eha tune` corrects.
    #[arg(long, value_name = "FILE")]
    pub plant_rig: Option<PathBuf>,
    /// Simulated duration, replacing the scenario's. [s]
    #[arg(long, value_name = "S", value_parser = positive_f64)]
    pub duration: Option<f64>,
    /// Effects to switch on: names from effects.md, each optionally with parameters,
    /// e.g. `piston_ripple,cogging_torque:amplitude_nm=0.05,order=72`.
    #[arg(long, value_name = "LIST", value_parser = parse_effect_list)]
    pub effects: Option<EffectList>,
    /// Seed of the sensor noise.
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
    /// Log rate (a divisor of the 20 kHz PWM rate is logged exactly; typical bench logs
    /// are 1 kHz). [Hz]
    #[arg(long, value_name = "HZ", default_value = "2000", value_parser = log_rate)]
    pub log_rate: f64,
    /// Name the scenarios and exit.
    #[arg(long)]
    pub list: bool,
    /// Write a run summary as JSON, with the real-time factor (`-`: standard output).
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
}

/// A log rate: positive and at most the 20 kHz PWM rate the telemetry is sampled at. [Hz]
fn log_rate(s: &str) -> Result<f64, String> {
    let v = positive_f64(s)?;
    if v > 20_000.0 {
        return Err(format!("{v} Hz is above the 20000 Hz telemetry rate"));
    }
    Ok(v)
}

/// `eha sweep-precharge`.
#[derive(Debug, Args)]
pub struct SweepPrechargeArgs {
    /// Precharges (gauge) to run. [Pa]
    #[arg(
        long,
        value_name = "PA,PA,…",
        value_delimiter = ',',
        default_value = "2e6,4e6,5e6,10e6,13e6",
        value_parser = positive_f64
    )]
    pub values: Vec<f64>,
    /// Write the results as JSON (`-`: standard output).
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// Folder for plots and the runs' bench logs.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

/// `eha accumulator-design`.
#[derive(Debug, Args)]
pub struct AccumulatorDesignArgs {
    /// Write the results as JSON (`-`: standard output, instead of the table).
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// Working (holding) pressure, gauge: the paper's low-speed pressure-holding case. [Pa]
    #[arg(long, value_name = "PA", default_value = "5e6", value_parser = positive_f64)]
    pub pressure: f64,
}

/// `eha commission`.
#[derive(Debug, Args)]
pub struct CommissionArgs {
    /// Current-loop bandwidth to design for. [rad/s]
    #[arg(long, value_name = "RAD_S", default_value = "1100", value_parser = positive_f64)]
    pub bandwidth: f64,
    /// Write the results as JSON (`-`: standard output).
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
}

/// Which loop `eha tune` identifies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LoopKind {
    /// Speed loop (speed reference step).
    Speed,
    /// Pressure loop (pressure setpoint step).
    Pressure,
}

/// `eha tune`.
#[derive(Debug, Args)]
pub struct TuneArgs {
    /// Bench log with a setpoint step.
    #[arg(value_name = "LOG.csv")]
    pub log: PathBuf,
    /// The loop to tune.
    #[arg(long = "loop", value_enum)]
    pub loop_kind: LoopKind,
    /// Overshoot target. [%]
    #[arg(long, value_name = "PCT", value_parser = non_negative_f64)]
    pub overshoot: Option<f64>,
    /// Settling-time target. [s]
    #[arg(long, value_name = "S", value_parser = positive_f64)]
    pub settling: Option<f64>,
    /// Write the results as JSON (`-`: standard output).
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
}

/// `eha ingest`.
#[derive(Debug, Args)]
pub struct IngestArgs {
    /// The decoder's output (`probe-rs run` or `defmt-print`).
    #[arg(value_name = "DEFMT_LOG")]
    pub defmt_log: PathBuf,
    /// Bench log to write.
    #[arg(long, value_name = "LOG.csv")]
    pub out: PathBuf,
}

/// `eha diagnose`.
#[derive(Debug, Args)]
pub struct DiagnoseArgs {
    /// Bench log to explain.
    #[arg(value_name = "LOG.csv")]
    pub log: PathBuf,
    /// Write the results as JSON (`-`: standard output).
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// Folder for the report (plots and text).
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
}

/// The parsed `--effects` list.
#[derive(Clone, Debug, PartialEq)]
pub struct EffectList(pub Vec<Effect>);

/// Why `eha` failed.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// A bench log that cannot be read (bad input) or written.
    #[error(transparent)]
    BenchLog(#[from] BenchLogError),
    /// A rig file that cannot be used.
    #[error(transparent)]
    RigFile(#[from] RigFileError),
    /// An argument or input value that makes no sense.
    #[error("{0}")]
    BadInput(String),
    /// An output file that cannot be written.
    #[error("cannot write `{}`: {source}", file.display())]
    Write {
        /// The file.
        file: PathBuf,
        /// Why.
        source: io::Error,
    },
    /// A subcommand whose implementation has not landed yet.
    #[error("`eha {command}` is not implemented yet: issue {issue} brings it")]
    NotYetImplemented {
        /// The subcommand.
        command: &'static str,
        /// The issue that implements it.
        issue: u32,
    },
    /// Any other failure.
    #[error("{0}")]
    Failed(String),
}

impl CliError {
    /// Exit status: 2 for bad input or arguments, 1 for anything else.
    pub fn exit_status(&self) -> u8 {
        match self {
            CliError::BenchLog(e) if e.is_bad_input() => 2,
            CliError::RigFile(_) | CliError::BadInput(_) => 2,
            _ => 1,
        }
    }
}

/// Parses the process's arguments, runs, reports; the binary's whole `main`.
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // Usage errors go to stderr with status 2; --help and --version to stdout, 0.
            let _ = e.print();
            return ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2));
        }
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(io::stderr(), "eha: error: {e}");
            ExitCode::from(e.exit_status())
        }
    }
}

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<(), CliError> {
    let rig = match &cli.rig {
        Some(path) => rig_file::load(path)?,
        None => Rig::nominal(),
    };
    match &cli.command {
        Command::Rig(a) => run_rig(&rig, a),
        Command::AccumulatorDesign(a) => run_accumulator_design(&rig, a),
        Command::Demo(a) => crate::simulate::run_demo(&rig, a),
        Command::Simulate(a) => crate::simulate::run_simulate(&rig, a),
        Command::SweepPrecharge(a) => crate::simulate::run_sweep_precharge(&rig, a),
        Command::Commission(a) => crate::commission::run_commission(&rig, a),
        Command::Tune(a) => crate::tune::run_tune(&rig, a),
        Command::Ingest(a) => crate::ingest::run_ingest(a),
        Command::Diagnose(a) => crate::diagnose::command::run_diagnose(&rig, a),
    }
}

/// `eha rig`: the TOML on standard output; with `--json PATH` the JSON too (with `--json -`
/// only the JSON, so standard output stays one parseable document).
fn run_rig(rig: &Rig, a: &RigArgs) -> Result<(), CliError> {
    if let Some(path) = &a.json {
        let value = serde_json::to_value(rig).map_err(|e| CliError::Failed(e.to_string()))?;
        write_json(path, &value)?;
        if is_stdout(path) {
            return Ok(());
        }
    }
    print_stdout(&rig_file::to_toml(rig))
}

/// `eha accumulator-design`: a table on standard output, JSON with `--json`.
fn run_accumulator_design(rig: &Rig, a: &AccumulatorDesignArgs) -> Result<(), CliError> {
    let design = accumulator_design::design(rig, a.pressure)
        .map_err(|e| CliError::BadInput(e.to_string()))?;
    if let Some(path) = &a.json {
        let value = serde_json::to_value(&design).map_err(|e| CliError::Failed(e.to_string()))?;
        write_json(path, &value)?;
        if is_stdout(path) {
            return Ok(());
        }
    }
    print_stdout(&design.to_table())
}

/// `-` means standard output.
pub fn is_stdout(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// Writes one JSON object, pretty-printed, to `path` atomically or to standard output.
pub fn write_json(path: &Path, value: &serde_json::Value) -> Result<(), CliError> {
    let mut text =
        serde_json::to_string_pretty(value).map_err(|e| CliError::Failed(e.to_string()))?;
    text.push('\n');
    if is_stdout(path) {
        print_stdout(&text)
    } else {
        crate::atomic_file::write(path, text.as_bytes()).map_err(|source| CliError::Write {
            file: path.to_path_buf(),
            source,
        })
    }
}

/// Writes `text` to standard output; a closed pipe (`eha rig | head`) is not an error.
pub fn print_stdout(text: &str) -> Result<(), CliError> {
    let mut out = io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != io::ErrorKind::BrokenPipe => Err(CliError::Write {
            file: PathBuf::from("<standard output>"),
            source: e,
        }),
        _ => Ok(()),
    }
}

fn positive_f64(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(_) => Err(format!("`{s}` must be a positive finite number")),
        Err(_) => Err(format!("`{s}` is not a number")),
    }
}

fn non_negative_f64(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        Ok(_) => Err(format!("`{s}` must be a finite number, not negative")),
        Err(_) => Err(format!("`{s}` is not a number")),
    }
}

/// Parses `name[:param=value,param=value…][,name…]`: a comma-separated token holding `=`
/// but no `:` continues the previous effect's parameters, any other token starts an
/// effect (effect names never contain `=`).
pub fn parse_effect_list(list: &str) -> Result<EffectList, String> {
    let mut specs: Vec<String> = Vec::new();
    for token in list.split(',').map(str::trim).filter(|t| !t.is_empty()) {
        match specs.last_mut() {
            Some(spec) if token.contains('=') && !token.contains(':') => {
                spec.push(',');
                spec.push_str(token);
            }
            _ => specs.push(token.to_string()),
        }
    }
    if specs.is_empty() {
        return Err("no effect named".into());
    }
    specs
        .iter()
        .map(|spec| {
            Effect::parse(spec).map_err(|e| {
                format!(
                    "effect `{spec}`: {e} (effects: {})",
                    EFFECT_NAMES.join(", ")
                )
            })
        })
        .collect::<Result<Vec<_>, _>>()
        .map(EffectList)
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
    fn effect_lists_group_parameters_with_their_effect() {
        let l =
            parse_effect_list("piston_ripple,cogging_torque:amplitude_nm=0.05,order=72,dead_time")
                .unwrap();
        assert_eq!(l.0.len(), 3);
        assert_eq!(l.0[0].name(), "piston_ripple");
        assert_eq!(
            l.0[1],
            Effect::CoggingTorque {
                amplitude_nm: 0.05,
                order: 72,
                phase_rad: 0.0
            }
        );
        assert_eq!(l.0[2].name(), "dead_time");
        let e = parse_effect_list("cogging_torque:amplitude=1").unwrap_err();
        assert!(e.contains("cogging_torque:amplitude=1"), "{e}");
        assert!(parse_effect_list("warp_drive")
            .unwrap_err()
            .contains("warp_drive"));
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
