//! `eha compensate LOG.csv… --out TABLE [--method model|histogram] [--json PATH]`: the
//! angle-indexed torque feed-forward learned from bench logs, written as the table record
//! the drive loads ([`firmware::compensation::record`]), the CAN frames that load it
//! printed, and its effect predicted on the paper's holding with the firmware's control
//! core against the model fitted to the logs.
//!
//! - [`learn`]: the diagnosis's significant angle-locked effects, combined over logs.
//! - [`model`]: the channels from a rig's equations, the rig extended by those effects.
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
    /// the pump delivers more and so evens out its flow.
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

/// Reads a table file written by `eha compensate` and checks it as the drive checks its
/// stored table (size, magic, version, bins, channels, exponents, CRC), then its amplitude
/// against the limit of `rig`'s controller configuration. Bad input names the file.
pub fn read_table(path: &std::path::Path, rig: &Rig) -> Result<Table, CliError> {
    let bad =
        |why: String| CliError::BadInput(format!("compensation table `{}`: {why}", path.display()));
    let len = std::fs::metadata(path)
        .map_err(|e| bad(crate::output::paths::describe(&e)))?
        .len();
    if len != RECORD_LEN as u64 {
        return Err(bad(record::RecordError::Length {
            found: usize::try_from(len).unwrap_or(usize::MAX),
        }
        .to_string()));
    }
    let bytes = std::fs::read(path).map_err(|e| bad(crate::output::paths::describe(&e)))?;
    let mut table = Table::ZERO;
    record::from_bytes(&bytes, &mut table).map_err(|e| bad(e.to_string()))?;
    let mut cfg = closed_loop::controller_config(rig);
    cfg.compensation.enabled = true;
    Compensation::check_amplitude(&table, &cfg).map_err(|e| bad(e.to_string()))?;
    Ok(table)
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
        .find(|x| !learn::LINE_EFFECTS.contains(&x.as_str()))
    {
        return Err(CliError::BadInput(format!(
            "--exclude `{bad}`: not an angle-locked effect (one of {})",
            learn::LINE_EFFECTS.join(", ")
        )));
    }
    let logs = read_logs(rig, args)?;
    let busy = crate::output::progress::spinner(format!(
        "learning the feed-forward from {} log(s)",
        logs.len()
    ));
    let learned = (|| {
        let found = find(&logs, rig)?;
        let table = table_of(&found, &logs, rig, args.method, &args.exclude)?;
        let plant = fitted_plant(&found, rig)?;
        let (without, with) = predict::without_and_with(&plant, rig, &[&table])?;
        let with = with
            .into_iter()
            .next()
            .ok_or_else(|| CliError::Failed("no run with the table".into()))?;
        Ok::<_, CliError>((found, table, without, with))
    })();
    busy.finish_and_clear();
    let (found, table, without, with) = learned?;
    let mut bytes = [0u8; RECORD_LEN];
    record::Encoder::write_all(&table, &mut bytes);
    crate::output::atomic::write(&args.out, &bytes).map_err(|source| CliError::Write {
        file: args.out.clone(),
        source,
    })?;
    let node = firmware::can_protocol::NodeId::new(crate::tune::can::NODE)
        .map_err(|e| CliError::Failed(format!("CAN node: {e:?}")))?;
    let frames = can::frames(&table, node);
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
        "table: {BINS} bins; peaks {:.4} A, {:.3e} A/Pa, {:.4} A/A; written to {} ({RECORD_LEN} bytes, CRC {:#010x})",
        peak[Channel::Constant as usize],
        peak[Channel::PerPressure as usize],
        peak[Channel::PerCurrent as usize],
        args.out.display(),
        record::crc_of(&table)
    );
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
                "table_crc": record::crc_of(&table),
                "table_peaks": {"constant_a": peak[0], "per_pressure_a_per_pa": peak[1], "per_current": peak[2]},
                "logs": args.logs.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            }),
        )?;
    }
    Ok(())
}
