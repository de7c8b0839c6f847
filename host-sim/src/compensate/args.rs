//! The command line of `eha compensate`: the logs to learn from, the table file and the
//! other outputs, the method, the effects left out.

use super::method::Method;
use crate::output::paths::Declared;
use clap::Args;
use std::path::PathBuf;

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
