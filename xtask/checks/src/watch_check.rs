//! The PIL's decoded telemetry, as it comes out of the run just made, piped into
//! `eha watch --out` in a real terminal (tmux), as a bench engineer pipes `probe-rs run`
//! into it: the captured screen must show the run's frame count, the drive's mode by name,
//! the pulsation and the three trace panels, and the bench log the live view writes must
//! hold, row for row and digit for digit, what `eha ingest` made of the same text — so a
//! watched session feeds `eha diagnose` and `eha tune` exactly as an ingested one does.

use anyhow::{bail, Context, Result};
use firmware::Mode;
use std::fs;
use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// How long the view may take to read the run's telemetry and finish the log. [s]
const END_TIMEOUT_S: u64 = 60;

fn tmux(socket: &str, args: &[&str]) -> Result<Output> {
    Command::new("tmux")
        .arg("-L")
        .arg(socket)
        .args(args)
        .output()
        .context("tmux is needed for the live view's check (cargo xtask test installs it)")
}

/// Polls `f` every 100 ms for up to `limit`.
fn wait_for(limit: Duration, mut f: impl FnMut() -> Result<bool>) -> Result<bool> {
    let start = Instant::now();
    while start.elapsed() < limit {
        if f()? {
            return Ok(true);
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    Ok(false)
}

/// The data rows of a bench log (its `#` metadata lines left out: they name the source).
fn rows(path: &Path) -> Result<Vec<String>> {
    let text = fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    Ok(text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(str::to_string)
        .collect())
}

/// The mode code of the last telemetry line of the decoded text.
fn last_mode(defmt_log: &str) -> Result<Mode> {
    let code = defmt_log
        .lines()
        .rev()
        .find_map(|l| {
            l.contains("EHA1 ")
                .then(|| l.split_once(" mode="))
                .flatten()
        })
        .and_then(|(_, rest)| rest.split_whitespace().next())
        .context("the PIL's telemetry has no `mode=` field")?;
    let code: u8 = code
        .parse()
        .with_context(|| format!("mode `{code}` in the PIL's telemetry"))?;
    Mode::from_code(code).with_context(|| format!("mode {code} is no firmware mode"))
}

/// Runs the check: `eha` is the binary, `defmt_log` the decoded text, `ingested` the
/// bench log `eha ingest` wrote from it, `out_dir` where the view's log and screen go.
pub fn check(eha: &Path, defmt_log: &Path, ingested: &Path, out_dir: &Path) -> Result<()> {
    let text = fs::read_to_string(defmt_log)?;
    let frames = text.lines().filter(|l| l.contains("EHA1 ")).count();
    let mode = last_mode(&text)?;
    let log = out_dir.join("watch.csv");
    let status = out_dir.join("watch-status.txt");
    let _ = fs::remove_file(&log);
    let _ = fs::remove_file(&status);
    let socket = format!("eha-xtask-watch-{}", std::process::id());
    let command = format!(
        "cat '{}' | '{}' watch --out '{}'; echo $? > '{}'",
        defmt_log.display(),
        eha.display(),
        log.display(),
        status.display()
    );
    eprintln!("\n=== eha watch on the PIL's telemetry, in tmux: {command}");
    let session = ["new-session", "-d", "-x", "120", "-y", "40", "-s", "pil"];
    let started = tmux(&socket, &[&session[..], &[command.as_str()]].concat())?;
    if !started.status.success() {
        bail!(
            "tmux new-session failed: {}",
            String::from_utf8_lossy(&started.stderr)
        );
    }
    let mut screen = String::new();
    let ended = wait_for(Duration::from_secs(END_TIMEOUT_S), || {
        let o = tmux(&socket, &["capture-pane", "-p", "-t", "pil"])?;
        screen = String::from_utf8_lossy(&o.stdout).into_owned();
        Ok(screen.contains("stream ended") && screen.contains("written"))
    })?;
    let quit = tmux(&socket, &["send-keys", "-t", "pil", "q"])?;
    let exited = wait_for(Duration::from_secs(20), || Ok(status.exists()))?;
    let _ = tmux(&socket, &["kill-server"]);
    fs::write(out_dir.join("watch-screen.txt"), &screen)?;
    if !ended || !quit.status.success() || !exited {
        bail!("eha watch did not show the end of the PIL's stream and quit on q:\n{screen}");
    }
    let code = fs::read_to_string(&status)?;
    if code.trim() != "0" {
        bail!(
            "eha watch exited with {} on the PIL's telemetry",
            code.trim()
        );
    }
    for expected in [
        format!("mode {}", mode.name()),
        format!("frames {frames}"),
        "malformed 0".to_string(),
        "kPa p-p".to_string(),
        format!("{frames} rows, written"),
        "[MPa]".to_string(),
        "[rad/s]".to_string(),
        "[A]".to_string(),
    ] {
        if !screen.contains(&expected) {
            bail!("`{expected}` is not on eha watch's screen:\n{screen}");
        }
    }
    let (watched, ingested_rows) = (rows(&log)?, rows(ingested)?);
    if watched != ingested_rows {
        let k = watched
            .iter()
            .zip(&ingested_rows)
            .position(|(a, b)| a != b)
            .unwrap_or(watched.len().min(ingested_rows.len()));
        bail!(
            "eha watch's log ({} lines) and eha ingest's ({} lines) differ from data line {k}",
            watched.len(),
            ingested_rows.len()
        );
    }
    eprintln!(
        "eha watch: {frames} frames of the PIL run on screen (mode {}), its log equals \
         eha ingest's ({} rows); screen in {}",
        mode.name(),
        watched.len() - 1,
        out_dir.join("watch-screen.txt").display()
    );
    Ok(())
}
