//! `eha rig [--json PATH]`: the rig every command runs on (the nominal rig, or `--rig
//! FILE`) printed in the rig-file format ([`crate::rig_file`]), or as JSON.

use crate::output::paths::Declared;
use crate::output::{is_stdout, CliError, Outputs};
use crate::rig_file::to_toml;
use clap::Args;
use plant_model::Rig;
use std::path::PathBuf;

/// `eha rig`.
#[derive(Debug, Args)]
pub struct RigArgs {
    /// Also write the rig as JSON (`-`: standard output, instead of the TOML).
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
}

impl RigArgs {
    /// The files it writes.
    pub fn paths(&self) -> Declared<'_> {
        Declared::default().file("--json", self.json.as_ref())
    }
}

/// `eha rig`: the TOML on standard output; with `--json PATH` the JSON too (with `--json -`
/// only the JSON, so standard output stays one parseable document).
pub fn run_rig(rig: &Rig, a: &RigArgs) -> Result<(), CliError> {
    let mut out = Outputs::new();
    if let Some(path) = &a.json {
        let value = serde_json::to_value(rig).map_err(|e| CliError::Failed(e.to_string()))?;
        out.json("--json", path, &value)?;
    }
    if !a.json.as_deref().is_some_and(is_stdout) {
        out.print(&to_toml(rig));
    }
    out.commit()
}
