//! `eha fleet PATH… --out DIR [--manifest CSV] [--shard K/N] [--jobs N] [--json PATH]`:
//! many bench logs diagnosed at once, one table of what each shows, and each drive's
//! parameters trended over time against their limits. The stages:
//!
//! - [`inputs`]: the logs, their drives and times, in one order; `--shard`'s part of it.
//! - [`cache`]: each log known by its content's SHA-256; its kept diagnosis read back, so
//!   a run resumes where the last one stopped.
//! - [`runner`]: the logs not yet diagnosed, each in a child `eha diagnose` process,
//!   `--jobs` at a time; a failure is that log's row, never the run's end.
//! - [`table`]: one row per log; [`drift`] and [`trend`]: per drive and parameter, the
//!   weighted straight-line trend, its significance, the value now and the crossing of
//!   the [`limits`]; [`figures`]: a figure per drifting drive.
//! - [`commit`]: the tables and figures staged for the output folder, in one place, and
//!   committed with the run's standard output and `--json` as one transaction.
//!
//! Exit status: 0 when every log was diagnosed, 1 when some were not (their rows say why),
//! 2 for bad arguments (checked before any log is diagnosed).

pub mod cache;
pub mod commit;
pub mod drift;
pub mod figures;
pub mod inputs;
pub mod limits;
pub mod runner;
pub mod table;
pub mod trend;

use crate::output::paths::{self, Declared};
use crate::output::{CliError, Outputs};
use crate::values::positive_f64;
use cache::{Context, Outcome};
use clap::Args;
use inputs::{Entry, Shard};
use plant_model::Rig;
use runner::{Finished, Ran, Runner};
use serde_json::json;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};
use table::Row;

/// `eha fleet`.
#[derive(Debug, Args)]
pub struct FleetArgs {
    /// Bench logs, or folders searched recursively for `*.csv` logs.
    #[arg(value_name = "PATH", required_unless_present = "manifest")]
    pub paths: Vec<PathBuf>,
    /// Output folder: fleet.csv, fleet.json, trends.csv, plots/, and the kept diagnoses
    /// (diagnoses/) that make a second run resume.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// CSV of logs with columns `path` (relative to the manifest's folder), `drive`,
    /// `recorded_at` (RFC 3339); its drive and time win over the logs' metadata lines.
    #[arg(long, value_name = "CSV")]
    pub manifest: Option<PathBuf>,
    /// Take only the K-th of N deterministic parts (0-based), for job arrays: the shards'
    /// tables, concatenated in order, are the whole table.
    #[arg(long, value_name = "K/N", value_parser = inputs::parse_shard)]
    pub shard: Option<Shard>,
    /// Diagnoses run at once (default: the number of cores).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub jobs: Option<u32>,
    /// Write a summary of the run as JSON (`-`: standard output).
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// Working pressure the absorber's precharge limit is designed at (eq. 26–32), gauge. [Pa]
    #[arg(long, value_name = "PA", default_value = "5e6", value_parser = positive_f64, allow_negative_numbers = true)]
    pub pressure: f64,
    /// Highest acceptable extra leakage (default: the rig file's own leakage, i.e. the
    /// holding flow doubled). [m³/(s·Pa)]
    #[arg(long, value_name = "M3_S_PA", value_parser = positive_f64, allow_negative_numbers = true)]
    pub leakage_limit: Option<f64>,
    /// Write the run's plan as JSON and stop without diagnosing (`-`: standard output):
    /// the logs in the table's order with their SHA-256 and whether DIR holds their
    /// diagnosis — what a distributed driver (tools/fleet_dask.py) maps over.
    #[arg(long, value_name = "PATH")]
    pub plan: Option<PathBuf>,
    /// Stop a log's diagnosis after this long (its row then says so; the next run tries
    /// it again). [s]
    #[arg(long, value_name = "S", value_parser = positive_f64, allow_negative_numbers = true)]
    pub timeout: Option<f64>,
}

impl FleetArgs {
    /// The files it reads and writes (the logs themselves are checked one by one: an
    /// unreadable log is a row, not a bad argument). The output folder is kept across runs,
    /// not replaced whole: [`FleetArgs::check_out`] checks it.
    pub fn paths(&self) -> Declared<'_> {
        Declared::default()
            .input("--manifest", self.manifest.as_ref())
            .file("--json", self.json.as_ref())
            .file("--plan", self.plan.as_ref())
    }

    /// Checks `--out`: a folder that is or can be made, in which eha can create files, and
    /// no other output's path.
    fn check_out(&self) -> Result<(), CliError> {
        let inputs: Vec<&Path> = self.manifest.iter().map(PathBuf::as_path).collect();
        paths::kept_dir("--out", &self.out, &inputs)?;
        let mut outputs = vec![("--out", self.out.as_path())];
        outputs.extend(self.json.as_deref().map(|p| ("--json", p)));
        outputs.extend(self.plan.as_deref().map(|p| ("--plan", p)));
        paths::distinct(&outputs)
    }
}

/// The rig's identity for the kept diagnoses: the rig file's SHA-256, or `nominal`.
fn rig_identity(rig_file: Option<&Path>) -> Result<String, CliError> {
    match rig_file {
        None => Ok(cache::NOMINAL_RIG.into()),
        Some(p) => cache::sha256_file(p).map_err(|e| {
            CliError::BadInput(format!(
                "--rig `{}`: {}",
                p.display(),
                crate::output::file_kind::describe(&e)
            ))
        }),
    }
}

/// SHA-256 of every entry's log, `jobs` at a time; an unreadable one becomes its problem.
fn hash_all(entries: &[Entry], jobs: usize) -> Vec<Result<String, String>> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(jobs).build();
    let hash = |e: &Entry| match &e.problem {
        Some(p) => Err(p.clone()),
        None => cache::sha256_file(&e.path).map_err(|err| {
            format!(
                "bench log `{}`: {}",
                e.path.display(),
                crate::output::file_kind::describe(&err)
            )
        }),
    };
    use rayon::prelude::*;
    match pool {
        Ok(pool) => pool.install(|| entries.par_iter().map(hash).collect()),
        Err(_) => entries.iter().map(hash).collect(),
    }
}

/// The plan of a run: the context a kept diagnosis must match, and every log in the
/// table's order with its hash (or why it cannot be read) and whether one is kept.
fn plan(
    entries: &[Entry],
    hashes: &[Result<String, String>],
    out: &Path,
    ctx: &Context,
    rig_file: Option<&Path>,
) -> serde_json::Value {
    let logs: Vec<_> = entries
        .iter()
        .zip(hashes)
        .map(|(e, h)| match h {
            Ok(h) => json!({
                "path": e.path.display().to_string(),
                "sha256": h,
                "kept": cache::load(out, h, ctx).is_some(),
                "record": cache::record_path(out, h).display().to_string(),
            }),
            Err(why) => json!({"path": e.path.display().to_string(), "error": why}),
        })
        .collect();
    json!({
        "rig_sha256": ctx.rig_sha256,
        "eha_version": ctx.eha_version,
        "rig": rig_file.map(|p| p.display().to_string()),
        "logs": logs,
    })
}

/// What the table needs of an outcome: the findings, or why there are none. Only these
/// are held for the whole run (a few kilobytes a log), never the diagnoses' JSON.
fn findings_of(outcome: Outcome) -> Result<table::Findings, String> {
    match outcome {
        Outcome::Diagnosed(d) => table::findings(&d)
            .ok_or_else(|| "the kept diagnosis is not eha diagnose's JSON".to_string()),
        Outcome::BadInput(why) => Err(why),
    }
}

/// What became of each distinct log: kept outcomes read back or made now, failures.
struct Results {
    by_hash: BTreeMap<String, Result<table::Findings, String>>,
    diagnosed_now: usize,
    reused: usize,
    worker_peak_rss: Option<u64>,
}

/// Reads back what `out` kept and diagnoses the rest.
fn diagnose_all(
    entries: &[Entry],
    hashes: &[Result<String, String>],
    out: &Path,
    ctx: &Context,
    runner: &Runner,
    jobs: usize,
) -> Result<Results, CliError> {
    let mut by_hash: BTreeMap<String, Result<table::Findings, String>> = BTreeMap::new();
    let mut to_run: Vec<(&str, &Path)> = Vec::new();
    for (e, h) in entries.iter().zip(hashes) {
        let Ok(h) = h else { continue };
        if by_hash.contains_key(h) || to_run.iter().any(|(r, _)| *r == h.as_str()) {
            continue;
        }
        match cache::load(out, h, ctx) {
            Some(o) => {
                by_hash.insert(h.clone(), findings_of(o));
            }
            None => to_run.push((h, &e.path)),
        }
    }
    let reused = by_hash.len();
    let bar = crate::output::progress::steps(to_run.len() as u64, "diagnosing".into());
    let logs: Vec<&Path> = to_run.iter().map(|(_, p)| *p).collect();
    // Each outcome is kept the moment it is known: a run stopped after hours keeps all
    // that it finished.
    let store_error: Mutex<Option<CliError>> = Mutex::new(None);
    let keep = |i: usize, f: &Finished| {
        bar.inc(1);
        if let Ran::Kept(o) = &f.ran {
            let h = to_run[i].0;
            if let Err(err) = cache::store(out, h, ctx, o) {
                if let Ok(mut e) = store_error.lock() {
                    e.get_or_insert(err);
                }
            }
        }
    };
    let finished = runner::run_all(runner, &logs, jobs, &keep);
    bar.finish_and_clear();
    if let Some(e) = store_error.into_inner().ok().flatten() {
        return Err(e);
    }
    let mut worker_peak_rss = None;
    for ((h, _), f) in to_run.iter().zip(finished) {
        worker_peak_rss = worker_peak_rss.max(f.peak_rss_bytes);
        let r = match f.ran {
            Ran::Kept(o) => findings_of(o),
            Ran::Failed(why) => Err(why),
        };
        by_hash.insert(h.to_string(), r);
    }
    Ok(Results {
        by_hash,
        diagnosed_now: to_run.len(),
        reused,
        worker_peak_rss,
    })
}

/// `why`, a kept reason, naming the log as the row does: a refusal is kept by the log's
/// content and names the path it was diagnosed at (another copy of the log, or the absolute
/// path a distributed driver gave), so the row's path takes its place.
fn naming(why: &str, path: &Path) -> String {
    const LOG: &str = "bench log `";
    let Some(rest) = why.strip_prefix(LOG) else {
        return why.to_string();
    };
    match rest.find('`') {
        Some(end) => format!("{LOG}{}{}", path.display(), &rest[end..]),
        None => why.to_string(),
    }
}

/// The table's rows, in the entries' order.
fn rows(entries: Vec<Entry>, hashes: Vec<Result<String, String>>, r: &Results) -> Vec<Row> {
    entries
        .into_iter()
        .zip(hashes)
        .map(|(e, h)| {
            let (sha256, result) = match h {
                Err(why) => (None, Err(why)),
                Ok(h) => {
                    let result = match r.by_hash.get(&h) {
                        Some(Ok(f)) => Ok(f.clone()),
                        Some(Err(why)) => Err(naming(why, &e.path)),
                        None => Err("not diagnosed".to_string()),
                    };
                    (Some(h), result)
                }
            };
            Row {
                path: e.path.display().to_string(),
                drive: e.drive,
                recorded_at: e.recorded_at,
                t_days: e.t_days,
                sha256,
                result,
            }
        })
        .collect()
}

/// The run's summary on standard output.
fn summary_text(rows: &[Row], r: &Results, trends: &[drift::DriveTrend], out: &Path) -> String {
    let failed = rows.iter().filter(|r| r.result.is_err()).count();
    let mut s = format!(
        "{} logs: {} diagnosed now, {} read back from {}, {failed} failed\n",
        rows.len(),
        r.diagnosed_now,
        r.reused,
        out.display()
    );
    let drifting: Vec<&drift::DriveTrend> = trends.iter().filter(|t| t.drifting()).collect();
    if drifting.is_empty() {
        s.push_str("no parameter drifts significantly\n");
    } else {
        s.push_str("drive                parameter                               rate/day      ± s.e.        crossing\n");
        for t in drifting {
            let cross = t.crossing.map_or(String::new(), |(c, se)| {
                format!(
                    "{} ± {se:.0} d",
                    crate::timestamp::date(c).unwrap_or_default()
                )
            });
            s.push_str(&format!(
                "{:<20} {:<38} {:>12.4e} {:>12.3e}  {cross}\n",
                t.drive, t.parameter, t.trend.rate_per_day, t.trend.rate_se_per_day
            ));
        }
    }
    s
}

/// `eha fleet`.
pub fn run_fleet(rig: &Rig, rig_file: Option<&Path>, args: &FleetArgs) -> Result<(), CliError> {
    let start = Instant::now();
    args.check_out()?;
    let limits = limits::limits(rig, args.pressure, args.leakage_limit)?;
    let ctx = Context {
        rig_sha256: rig_identity(rig_file)?,
        eha_version: env!("CARGO_PKG_VERSION").to_string(),
    };
    let exe = std::env::current_exe()
        .map_err(|e| CliError::Failed(format!("cannot find the eha executable: {e}")))?;
    let mut entries = inputs::gather(&args.paths, args.manifest.as_deref(), &args.out)?;
    if entries.is_empty() {
        return Err(CliError::BadInput(
            "no bench logs found (folders are searched for *.csv files)".into(),
        ));
    }
    if let Some(shard) = args.shard {
        entries = entries[shard.range(entries.len())].to_vec();
    }
    let jobs = args.jobs.map_or_else(
        || std::thread::available_parallelism().map_or(1, |n| n.get()),
        |j| j as usize,
    );
    let staging = args.out.join(cache::FOLDER);
    std::fs::create_dir_all(&staging).map_err(|source| CliError::Write {
        file: staging.clone(),
        source,
    })?;
    let runner = Runner {
        exe,
        rig: rig_file.map(Path::to_path_buf),
        staging,
        timeout: args.timeout.map(Duration::from_secs_f64),
    };
    let hashes = hash_all(&entries, jobs);
    if let Some(path) = &args.plan {
        let mut outputs = Outputs::new();
        outputs.json(
            "--plan",
            path,
            &plan(&entries, &hashes, &args.out, &ctx, rig_file),
        )?;
        return outputs.commit();
    }
    let results = diagnose_all(&entries, &hashes, &args.out, &ctx, &runner, jobs)?;
    let rows = rows(entries, hashes, &results);
    let trends = drift::trends(&rows, &limits);
    let mut outputs = Outputs::new();
    let figures = commit::stage(&mut outputs, &args.out, &rows, &trends)?;
    if !args.json.as_deref().is_some_and(crate::output::is_stdout) {
        outputs.print(&summary_text(&rows, &results, &trends, &args.out));
    }
    let failed = rows.iter().filter(|r| r.result.is_err()).count();
    if let Some(path) = &args.json {
        let drifting: Vec<_> = trends
            .iter()
            .filter(|t| t.drifting())
            .map(|t| {
                json!({
                    "drive": t.drive,
                    "parameter": t.parameter,
                    "rate_per_day": t.trend.rate_per_day,
                    "rate_se_per_day": t.trend.rate_se_per_day,
                    "limit": t.limit.map(|l| l.value()),
                    "crossing_date": t.crossing.and_then(|(c, _)| crate::timestamp::date(c)),
                    "crossing_se_days": t.crossing.map(|(_, se)| se),
                })
            })
            .collect();
        outputs.json(
            "--json",
            path,
            &json!({
                "logs": rows.len(),
                "diagnosed_now": results.diagnosed_now,
                "read_back": results.reused,
                "failed": failed,
                "shard": args.shard.map(|s| format!("{}/{}", s.index, s.count)),
                "jobs": jobs,
                "out": args.out.display().to_string(),
                "limits": {
                    "precharge_pa": limits.precharge_pa,
                    "extra_leakage_m3_s_pa": limits.leakage_m3_s_pa,
                    "working_pressure_pa": limits.working_pressure_pa,
                },
                "drifting": drifting,
                "figures": figures.iter().map(|f| f.display().to_string()).collect::<Vec<_>>(),
                "worker_peak_rss_bytes": results.worker_peak_rss,
                "fleet_peak_rss_bytes": runner::own_peak_rss(),
                "elapsed_s": start.elapsed().as_secs_f64(),
            }),
        )?;
    }
    outputs.commit()?;
    if failed > 0 {
        return Err(CliError::Failed(format!(
            "{failed} of {} logs could not be diagnosed; their rows in {} say why",
            rows.len(),
            args.out.join(commit::FLEET_CSV).display()
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::naming;
    use std::path::Path;

    #[test]
    fn a_kept_refusal_names_the_rows_log() {
        let kept = "bench log `/cluster/a/logs/x.csv`, line 39, column `t_s`: `x0.1` is not a finite number";
        assert_eq!(
            naming(kept, Path::new("logs/x.csv")),
            "bench log `logs/x.csv`, line 39, column `t_s`: `x0.1` is not a finite number"
        );
        // Other reasons are the row's own already.
        let other = "diagnosis of `logs/x.csv` killed by signal 9";
        assert_eq!(naming(other, Path::new("logs/x.csv")), other);
    }
}
