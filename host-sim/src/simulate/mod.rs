//! The closed-loop runs: `eha simulate` (a named scenario to a bench log) here, `eha demo`
//! in [`demo`], and the low-speed holding run both the demo and the precharge sweep
//! (`crate::study::precharge_sweep`) measure, in [`holding`].

pub mod demo;
pub mod holding;

use crate::bench_log::{self, MIN_ROWS};
use crate::feedforward::Feedforward;
use crate::output::paths::Declared;
use crate::output::{CliError, Outputs};
use crate::rig_file;
use crate::run::{first_unphysical, log_plan, most_rows, run, Run, RunOptions, LOGGED_COLUMNS};
use crate::values::{positive_f64, show};
use clap::Args;
use closed_loop::{by_name, Scenario, PROCEDURES, SCENARIOS};
use plant_model::effects::{EffectError, EFFECT_NAMES};
use plant_model::{Effect, Integrator, Rig};
use serde_json::json;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

pub use crate::run::LOG_RATE_HZ;

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
    #[arg(long, value_name = "PA", value_parser = positive_f64, allow_negative_numbers = true)]
    pub precharge: Option<f64>,
    /// Rig file of the simulated actuator when it is not the one the controller is
    /// configured from (`--rig`, `--precharge`): a bench whose absorber or shaft differs
    /// from what the engineer believes, as `eha tune` corrects.
    #[arg(long, value_name = "FILE")]
    pub plant_rig: Option<PathBuf>,
    /// Simulated duration, replacing the scenario's. [s]
    #[arg(long, value_name = "S", value_parser = positive_f64, allow_negative_numbers = true)]
    pub duration: Option<f64>,
    /// Effects to switch on: names from effects.md, each optionally with parameters,
    /// e.g. `piston_ripple,cogging_torque:amplitude_nm=0.05,order=72`.
    #[arg(long, value_name = "LIST", value_parser = parse_effect_list)]
    pub effects: Option<EffectList>,
    /// Seed of the sensor noise.
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
    /// A torque feed-forward table written by `eha compensate`, loaded into the
    /// controller and enabled before the run, as the drive loads it from flash.
    #[arg(long, value_name = "TABLE")]
    pub compensation: Option<PathBuf>,
    /// Log rate (a divisor of the 20 kHz PWM rate is logged exactly; typical bench logs
    /// are 1 kHz). [Hz]
    #[arg(long, value_name = "HZ", default_value = "2000", value_parser = log_rate, allow_negative_numbers = true)]
    pub log_rate: f64,
    /// The actuator the log is of, written as the log's `# drive:` line (what `eha fleet`
    /// groups logs by).
    #[arg(long, value_name = "ID", value_parser = drive_id)]
    pub drive: Option<String>,
    /// When the log started, RFC 3339 (`2026-11-30T14:05:00Z`), written as the log's
    /// `# recorded_at:` line (what `eha fleet` trends over).
    #[arg(long, value_name = "TIME", value_parser = crate::timestamp::rfc3339_arg)]
    pub recorded_at: Option<String>,
    /// Name the scenarios and exit.
    #[arg(long)]
    pub list: bool,
    /// Write a run summary as JSON, with the real-time factor (`-`: standard output).
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// The plant's integration scheme: `exponential` (the default: exact winding and
    /// hydraulic blocks, third-order exponential Adams–Bashforth), `rk4` (classical
    /// Runge–Kutta at the PWM period, the scheme before it) or `rk4-quarter` (at a quarter of
    /// the period, the accuracy reference).
    #[arg(long, value_name = "NAME", default_value = "exponential", value_parser = integrator)]
    pub integrator: Integrator,
    /// Also run the same simulation with this scheme (not logged) and report both real-time
    /// factors and their ratio (per second of the thread's CPU time, so that other work on
    /// the machine does not bias it), measured in this process (`--json`'s `compared`).
    #[arg(long, value_name = "NAME", value_parser = integrator)]
    pub compare_integrator: Option<Integrator>,
}

/// An integration scheme by name.
fn integrator(s: &str) -> Result<Integrator, String> {
    Integrator::from_name(s).ok_or_else(|| {
        let names: Vec<&str> = Integrator::NAMES.iter().map(|(n, _)| *n).collect();
        format!(
            "unknown integrator `{s}`: the integrators are {}",
            names.join(", ")
        )
    })
}

/// A log rate: positive and at most the 20 kHz PWM rate the telemetry is sampled at. [Hz]
fn log_rate(s: &str) -> Result<f64, String> {
    let v = positive_f64(s)?;
    if v > 20_000.0 {
        return Err(format!("{v} Hz is above the 20000 Hz telemetry rate"));
    }
    Ok(v)
}

/// A drive's name as a metadata value: not empty, on one line, no surrounding blanks.
pub fn drive_id(s: &str) -> Result<String, String> {
    let t = s.trim();
    if t.is_empty() {
        return Err("a drive needs a name".into());
    }
    if t.contains(['\n', '\r']) {
        return Err(format!(
            "`{}`: a drive's name must be on one line",
            crate::bench_log::limits::excerpt(s)
        ));
    }
    Ok(t.to_string())
}

impl SimulateArgs {
    /// The files it reads and writes.
    pub fn paths(&self) -> Declared<'_> {
        Declared::default()
            .input("--plant-rig", self.plant_rig.as_ref())
            .input("--compensation", self.compensation.as_ref())
            .file("--out", self.out.as_ref())
            .file("--json", self.json.as_ref())
    }
}

/// The parsed `--effects` list.
#[derive(Clone, Debug, PartialEq)]
pub struct EffectList(pub Vec<Effect>);

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
        .map(|spec| Effect::parse(spec).map_err(|e| effect_error(spec, e)))
        .collect::<Result<Vec<_>, _>>()
        .map(EffectList)
}

/// The message for a refused effect `spec`: what is wrong, and for a name or parameter
/// not in the catalogue, the ones that are.
fn effect_error(spec: &str, e: EffectError) -> String {
    let known = match e {
        EffectError::UnknownEffect => format!(" (effects: {})", EFFECT_NAMES.join(", ")),
        EffectError::UnknownParameter => {
            let name = spec.split_once(':').map_or(spec, |(n, _)| n).trim();
            let params: Vec<&str> = Effect::default_for(name)
                .map(|d| {
                    d.parameters()
                        .into_iter()
                        .flatten()
                        .map(|(k, _)| k)
                        .collect()
                })
                .unwrap_or_default();
            format!(" (its parameters: {})", params.join(", "))
        }
        _ => String::new(),
    };
    format!("effect `{spec}`: {e}{known}")
}

pub(crate) fn rig_name(rig: &Rig) -> &'static str {
    if *rig == Rig::nominal() {
        "nominal"
    } else {
        "file"
    }
}

/// `effects` as the log's metadata records them: each as it acts on `rig` (every default
/// stated, [`Effect::resolved`]), `name:param=value,…` joined by `;`.
pub(crate) fn effects_text(rig: &Rig, effects: &[Effect]) -> String {
    if effects.is_empty() {
        return "none".into();
    }
    effects
        .iter()
        .map(|e| e.resolved(rig))
        .map(|e| {
            let params: Vec<String> = e
                .parameters()
                .iter()
                .flatten()
                .map(|(k, v)| format!("{k}={v}"))
                .collect();
            if params.is_empty() {
                e.name().to_string()
            } else {
                format!("{}:{}", e.name(), params.join(","))
            }
        })
        .collect::<Vec<_>>()
        .join(";")
}

/// The plant rig: `rig` with `effects` switched on, validated.
pub(crate) fn plant_rig(rig: &Rig, effects: &[Effect]) -> Result<Rig, CliError> {
    let mut r = rig.clone();
    for e in effects {
        e.apply(&mut r);
    }
    r.validate()
        .map_err(|e| CliError::BadInput(format!("with the requested effects, {e}")))?;
    Ok(r)
}

/// `run` unless its state left the physical range: a rig the integration cannot follow
/// (bad input, exit status 2) rather than a log of NaN. `rig_file` is the plant's rig file
/// when one was given (the message points there, else at the rig and effects asked for).
pub(crate) fn converged(run: Run, rig_file: Option<&Path>) -> Result<Run, CliError> {
    match first_unphysical(&run.log) {
        None => Ok(run),
        Some((t, name, v)) => {
            let check = match rig_file {
                Some(f) => format!("check the values in the rig file `{}`", f.display()),
                None => "check the rig's parameters and the effects asked for".into(),
            };
            Err(CliError::BadInput(format!(
                "the simulation diverged: `{name}` reached {v:e} at t = {t:.6} s; the plant's \
                 parameters make the model numerically unstable ({check})"
            )))
        }
    }
}

/// Checks before a run that `duration_s` [s] at `log_rate_hz` [Hz] gives a bench log of
/// [`MIN_ROWS`] to [`most_rows`] rows (`period_s`: the PWM period [s]).
fn check_log_length(duration_s: f64, log_rate_hz: f64, period_s: f64) -> Result<(), CliError> {
    let (every, rows) = log_plan(duration_s, log_rate_hz, period_s);
    let rate = 1.0 / (period_s * every as f64);
    let asked = format!(
        "--duration {} s at --log-rate {} Hz",
        show(duration_s),
        show(log_rate_hz)
    );
    let most = most_rows();
    if rows > most as f64 {
        return Err(CliError::BadInput(format!(
            "{asked} would log {} rows; a bench log of its {LOGGED_COLUMNS} columns holds at \
             most {most} ({:.0} s at this rate)",
            show(rows),
            most as f64 / rate
        )));
    }
    if rows < MIN_ROWS as f64 {
        return Err(CliError::BadInput(format!(
            "{asked} would log {rows} rows; a bench log needs at least {MIN_ROWS}"
        )));
    }
    Ok(())
}

/// `eha simulate`.
pub fn run_simulate(rig: &Rig, args: &SimulateArgs) -> Result<(), CliError> {
    // The command's own wall clock (rig, closed loop, log spelt and written; the comparison
    // run's time taken out): the real-time factor a user of the command sees.
    let started = std::time::Instant::now();
    if args.list {
        return print_list();
    }
    let scenario = scenario_named(args.scenario.as_deref().unwrap_or_default())?;
    let out = args
        .out
        .as_ref()
        .ok_or_else(|| CliError::BadInput("--out LOG.csv is required".into()))?;
    let controller = controller_rig(rig, args.precharge)?;
    let effects = args
        .effects
        .as_ref()
        .map(|e| e.0.clone())
        .unwrap_or_default();
    // The plant is the controller's rig unless the bench's actuator is given apart.
    let base = match &args.plant_rig {
        Some(path) => rig_file::load(path)?,
        None => controller.clone(),
    };
    let plant = plant_rig(&base, &effects)?;
    let compensation = match &args.compensation {
        Some(path) => Some(crate::feedforward::read_table(path, &controller)?),
        None => None,
    };
    let duration = args.duration.unwrap_or(scenario.duration_s);
    let period_s = 1.0 / closed_loop::controller_config(&controller).rates.pwm_hz as f64;
    check_log_length(duration, args.log_rate, period_s)?;
    let seed = args.seed.unwrap_or(1);
    let mut metadata = vec![
        ("source".into(), "simulation".into()),
        ("rig".into(), rig_name(rig).into()),
        ("scenario".into(), scenario.name.into()),
        ("effects".into(), effects_text(&base, &effects)),
        (
            "precharge_pa".into(),
            format!("{}", controller.absorber.precharge_pa),
        ),
        ("seed".into(), format!("{seed}")),
        ("integrator".into(), args.integrator.name().into()),
    ];
    metadata.extend(optional_metadata(args, compensation.as_ref()));
    let options = RunOptions {
        duration_s: duration,
        log_rate_hz: args.log_rate,
        seed,
        progress: true,
        metadata,
        compensation,
        integrator: args.integrator,
    };
    let r = run(&plant, &controller, scenario, &options)
        .map_err(CliError::Failed)
        .and_then(|r| converged(r, args.plant_rig.as_deref()))?;
    // The same run with the other scheme, for the ratio of their speeds in this process.
    let comparing = std::time::Instant::now();
    let compared = match args.compare_integrator {
        Some(other) => {
            let o = run(
                &plant,
                &controller,
                scenario,
                &RunOptions {
                    integrator: other,
                    progress: false,
                    ..options
                },
            )
            .map_err(CliError::Failed)
            .and_then(|r| converged(r, args.plant_rig.as_deref()))?;
            Some((other, o))
        }
        None => None,
    };
    let comparison = comparing.elapsed();
    let mut outputs = Outputs::new();
    bench_log::stage(&mut outputs, "--out", out, &r.log)?;
    let command_s = started.elapsed().saturating_sub(comparison).as_secs_f64();
    if let Some(json_path) = &args.json {
        let ran = Ran {
            scenario,
            duration_s: duration,
            out,
            integrator: args.integrator,
            run: &r,
            command_s,
            compared: compared.as_ref(),
        };
        outputs.json("--json", json_path, &ran.summary())?;
    }
    outputs.commit()?;
    report(
        scenario,
        duration,
        out,
        args.integrator,
        &r,
        compared.as_ref(),
    );
    Ok(())
}

/// `eha simulate --list`: the scenarios and procedures, a line each.
fn print_list() -> Result<(), CliError> {
    let mut s = String::new();
    for sc in SCENARIOS.iter().chain(&PROCEDURES) {
        let _ = writeln!(
            s,
            "{:<19} {:>4.1} s  {}",
            sc.name, sc.duration_s, sc.description
        );
    }
    let mut out = Outputs::new();
    out.print(&s);
    out.commit()
}

/// The scenario or procedure called `name`, or an error listing them.
fn scenario_named(name: &str) -> Result<&'static Scenario, CliError> {
    by_name(name).ok_or_else(|| {
        let names: Vec<&str> = SCENARIOS
            .iter()
            .chain(&PROCEDURES)
            .map(|s| s.name)
            .collect();
        CliError::BadInput(format!(
            "unknown scenario `{name}`: the scenarios are {} (see `eha simulate --list`)",
            names.join(", ")
        ))
    })
}

/// The rig the controller is configured from: `rig` with `--precharge` in place, validated
/// (an invalid precharge named as the option).
fn controller_rig(rig: &Rig, precharge: Option<f64>) -> Result<Rig, CliError> {
    let mut controller = rig.clone();
    if let Some(p0) = precharge {
        controller.absorber.precharge_pa = p0;
    }
    controller.validate().map_err(|e| {
        CliError::BadInput(match precharge {
            Some(p0) if e.parameter == "absorber.precharge_pa" => {
                format!("--precharge {}: {e}", show(p0))
            }
            _ => e.to_string(),
        })
    })?;
    Ok(controller)
}

/// The log's metadata lines that only some runs have: the plant's own rig file, the drive,
/// the start of the recording and the torque feed-forward loaded.
fn optional_metadata(
    args: &SimulateArgs,
    compensation: Option<&Feedforward>,
) -> Vec<(String, String)> {
    let mut metadata = Vec::new();
    if let Some(path) = &args.plant_rig {
        metadata.push(("plant_rig".into(), path.display().to_string()));
    }
    if let Some(drive) = &args.drive {
        metadata.push((bench_log::DRIVE_KEY.into(), drive.clone()));
    }
    if let Some(at) = &args.recorded_at {
        metadata.push((bench_log::RECORDED_AT_KEY.into(), at.clone()));
    }
    if let (Some(path), Some(t)) = (&args.compensation, compensation) {
        metadata.push((
            "compensation".into(),
            format!(
                "{} (CRC {:#010x}; speed modulation {})",
                path.display(),
                firmware::compensation::record::crc_of(&t.table),
                match &t.flow {
                    Some(f) => format!(
                        "{} pistons, {:.4} peak-to-peak, phase {} rad",
                        f.pistons, f.ratio, f.phase_rad
                    ),
                    None => "off".into(),
                }
            ),
        ));
    }
    metadata
}

/// A finished `eha simulate` run, as `--json` reports it.
struct Ran<'a> {
    scenario: &'static Scenario,
    duration_s: f64,
    out: &'a Path,
    integrator: Integrator,
    run: &'a Run,
    /// The command's wall clock, the comparison run taken out. [s]
    command_s: f64,
    compared: Option<&'a (Integrator, Run)>,
}

impl Ran<'_> {
    /// The `--json` summary: rows, the real-time factors, and the comparison run's.
    fn summary(&self) -> serde_json::Value {
        let r = self.run;
        let mut summary = json!({
            "scenario": self.scenario.name,
            "duration_s": self.duration_s,
            "rows": r.log.len(),
            "out": self.out.display().to_string(),
            "real_time_factor": r.real_time_factor,
            "cpu_real_time_factor": r.cpu_real_time_factor,
            "command_wall_s": self.command_s,
            "command_real_time_factor": self.duration_s / self.command_s.max(1e-9),
            "integrator": self.integrator.name(),
        });
        if let Some((other, o)) = self.compared {
            summary["compared"] = json!({
                "integrator": other.name(),
                "real_time_factor": o.real_time_factor,
                "cpu_real_time_factor": o.cpu_real_time_factor,
                "speedup": r.cpu_real_time_factor / o.cpu_real_time_factor,
            });
        }
        summary
    }
}

/// The run's line on standard error, and the comparison's.
fn report(
    scenario: &Scenario,
    duration_s: f64,
    out: &Path,
    integrator: Integrator,
    r: &Run,
    compared: Option<&(Integrator, Run)>,
) {
    eprintln!(
        "{}: {} rows over {duration_s} s written to {} ({:.0}× real time, {:.0}× per CPU second, \
         {})",
        scenario.name,
        r.log.len(),
        out.display(),
        r.real_time_factor,
        r.cpu_real_time_factor,
        integrator.name()
    );
    if let Some((other, o)) = compared {
        eprintln!(
            "{}: {:.0}× per CPU second; {} is {:.2}× as fast",
            other.name(),
            o.cpu_real_time_factor,
            integrator.name(),
            r.cpu_real_time_factor / o.cpu_real_time_factor
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
