//! The commit point of a fleet run: the finished tables and figures put into the output
//! folder — `fleet.csv`, `fleet.json`, `trends.csv` and `plots/` — and nowhere else.
//! They are staged as outputs of the run's transaction ([`crate::output::Outputs`]): each
//! table a file, `plots/` a folder replaced whole, all moved into place together when the
//! run commits, so a run stopped at any moment leaves every one of them as the last run
//! left it or all of them complete. (The kept diagnoses beside them, `diagnoses/`, are
//! committed one by one as they are made: [`super::cache`].)

use super::drift::{self, DriveTrend};
use super::table::{self, Row};
use crate::output::{CliError, Outputs};
use serde_json::json;
use std::path::{Path, PathBuf};

/// The table of logs.
pub const FLEET_CSV: &str = "fleet.csv";
/// The same, as JSON.
pub const FLEET_JSON: &str = "fleet.json";
/// The trends.
pub const TRENDS_CSV: &str = "trends.csv";
/// The folder of the drifting drives' figures.
pub const PLOTS: &str = "plots";

/// Stages the run's tables and figures for `out` in `outputs`; returns the figures (SVG)
/// that the commit puts in place.
pub fn stage(
    outputs: &mut Outputs,
    out: &Path,
    rows: &[Row],
    trends: &[DriveTrend],
) -> Result<Vec<PathBuf>, CliError> {
    outputs.file_with("--out", &out.join(FLEET_CSV), |w| table::write_csv(w, rows))?;
    outputs.file_with("--out", &out.join(FLEET_JSON), |w| {
        let doc = json!({
            "logs": rows.len(),
            "failed": rows.iter().filter(|r| r.result.is_err()).count(),
            "rows": rows.iter().map(table::row_json).collect::<Vec<_>>(),
        });
        serde_json::to_writer_pretty(&mut *w, &doc)?;
        w.write_all(b"\n")
    })?;
    outputs.file_with("--out", &out.join(TRENDS_CSV), |w| {
        drift::write_csv(w, trends)
    })?;
    let plots = out.join(PLOTS);
    let mut figures = Vec::new();
    outputs.folder("--out", &plots, super::figures::FILES, |d| {
        figures = super::figures::write(d, trends)?;
        Ok(())
    })?;
    Ok(figures.iter().map(|f| plots.join(f)).collect())
}
