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
//! - `summary`: the printed summary and the JSON of a run.
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
mod summary;
pub mod table;

use crate::bench_log::{self, BenchLog};
use crate::output::paths::Declared;
use crate::output::{CliError, Outputs};
use clap::{Args, ValueEnum};
use firmware::can_protocol::{Frame, NodeId};
use firmware::compensation::record::{self, RECORD_LEN};
use firmware::compensation::{Compensation, Table, BINS, CHANNELS};
use flow::FlowParams;
use learn::Learned;
use plant_model::Rig;
use predict::Pulsation;
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

/// Most rows learned from, over all the logs: the learning diagnoses each log and keeps
/// every row's traces of all of them at once (more bytes a row than one diagnosis;
/// `docs/memory.md`), so that it stays under 1 GiB of memory.
pub const MAX_LEARNED_ROWS: usize = 1_500_000;

/// Reads and checks the logs (bad input before any work).
fn read_logs(rig: &Rig, args: &CompensateArgs) -> Result<Vec<BenchLog>, CliError> {
    let mut rows = 0;
    args.logs
        .iter()
        .map(|path| {
            let log = bench_log::read(path)?;
            bench_log::replayable::check(&log, rig, path)?;
            rows += log.len();
            if rows > MAX_LEARNED_ROWS {
                return Err(CliError::BadInput(format!(
                    "bench log `{}` brings the logs to {rows} rows; eha compensate learns from \
                     at most {MAX_LEARNED_ROWS} in all (it keeps every row's traces, within \
                     1 GiB of memory): give fewer or shorter logs, or log at a lower rate",
                    path.display()
                )));
            }
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
        .map_err(|e| bad(crate::output::file_kind::describe(&e)))?
        .len();
    if !(RECORD_LEN as u64..=MAX_FILE_LEN).contains(&len) {
        return Err(bad(record::RecordError::Length {
            found: usize::try_from(len).unwrap_or(usize::MAX),
        }
        .to_string()));
    }
    let bytes = std::fs::read(path).map_err(|e| bad(crate::output::file_kind::describe(&e)))?;
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

/// What one run learned from the logs and predicted of it on the paper's holding.
struct Outcome {
    /// What the diagnosis found in the logs.
    found: Found,
    /// The feed-forward learned.
    ff: Feedforward,
    /// The holding's pulsation on the fitted plant without the feed-forward.
    without: Pulsation,
    /// The same with it.
    with: Pulsation,
}

/// Checks `--exclude`: each name an angle-locked effect or [`flow::EXCLUDE_NAME`].
fn check_exclude(exclude: &[String]) -> Result<(), CliError> {
    match exclude
        .iter()
        .find(|x| !learn::LINE_EFFECTS.contains(&x.as_str()) && *x != flow::EXCLUDE_NAME)
    {
        Some(bad) => Err(CliError::BadInput(format!(
            "--exclude `{bad}`: not an angle-locked effect (one of {}) or {}",
            learn::LINE_EFFECTS.join(", "),
            flow::EXCLUDE_NAME
        ))),
        None => Ok(()),
    }
}

/// Learns the feed-forward from `logs` by `args.method` and predicts its effect on the
/// holding against the plant fitted to the logs, under a progress spinner.
fn learn_and_predict(
    rig: &Rig,
    logs: &[BenchLog],
    args: &CompensateArgs,
) -> Result<Outcome, CliError> {
    let busy = crate::output::progress::spinner(format!(
        "learning the feed-forward from {} log(s)",
        logs.len()
    ));
    let learned = (|| {
        let found = find(logs, rig)?;
        let ff = feedforward_of(&found, logs, rig, args.method, &args.exclude)?;
        let plant = fitted_plant(&found, rig)?;
        let (without, with) = predict::without_and_with(&plant, rig, &[&ff])?;
        let with = with
            .into_iter()
            .next()
            .ok_or_else(|| CliError::Failed("no run with the table".into()))?;
        Ok::<_, CliError>(Outcome {
            found,
            ff,
            without,
            with,
        })
    })();
    busy.finish_and_clear();
    learned
}

/// Stages `frames` as the `candump -l` log `--can-log path`.
fn stage_can_log(
    out: &mut Outputs,
    path: &std::path::Path,
    frames: &[Frame],
) -> Result<(), CliError> {
    let commands: Vec<crate::can_commands::CanCommand> = frames
        .iter()
        .map(|f| crate::can_commands::CanCommand {
            frame: *f,
            what: "compensation table".into(),
        })
        .collect();
    crate::can_commands::stage_candump_log(out, path, &commands)
}

/// `eha compensate`: checks the arguments and logs, learns the feed-forward, then writes
/// the table, the CAN log and the JSON if asked for, together, and prints the summary and
/// the CAN frames.
pub fn run_compensate(rig: &Rig, args: &CompensateArgs) -> Result<(), CliError> {
    check_exclude(&args.exclude)?;
    let logs = read_logs(rig, args)?;
    let outcome = learn_and_predict(rig, &logs, args)?;
    let bytes = outcome.ff.file_bytes();
    let mut out = Outputs::new();
    out.file("--out", &args.out, &bytes)?;
    let node = NodeId::new(crate::tune::can::NODE)
        .map_err(|e| CliError::Failed(format!("CAN node: {e:?}")))?;
    let frames = can::frames(&outcome.ff, node);
    let in_table = summary::in_table(&outcome, &args.exclude);
    let written = summary::Written {
        file_len: bytes.len(),
        node,
        frames: &frames,
    };
    // Standard output: the summary, then the JSON when it goes there too (`--json -`).
    out.print(&summary::text(
        args,
        logs.len(),
        &outcome,
        &in_table,
        &written,
    ));
    if let Some(path) = &args.can_log {
        stage_can_log(&mut out, path, &frames)?;
    }
    if let Some(path) = &args.json {
        out.json("--json", path, &summary::json(args, &outcome, &in_table))?;
    }
    out.commit()
}
