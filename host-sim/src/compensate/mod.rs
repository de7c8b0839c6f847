//! `eha compensate LOG.csv… --out TABLE [--method model|histogram] [--json PATH]`: the
//! angle-indexed torque feed-forward learned from bench logs, written as the table record
//! the drive loads ([`firmware::compensation::record`]), the CAN frames that load it
//! printed, and its effect predicted on the paper's holding with the firmware's control
//! core against the model fitted to the logs.
//!
//! - [`learn`]: the diagnosis's significant angle-locked effects, combined over logs.
//! - [`model`]: the channels from a rig's equations, the rig extended by those effects.
//! - [`flow`]: the speed modulation against the pump's flow ripple, its parameters.
//! - [`histogram`]: the anchors' method, the q current binned by angle, for comparison.
//! - [`table`]: channels as harmonics → the drive's table (pre-emphasis, quantisation).
//! - [`predict`]: holding runs without and with a table, their pulsation.
//! - [`can`]: the loading frames in `cansend` notation.
//! - [`study`]: the closed-loop study of `docs/compensation.md`.
//!
//! More than one log may be given (the contract's one `LOG.csv` is the common case): the
//! bench sweep at low pressure carries the load-independent lines, a hold at working
//! pressure the load-scaled ones.

pub mod can;
pub mod flow;
pub mod histogram;
pub mod learn;
pub mod model;
pub mod predict;
pub mod study;
pub mod table;

use crate::bench_log::{self, BenchLog};
use crate::output::paths::Declared;
use crate::output::{print_stdout, write_json, CliError};
use clap::{Args, ValueEnum};
use firmware::compensation::record::{self, RECORD_LEN};
use firmware::compensation::{Channel, Compensation, Table, BINS, CHANNELS};
use flow::FlowParams;
use learn::Learned;
use plant_model::Rig;
use predict::reduction_percent;
use serde_json::json;
use std::fmt::Write as _;
use std::path::PathBuf;

/// How the table is learned.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// From the diagnosis's fitted effects, each in the channel of its scaling law.
    Model,
    /// The q current binned by shaft angle at constant speed (moteus, ODrive).
    Histogram,
}

impl Method {
    fn name(self) -> &'static str {
        match self {
            Method::Model => "model",
            Method::Histogram => "histogram",
        }
    }
}

/// `eha compensate`.
#[derive(Debug, Args)]
pub struct CompensateArgs {
    /// Bench logs to learn from (the bench sweep's, and a hold at working pressure for the
    /// load-scaled effects).
    #[arg(value_name = "LOG.csv", required = true)]
    pub logs: Vec<PathBuf>,
    /// The table to write (the record the drive stores and loads).
    #[arg(long, value_name = "TABLE")]
    pub out: PathBuf,
    /// How to learn it.
    #[arg(long, value_enum, default_value = "model")]
    pub method: Method,
    /// Write the results as JSON (`-`: standard output).
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// Effects to leave out of the model-based table (catalogue names, comma-separated),
    /// e.g. `piston_ripple` to keep the pump's torque ripple, which slows the shaft where
    /// the pump delivers more and so evens out its flow (and no speed modulation), or
    /// `flow_ripple` for the torque table without the speed modulation against the pump's
    /// flow ripple.
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub exclude: Vec<String>,
    /// Also write the loading frames as a `candump -l` log (`canplayer -I FILE` replays it).
    #[arg(long, value_name = "FILE")]
    pub can_log: Option<PathBuf>,
}

impl CompensateArgs {
    /// The files it reads and writes.
    pub fn paths(&self) -> Declared<'_> {
        let mut d = Declared::default();
        for log in &self.logs {
            d = d.input("LOG", Some(log));
        }
        d.file("--out", Some(&self.out))
            .file("--json", self.json.as_ref())
            .file("--can-log", self.can_log.as_ref())
    }
}

/// What the diagnosis found in a set of logs.
pub struct Found {
    /// The significant angle-locked effects, combined over the logs, strongest first.
    pub effects: Vec<Learned>,
    /// The low port's mean pressure over the logs. [Pa]
    pub p_low_pa: f64,
}

/// Runs the diagnosis on each log (in parallel) and combines what it found.
pub fn find(logs: &[BenchLog], rig: &Rig) -> Result<Found, CliError> {
    use rayon::prelude::*;
    let per_log = logs
        .par_iter()
        .map(|log| learn::causes_of(log, rig))
        .collect::<Result<Vec<_>, _>>()?;
    let diagnoses: Vec<_> = per_log.into_iter().flatten().collect();
    Ok(Found {
        effects: learn::combine(&diagnoses),
        p_low_pa: learn::mean_low_pressure(logs, rig),
    })
}

/// Reads and checks the logs (bad input before any work).
fn read_logs(rig: &Rig, args: &CompensateArgs) -> Result<Vec<BenchLog>, CliError> {
    args.logs
        .iter()
        .map(|path| {
            let log = bench_log::read(path)?;
            bench_log::replayable::check(&log, rig, path)?;
            if log.theta_m_rad.is_none() {
                return Err(CliError::BadInput(format!(
                    "bench log `{}` has no theta_m_rad column: an angle-indexed table needs \
                     the shaft angle the ripple is locked to",
                    path.display()
                )));
            }
            Ok(log)
        })
        .collect()
}

/// What `eha compensate` loads into a drive: the torque table and, when the pump's ripple
/// was learned, the speed modulation's parameters ([`flow`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Feedforward {
    /// The angle-indexed q-current table.
    pub table: Table,
    /// The speed modulation against the pump's flow ripple (`None`: off).
    pub flow: Option<FlowParams>,
}

impl Feedforward {
    /// The table alone (no speed modulation).
    pub fn table_only(table: Table) -> Feedforward {
        Feedforward { table, flow: None }
    }

    /// The table file: the drive's table record, then the modulation's parameter trailer
    /// if there is one.
    pub fn file_bytes(&self) -> Vec<u8> {
        let mut bytes = vec![0u8; RECORD_LEN];
        if let Ok(b) = <&mut [u8; RECORD_LEN]>::try_from(bytes.as_mut_slice()) {
            record::Encoder::write_all(&self.table, b);
        }
        if let Some(f) = &self.flow {
            bytes.extend_from_slice(&f.trailer());
        }
        bytes
    }

    /// Checks it against `rig`'s controller configuration as the drive would: the table's
    /// amplitude, the modulation's parameters and depth. The error names the bound.
    pub fn check(&self, rig: &Rig) -> Result<(), String> {
        let mut cfg = closed_loop::controller_config(rig);
        cfg.compensation.enabled = true;
        Compensation::check_amplitude(&self.table, &cfg).map_err(|e| e.to_string())?;
        match &self.flow {
            Some(f) => f.apply(&mut cfg),
            None => Ok(()),
        }
    }
}

/// Longest table file: the record and a trailer of the modulation's parameters. [bytes]
const MAX_FILE_LEN: u64 = RECORD_LEN as u64 + 12 + 8 * flow::FLOW_IDS.len() as u64;

/// Reads a table file written by `eha compensate` and checks it as the drive checks its
/// stored table (size, magic, version, bins, channels, exponents, CRC), then its amplitude
/// against the limit of `rig`'s controller configuration, and the modulation's parameter
/// trailer if there is one ([`flow`]). Bad input names the file.
pub fn read_table(path: &std::path::Path, rig: &Rig) -> Result<Feedforward, CliError> {
    let bad =
        |why: String| CliError::BadInput(format!("compensation table `{}`: {why}", path.display()));
    let len = std::fs::metadata(path)
        .map_err(|e| bad(crate::output::paths::describe(&e)))?
        .len();
    if !(RECORD_LEN as u64..=MAX_FILE_LEN).contains(&len) {
        return Err(bad(record::RecordError::Length {
            found: usize::try_from(len).unwrap_or(usize::MAX),
        }
        .to_string()));
    }
    let bytes = std::fs::read(path).map_err(|e| bad(crate::output::paths::describe(&e)))?;
    let (rec, trailer) = bytes.split_at(RECORD_LEN.min(bytes.len()));
    let mut table = Table::ZERO;
    record::from_bytes(rec, &mut table).map_err(|e| bad(e.to_string()))?;
    let flow = if trailer.is_empty() {
        None
    } else {
        Some(FlowParams::from_trailer(trailer).map_err(bad)?)
    };
    let ff = Feedforward { table, flow };
    ff.check(rig).map_err(bad)?;
    Ok(ff)
}

/// The feed-forward learned from `found` (model) or `logs` (histogram) on `rig`: the table
/// of [`table_of`] and, for the model, the speed modulation against the pump's flow ripple
/// when `piston_ripple` was found and neither it nor [`flow::EXCLUDE_NAME`] is in
/// `exclude`; refused when the drive would refuse it.
pub fn feedforward_of(
    found: &Found,
    logs: &[BenchLog],
    rig: &Rig,
    method: Method,
    exclude: &[String],
) -> Result<Feedforward, CliError> {
    let table = table_of(found, logs, rig, method, exclude)?;
    let left_out = |n: &str| exclude.iter().any(|x| x == n);
    let flow = match method {
        Method::Model if !left_out("piston_ripple") && !left_out(flow::EXCLUDE_NAME) => found
            .effects
            .iter()
            .find_map(|l| FlowParams::of_effect(&l.effect, rig)),
        _ => None,
    };
    let ff = Feedforward { table, flow };
    ff.check(rig)
        .map_err(|e| CliError::BadInput(format!("the learned feed-forward is refused: {e}")))?;
    Ok(ff)
}

/// The histogram's table from `logs`: their constant channels averaged.
fn histogram_table(logs: &[BenchLog]) -> Result<Table, CliError> {
    let maps: Vec<Vec<f64>> = logs
        .iter()
        .filter_map(histogram::constant_channel)
        .collect();
    if maps.is_empty() {
        return Err(CliError::BadInput(
            "no stretch of steady rotation in the logs: the histogram needs the shaft turning \
             at constant speed (the bench sweep, or a hold that turns)"
                .into(),
        ));
    }
    let n = maps.len() as f64;
    let constant: Vec<f64> = (0..BINS)
        .map(|b| maps.iter().map(|m| m[b]).sum::<f64>() / n)
        .collect();
    let columns: [Vec<f64>; CHANNELS] = [constant, vec![0.0; BINS], vec![0.0; BINS]];
    table::quantise(&columns)
        .ok_or_else(|| CliError::Failed("the histogram does not fit the table's range".into()))
}

/// The table learned from `found` (model) or `logs` (histogram) on `rig`, leaving out the
/// effects named in `exclude`; refused when its amplitude exceeds the drive's limit.
pub fn table_of(
    found: &Found,
    logs: &[BenchLog],
    rig: &Rig,
    method: Method,
    exclude: &[String],
) -> Result<Table, CliError> {
    let table = match method {
        Method::Model => {
            let ch = model::channels_from_rig(&fitted_plant(found, rig)?, found.p_low_pa, exclude);
            table::build(&ch).ok_or_else(|| {
                CliError::Failed("the fitted effects do not fit the table's range".into())
            })?
        }
        Method::Histogram => histogram_table(logs)?,
    };
    let mut cfg = closed_loop::controller_config(rig);
    cfg.compensation.enabled = true;
    Compensation::check_amplitude(&table, &cfg)
        .map_err(|e| CliError::BadInput(format!("the learned table is refused: {e}")))?;
    Ok(table)
}

/// The rig with the effects `found` switched on: the model fitted to the logs.
pub fn fitted_plant(found: &Found, rig: &Rig) -> Result<Rig, CliError> {
    let mut plant = rig.clone();
    for l in &found.effects {
        l.effect.apply(&mut plant);
    }
    plant
        .validate()
        .map_err(|e| CliError::Failed(format!("the fitted plant is not a rig: {e}")))?;
    Ok(plant)
}

/// One line per learned effect: name, Λ, logs, fitted parameters.
fn effect_lines(effects: &[Learned]) -> String {
    let mut s = String::from("effect                      Λ  fits  parameters\n");
    for l in effects {
        let params: Vec<String> = l
            .effect
            .parameters()
            .iter()
            .flatten()
            .map(|(k, v)| format!("{k}={v:.4e}"))
            .collect();
        let _ = writeln!(
            s,
            "{:<22} {:>7.0} {:>5}  {}",
            l.effect.name(),
            l.score,
            l.diagnoses,
            params.join(" ")
        );
    }
    if effects.is_empty() {
        s.push_str("(none significant: the table is empty)\n");
    }
    s
}

/// `eha compensate`.
pub fn run_compensate(rig: &Rig, args: &CompensateArgs) -> Result<(), CliError> {
    if let Some(bad) = args
        .exclude
        .iter()
        .find(|x| !learn::LINE_EFFECTS.contains(&x.as_str()) && *x != flow::EXCLUDE_NAME)
    {
        return Err(CliError::BadInput(format!(
            "--exclude `{bad}`: not an angle-locked effect (one of {}) or {}",
            learn::LINE_EFFECTS.join(", "),
            flow::EXCLUDE_NAME
        )));
    }
    let logs = read_logs(rig, args)?;
    let busy = crate::output::progress::spinner(format!(
        "learning the feed-forward from {} log(s)",
        logs.len()
    ));
    let learned = (|| {
        let found = find(&logs, rig)?;
        let ff = feedforward_of(&found, &logs, rig, args.method, &args.exclude)?;
        let plant = fitted_plant(&found, rig)?;
        let (without, with) = predict::without_and_with(&plant, rig, &[&ff])?;
        let with = with
            .into_iter()
            .next()
            .ok_or_else(|| CliError::Failed("no run with the table".into()))?;
        Ok::<_, CliError>((found, ff, without, with))
    })();
    busy.finish_and_clear();
    let (found, ff, without, with) = learned?;
    let table = &ff.table;
    let bytes = ff.file_bytes();
    crate::output::atomic::write(&args.out, &bytes).map_err(|source| CliError::Write {
        file: args.out.clone(),
        source,
    })?;
    let node = firmware::can_protocol::NodeId::new(crate::tune::can::NODE)
        .map_err(|e| CliError::Failed(format!("CAN node: {e:?}")))?;
    let frames = can::frames(&ff, node);
    let peak = table.peak();
    let mut text = String::new();
    let _ = writeln!(
        text,
        "{} method from {} log(s); effects learned:",
        args.method.name(),
        logs.len()
    );
    let in_table: Vec<Learned> = found
        .effects
        .iter()
        .filter(|l| !args.exclude.iter().any(|x| x == l.effect.name()))
        .cloned()
        .collect();
    text.push_str(&effect_lines(&in_table));
    if in_table.len() < found.effects.len() {
        let _ = writeln!(text, "(left out of the table: {})", args.exclude.join(", "));
    }
    let _ = writeln!(
        text,
        "table: {BINS} bins; peaks {:.4} A, {:.3e} A/Pa, {:.4} A/A; written to {} ({} bytes, record CRC {:#010x})",
        peak[Channel::Constant as usize],
        peak[Channel::PerPressure as usize],
        peak[Channel::PerCurrent as usize],
        args.out.display(),
        bytes.len(),
        record::crc_of(table)
    );
    match &ff.flow {
        Some(f) => {
            let _ = writeln!(
                text,
                "speed modulation against the pump's flow ripple: {} pistons, {:.3} % peak-to-peak, phase {:.3} rad, J = {:.3e} kg·m²",
                f.pistons,
                100.0 * f.ratio,
                f.phase_rad,
                f.inertia_kg_m2
            );
        }
        None => {
            let _ = writeln!(text, "speed modulation against the pump's flow ripple: off");
        }
    }
    let _ = writeln!(
        text,
        "predicted, holding at 5 MPa on the rig with the learned effects (true signals, steady part):"
    );
    let _ = writeln!(
        text,
        "                          without       with  reduction"
    );
    for (name, w, t, unit) in [
        (
            "pressure pp",
            without.pressure_pp_pa,
            with.pressure_pp_pa,
            "Pa",
        ),
        (
            "pressure locked pp",
            without.pressure_locked_pp_pa,
            with.pressure_locked_pp_pa,
            "Pa",
        ),
        (
            "speed pp",
            without.speed_pp_rad_s,
            with.speed_pp_rad_s,
            "rad/s",
        ),
        (
            "speed locked pp",
            without.speed_locked_pp_rad_s,
            with.speed_locked_pp_rad_s,
            "rad/s",
        ),
    ] {
        let _ = writeln!(
            text,
            "  {name:<20} {w:>10.3} {t:>10.3} {:>8.0} %  [{unit}]",
            reduction_percent(w, t)
        );
    }
    let _ = writeln!(
        text,
        "CAN frames loading, enabling and saving it on node {} ({} frames):",
        node.get(),
        frames.len()
    );
    text.push_str(&can::cansend_lines(&frames));
    print_stdout(&text)?;
    if let Some(path) = &args.can_log {
        let commands: Vec<crate::can_commands::CanCommand> = frames
            .iter()
            .map(|f| crate::can_commands::CanCommand {
                frame: *f,
                what: "compensation table".into(),
            })
            .collect();
        crate::can_commands::write_candump_log(path, &commands)?;
    }
    if let Some(path) = &args.json {
        write_json(
            path,
            &json!({
                "method": args.method.name(),
                "effects": in_table.iter().map(|e| e.effect.name()).collect::<Vec<_>>(),
                "table_bins": BINS,
                "predicted": {
                    "pressure_pp_pa": {"without": without.pressure_pp_pa, "with": with.pressure_pp_pa},
                    "speed_pp_rad_s": {"without": without.speed_pp_rad_s, "with": with.speed_pp_rad_s},
                    "pressure_angle_locked_pp_pa": {"without": without.pressure_locked_pp_pa, "with": with.pressure_locked_pp_pa},
                    "speed_angle_locked_pp_rad_s": {"without": without.speed_locked_pp_rad_s, "with": with.speed_locked_pp_rad_s},
                },
                "table_crc": record::crc_of(table),
                "flow_ripple": ff.flow.map(|f| json!({
                    "pistons": f.pistons,
                    "ratio": f.ratio,
                    "phase_rad": f.phase_rad,
                    "inertia_kg_m2": f.inertia_kg_m2,
                })),
                "table_peaks": {"constant_a": peak[0], "per_pressure_a_per_pa": peak[1], "per_current": peak[2]},
                "logs": args.logs.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            }),
        )?;
    }
    Ok(())
}
