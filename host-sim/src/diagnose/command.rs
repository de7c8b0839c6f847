//! `eha diagnose LOG.csv [--json PATH] [--report DIR]`: reads the log, diagnoses it against
//! the rig (nominal or `--rig`), prints a summary, writes the contract's JSON and the report.

use super::analysis::{analyse_reporting, Precision, MIN_ANALYSED_INTERVAL_S, STEPS};
use super::candidates::short;
use super::diagnosis::Diagnosis;
use super::error::DiagnoseError;
use crate::output::paths::Declared;
use crate::output::{CliError, Outputs};
use clap::Args;
use plant_model::Rig;
use std::path::PathBuf;

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

impl DiagnoseArgs {
    /// The files it reads and writes.
    pub fn paths(&self) -> Declared<'_> {
        Declared::default()
            .input("LOG", Some(&self.log))
            .file("--json", self.json.as_ref())
            .dir("--report", self.report.as_ref(), super::report::FILES)
    }
}

/// A diagnosis error as the command reports it: what the log holds is bad input (exit 2),
/// naming the log's columns rather than the replay's internal state.
fn input_or_failure(e: DiagnoseError, log: &std::path::Path) -> CliError {
    match e {
        DiagnoseError::Log(e) => CliError::BenchLog(e),
        DiagnoseError::Rig(e) => {
            let column = match e.parameter {
                "initial.p_a_pa" => "p_pa",
                "initial.p_b_pa" => "p_low_pa",
                "initial.x_m" => "x_m",
                "initial.omega_rad_s" => "speed_rad_s (or theta_m_rad)",
                "initial.theta_m_rad" => "theta_m_rad",
                _ => return CliError::BadInput(format!("the rig cannot be replayed: {e}")),
            };
            CliError::BadInput(format!(
                "bench log `{}`: the first rows' {column} give the replay a start the rig \
                 cannot take ({}): is the log of this rig (--rig), in SI units?",
                log.display(),
                e.reason
            ))
        }
    }
}

/// `eha diagnose`.
pub fn run_diagnose(rig: &Rig, args: &DiagnoseArgs) -> Result<(), CliError> {
    let (mut log, rows) = crate::bench_log::read_thinned(&args.log, MIN_ANALYSED_INTERVAL_S)?;
    crate::bench_log::replayable::check(&log, rig, &args.log)?;
    // The setpoint was checked as it was read; the diagnosis never reads it.
    log.p_ref_pa = Vec::new();
    let read_as = if rows > log.len() {
        format!(
            " of {rows} rows (a row closer than {:.2} ms to the last one read is skipped)",
            MIN_ANALYSED_INTERVAL_S * 1e3
        )
    } else {
        String::new()
    };
    let bar = crate::output::progress::steps(
        STEPS,
        format!("diagnosing {} ({} rows)", args.log.display(), log.len()),
    );
    bar.set_prefix("facts");
    let analysis = analyse_reporting(&log, rig, Precision::Diagnosis, &|next: &'static str| {
        bar.inc(1);
        bar.set_prefix(next);
    });
    bar.finish_and_clear();
    let analysis = analysis.map_err(|e| input_or_failure(e, &args.log))?;
    let text = summary(&args.log, &read_as, &analysis.diagnosis);
    let mut out = Outputs::new();
    out.print(&text);
    if let Some(dir) = &args.report {
        out.folder("--report", dir, super::report::FILES, |folder| {
            super::report::write_report(folder, &args.log, &analysis)
        })?;
    }
    if let Some(path) = &args.json {
        let value = serde_json::to_value(&analysis.diagnosis)
            .map_err(|e| CliError::Failed(e.to_string()))?;
        out.json("--json", path, &value)?;
    }
    out.commit()
}

/// The terminal's summary of diagnosis `d` of the log at `path` (`read_as`: how its rows
/// were read): the segments, what it names, the ranking, each named effect's evidence, the
/// validation fit per signal.
fn summary(path: &std::path::Path, read_as: &str, d: &Diagnosis) -> String {
    let mut text = format!(
        "{}: {} samples{read_as}; identification {:.3}–{:.3} s, validation {:.3}–{:.3} s\n",
        path.display(),
        d.samples,
        d.identification_segment_s[0],
        d.identification_segment_s[1],
        d.validation_segment_s[0],
        d.validation_segment_s[1]
    );
    text.push_str(&format!("named: {}\n", d.named_label()));
    text.push_str("rank  effect                       score  parameters\n");
    for (k, c) in d.causes.iter().enumerate() {
        let params: Vec<String> = c
            .parameters
            .iter()
            .map(|(n, v)| format!("{n}={}", short(*v)))
            .collect();
        text.push_str(&format!(
            "{:>4}  {:<22} {:>11.3}  {}\n",
            k + 1,
            c.effect,
            c.score,
            params.join(" ")
        ));
    }
    for c in d.named_causes() {
        text.push_str(&format!("cause: {} — {}\n", c.effect, c.evidence_in_full()));
    }
    text.push_str("validation fit [%]   baseline  extended\n");
    for (signal, b) in &d.baseline.fit_percent_by_signal {
        let e = d.extended.fit_percent_by_signal.get(signal).copied();
        text.push_str(&format!(
            "  {:<18} {:>8.1}  {:>8.1}\n",
            signal,
            b,
            e.unwrap_or(f64::NAN)
        ));
    }
    text
}
