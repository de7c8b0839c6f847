//! The commit point of a fleet run: the finished tables and figures put into the output
//! folder — `fleet.csv`, `fleet.json`, `trends.csv` and `plots/` — and nowhere else.
//! Each table is written atomically ([`crate::output::atomic`]); the figures are drawn into
//! a hidden staging folder and swapped in whole, so a run stopped at any moment leaves
//! every file either as the last run left it or complete.

use super::drift::{self, DriveTrend};
use super::table::{self, Row};
use crate::output::{atomic, interrupt, CliError};
use serde_json::json;
use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// The table of logs.
pub const FLEET_CSV: &str = "fleet.csv";
/// The same, as JSON.
pub const FLEET_JSON: &str = "fleet.json";
/// The trends.
pub const TRENDS_CSV: &str = "trends.csv";
/// The folder of the drifting drives' figures.
pub const PLOTS: &str = "plots";

fn write_file(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), CliError> {
    atomic::write_with(path, fill).map_err(|source| CliError::Write {
        file: path.to_path_buf(),
        source,
    })
}

/// Writes the run's tables and figures into `out`; returns the figures (SVG) written.
pub fn commit(out: &Path, rows: &[Row], trends: &[DriveTrend]) -> Result<Vec<PathBuf>, CliError> {
    let staging = out.join(format!(".{PLOTS}.staging-{}", std::process::id()));
    let _cleanup = interrupt::remove_on_interrupt(&staging);
    let _ = fs::remove_dir_all(&staging);
    fs::create_dir_all(&staging).map_err(|source| CliError::Write {
        file: staging.clone(),
        source,
    })?;
    let figures = super::figures::write(&staging, trends).map_err(CliError::Failed);
    let figures = match figures {
        Ok(f) => f,
        Err(e) => {
            let _ = fs::remove_dir_all(&staging);
            return Err(e);
        }
    };
    write_file(&out.join(FLEET_CSV), |w| table::write_csv(w, rows))?;
    write_file(&out.join(FLEET_JSON), |w| {
        let doc = json!({
            "logs": rows.len(),
            "failed": rows.iter().filter(|r| r.result.is_err()).count(),
            "rows": rows.iter().map(table::row_json).collect::<Vec<_>>(),
        });
        serde_json::to_writer_pretty(&mut *w, &doc)?;
        w.write_all(b"\n")
    })?;
    write_file(&out.join(TRENDS_CSV), |w| drift::write_csv(w, trends))?;
    let plots = out.join(PLOTS);
    swap_in(&staging, &plots).map_err(|source| CliError::Write {
        file: plots.clone(),
        source,
    })?;
    Ok(figures
        .iter()
        .filter_map(|f| f.file_name().map(|n| plots.join(n)))
        .collect())
}

/// Puts the folder `staging` in place of `target` (which may not exist yet): the old one
/// is renamed aside first and removed after.
fn swap_in(staging: &Path, target: &Path) -> io::Result<()> {
    let old = target.with_file_name(format!(".{PLOTS}.old-{}", std::process::id()));
    let had = match fs::symlink_metadata(target) {
        Ok(m) if m.is_dir() => true,
        Ok(_) => {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "is not a folder; eha never replaces it",
            ))
        }
        Err(e) if e.kind() == io::ErrorKind::NotFound => false,
        Err(e) => return Err(e),
    };
    if had {
        let _ = fs::remove_dir_all(&old);
        fs::rename(target, &old)?;
    }
    fs::rename(staging, target)?;
    if had {
        let _ = fs::remove_dir_all(&old);
    }
    Ok(())
}
