//! The paper's accumulator study: the selection method of Section 4.3
//! ([`accumulator_design`], `eha accumulator-design`) and the precharge sweep of Section 5.2
//! ([`precharge_sweep`], `eha sweep-precharge`).

pub mod accumulator_design;
pub mod precharge_sweep;

use crate::output::paths::Declared;
use crate::output::{is_stdout, CliError, Outputs};
use crate::values::positive_f64;
use clap::Args;
use plant_model::Rig;
use std::path::PathBuf;

/// `eha accumulator-design`.
#[derive(Debug, Args)]
pub struct AccumulatorDesignArgs {
    /// Write the results as JSON (`-`: standard output, instead of the table).
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// Working (holding) pressure, gauge: the paper's low-speed pressure-holding case. [Pa]
    #[arg(long, value_name = "PA", default_value = "5e6", value_parser = positive_f64, allow_negative_numbers = true)]
    pub pressure: f64,
}

impl AccumulatorDesignArgs {
    /// The files it writes.
    pub fn paths(&self) -> Declared<'_> {
        Declared::default().file("--json", self.json.as_ref())
    }
}

/// `eha accumulator-design`: a table on standard output, JSON with `--json`.
pub fn run_accumulator_design(rig: &Rig, a: &AccumulatorDesignArgs) -> Result<(), CliError> {
    let design = accumulator_design::design(rig, a.pressure)
        .map_err(|e| CliError::BadInput(e.to_string()))?;
    let mut out = Outputs::new();
    if let Some(path) = &a.json {
        let value = serde_json::to_value(&design).map_err(|e| CliError::Failed(e.to_string()))?;
        out.json("--json", path, &value)?;
    }
    if !a.json.as_deref().is_some_and(is_stdout) {
        out.print(&design.to_table());
    }
    out.commit()
}
