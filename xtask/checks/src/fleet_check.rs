//! `eha fleet` against its distributed forms, on a small fleet `eha simulate` writes (two
//! drives, three monthly 1 s logs each, and a corrupt copy of one):
//!
//! 1. `eha fleet` alone, two jobs, the logs named by a relative path as a user would (the
//!    driver hands its workers absolute ones: the tables must not show it);
//! 2. the Dask driver (`tools/fleet_dask.py`) on a local `dask.distributed` cluster of two
//!    worker processes: its `fleet.csv`, `fleet.json` and `trends.csv` must be byte for
//!    byte those of step 1;
//! 3. `eha fleet --shard 0/2` and `--shard 1/2`, each in a folder of its own (diagnosing
//!    afresh): their tables concatenated must be the table of step 1.
//!
//! The Python side runs with the interpreter of the virtual environment `.ci/run` and
//! [`xtask::setup`] make, with `dask` and `distributed` from `xtask/requirements.txt`
//! (missing is a failure, never a skip).

use anyhow::{bail, Context, Result};
use serde_json::Value;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The small fleet: (drive, start time) of each log.
const LOGS: [(&str, &str); 6] = [
    ("press-1", "2026-01-04T07:30:00Z"),
    ("press-1", "2026-02-04T07:30:00Z"),
    ("press-1", "2026-03-04T07:30:00Z"),
    ("press-2", "2026-01-06T07:30:00Z"),
    ("press-2", "2026-02-06T07:30:00Z"),
    ("press-2", "2026-03-06T07:30:00Z"),
];

fn run(what: &str, cmd: &mut Command) -> Result<Output> {
    eprintln!("fleet check: {what}: {cmd:?}");
    let o = cmd
        .output()
        .with_context(|| format!("{what}: could not start {cmd:?}"))?;
    Ok(o)
}

/// `eha fleet` exits 1 here (the corrupt log): anything else is a failure.
fn expect_some_failed(what: &str, o: &Output) -> Result<()> {
    if o.status.code() != Some(1) {
        bail!(
            "{what}: exit status {:?}, expected 1 (one corrupt log)\n{}",
            o.status.code(),
            String::from_utf8_lossy(&o.stderr)
        );
    }
    Ok(())
}

/// The small fleet, written by `eha simulate` into `dir`.
fn make_fleet(eha: &Path, dir: &Path) -> Result<()> {
    for (k, (drive, at)) in LOGS.iter().enumerate() {
        let log = dir.join(drive).join(format!("{}.csv", &at[..10]));
        fs::create_dir_all(log.parent().unwrap_or(dir))?;
        let o = run(
            "simulate",
            Command::new(eha)
                .args(["simulate", "--scenario", "pressure-hold", "--duration", "1"])
                .args(["--log-rate", "1000", "--seed", &(k + 1).to_string()])
                .args(["--drive", drive, "--recorded-at", at, "--out"])
                .arg(&log),
        )?;
        if !o.status.success() {
            bail!("eha simulate: {}", String::from_utf8_lossy(&o.stderr));
        }
    }
    // A corrupt copy of the first log: a value made unreadable on data row 30.
    let first = dir.join("press-1").join("2026-01-04.csv");
    let text = fs::read_to_string(&first)?;
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let header = lines
        .iter()
        .position(|l| !l.starts_with('#'))
        .context("a log without a header")?;
    lines[header + 30].insert(0, 'x');
    fs::write(
        dir.join("press-1").join("corrupt.csv"),
        lines.join("\n") + "\n",
    )?;
    Ok(())
}

/// The data rows of a fleet table (header dropped), and the header.
fn table(path: &Path) -> Result<(String, Vec<String>)> {
    let text = fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut lines = text.lines().map(str::to_string);
    let header = lines.next().context("an empty table")?;
    Ok((header, lines.collect()))
}

fn json_rows(path: &Path) -> Result<Vec<Value>> {
    let v: Value = serde_json::from_str(&fs::read_to_string(path)?)?;
    Ok(v["rows"].as_array().cloned().unwrap_or_default())
}

/// Runs the check with the Python interpreter `python`.
pub fn check(python: &Path) -> Result<()> {
    let root = xtask::workspace::root();
    let eha = xtask::workspace::eha_binary("eha for the fleet check")?;
    let base = xtask::workspace::target_dir().join("fleet-check");
    let _ = fs::remove_dir_all(&base);
    let logs = base.join("logs");
    fs::create_dir_all(&logs)?;
    make_fleet(&eha, &logs)?;
    let alone: PathBuf = base.join("alone");
    let o = run(
        "eha fleet",
        Command::new(&eha)
            .arg("fleet")
            .current_dir(&base)
            .arg("logs")
            .arg("--out")
            .arg(&alone)
            .args(["--jobs", "2"]),
    )?;
    expect_some_failed("eha fleet", &o)?;

    let dask = base.join("dask");
    let o = run(
        "the Dask driver on a local cluster of two workers",
        Command::new(python)
            .arg(root.join("tools").join("fleet_dask.py"))
            .current_dir(&base)
            .arg("logs")
            .arg("--out")
            .arg(&dask)
            .arg("--eha")
            .arg(&eha)
            .args(["--local-workers", "2"]),
    )?;
    expect_some_failed("tools/fleet_dask.py", &o)?;
    let said = String::from_utf8_lossy(&o.stderr);
    if !said.contains("7 logs diagnosed on the cluster") {
        bail!("the Dask driver did not diagnose the 7 logs itself:\n{said}");
    }
    for file in ["fleet.csv", "fleet.json", "trends.csv"] {
        let a = fs::read(alone.join(file))?;
        let b = fs::read(dask.join(file))?;
        if a != b {
            bail!(
                "{file}: the Dask driver's differs from eha fleet's ({} and {})",
                dask.join(file).display(),
                alone.join(file).display()
            );
        }
    }

    let (header, whole) = table(&alone.join("fleet.csv"))?;
    let mut concatenated = Vec::new();
    let mut concatenated_json = Vec::new();
    for k in 0..2 {
        let out = base.join(format!("shard-{k}"));
        let o = run(
            "eha fleet --shard",
            Command::new(&eha)
                .arg("fleet")
                .current_dir(&base)
                .arg("logs")
                .arg("--out")
                .arg(&out)
                .args(["--shard", &format!("{k}/2")]),
        )?;
        if o.status.code().is_none_or(|c| c > 1) {
            bail!(
                "eha fleet --shard {k}/2: {}",
                String::from_utf8_lossy(&o.stderr)
            );
        }
        let (h, rows) = table(&out.join("fleet.csv"))?;
        if h != header {
            bail!("shard {k}/2's header differs from the whole table's");
        }
        concatenated.extend(rows);
        concatenated_json.extend(json_rows(&out.join("fleet.json"))?);
    }
    if concatenated != whole {
        bail!("the shards' fleet.csv concatenated differ from the whole fleet.csv");
    }
    if concatenated_json != json_rows(&alone.join("fleet.json"))? {
        bail!("the shards' fleet.json rows concatenated differ from the whole fleet.json's");
    }
    eprintln!(
        "fleet check: {} rows; the Dask driver's tables equal eha fleet's, and two shards \
         concatenate into them",
        whole.len()
    );
    Ok(())
}
