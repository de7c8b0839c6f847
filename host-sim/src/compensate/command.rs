//! `eha compensate`: the arguments and logs checked before any work, then the feed-forward
//! learned and predicted ([`super::outcome`]), then the table file, the CAN log and the JSON
//! written together, and the summary and the CAN frames printed ([`super::summary`]).

use super::args::CompensateArgs;
use super::outcome::learn_and_predict;
use super::{can, learn, summary};
use crate::bench_log::{self, BenchLog};
use crate::feedforward::flow;
use crate::output::{CliError, Outputs};
use firmware::can_protocol::{Frame, NodeId};
use plant_model::Rig;

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
