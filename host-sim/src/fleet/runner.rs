//! Diagnosing logs in child processes: each log is `eha [--rig FILE] diagnose LOG --json
//! FILE` run by this very executable, `--jobs` of them at a time. A child holds one log's
//! memory and frees it all when it ends, so a worker's memory is bounded by the largest
//! log (the bench-log reader's limits), whatever the fleet's size; a child that crashes,
//! is killed (by the kernel's out-of-memory killer, an operator) or outlives `--timeout`
//! costs that log only: its row says what happened and the run goes on.
//!
//! While a child runs its peak resident memory (Linux: `VmHWM` of `/proc/PID/status`) is
//! sampled, so the run reports how much memory a worker took.

use super::cache::Outcome;
use crate::output::{interrupt, paths, transaction};
use serde_json::Value;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicU32, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// How often a running child is checked (exit, time limit, memory). [s]
const POLL: Duration = Duration::from_millis(25);

/// The most of a child's standard error kept for its message. [bytes]
const STDERR_KEPT: usize = 8 * 1024;

/// How to run one diagnosis.
#[derive(Clone, Debug)]
pub struct Runner {
    /// The eha executable.
    pub exe: PathBuf,
    /// The rig file (`--rig`), if not the nominal rig.
    pub rig: Option<PathBuf>,
    /// Folder for the children's JSON files (hidden names, removed when read).
    pub staging: PathBuf,
    /// Longest a diagnosis may take before it is stopped.
    pub timeout: Option<Duration>,
}

/// What became of one diagnosis.
#[derive(Clone, Debug, PartialEq)]
pub enum Ran {
    /// An outcome the log's content decides (kept for the next run).
    Kept(Outcome),
    /// Killed, timed out or failed otherwise (tried again next run): why.
    Failed(String),
}

/// One finished diagnosis: the outcome and the child's peak resident memory. [bytes]
#[derive(Clone, Debug, PartialEq)]
pub struct Finished {
    /// What became of it.
    pub ran: Ran,
    /// The child's peak resident set, where the system reports it. [bytes]
    pub peak_rss_bytes: Option<u64>,
}

static STAGED: AtomicU32 = AtomicU32::new(0);

/// Diagnoses every log of `logs` with `workers` children at a time; `done` is called with
/// the log's index as each finishes (to keep its outcome at once, and for progress).
/// Results in the order of `logs`.
pub fn run_all(
    runner: &Runner,
    logs: &[&Path],
    workers: usize,
    done: &(dyn Fn(usize, &Finished) + Sync),
) -> Vec<Finished> {
    let next = AtomicUsize::new(0);
    let workers = workers.clamp(1, logs.len().max(1));
    let mut out: Vec<Option<Finished>> = vec![None; logs.len()];
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..workers)
            .map(|_| {
                s.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(log) = logs.get(i) else { break };
                        let f = runner.diagnose(log);
                        done(i, &f);
                        mine.push((i, f));
                    }
                    mine
                })
            })
            .collect();
        for h in handles {
            // A worker thread only runs children and cannot panic short of a bug; its
            // logs are then reported as failed below rather than lost.
            if let Ok(mine) = h.join() {
                for (i, f) in mine {
                    out[i] = Some(f);
                }
            }
        }
    });
    out.into_iter()
        .map(|f| {
            f.unwrap_or(Finished {
                ran: Ran::Failed("the worker running this diagnosis stopped".into()),
                peak_rss_bytes: None,
            })
        })
        .collect()
}

impl Runner {
    /// Diagnoses `log` in a child process.
    pub fn diagnose(&self, log: &Path) -> Finished {
        let n = STAGED.fetch_add(1, Ordering::Relaxed);
        let json = self
            .staging
            .join(format!(".run-{}-{n}.json", std::process::id()));
        let _cleanup = interrupt::remove_on_interrupt(&json);
        let mut cmd = Command::new(&self.exe);
        if let Some(rig) = &self.rig {
            cmd.arg("--rig").arg(rig);
        }
        cmd.arg("diagnose")
            .arg(log)
            .arg("--json")
            .arg(&json)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped());
        let finished = match cmd.spawn() {
            Ok(child) => {
                let pid = child.id();
                let finished = self.watch(child, log, &json);
                remove_left_behind(&json, pid);
                finished
            }
            Err(e) => Finished {
                ran: Ran::Failed(format!(
                    "could not start `{} diagnose` for `{}`: {e}",
                    self.exe.display(),
                    log.display()
                )),
                peak_rss_bytes: None,
            },
        };
        let _ = std::fs::remove_file(&json);
        finished
    }

    /// Waits for `child` (stopping it at the time limit), sampling its memory, and reads
    /// what it left.
    fn watch(&self, mut child: Child, log: &Path, json: &Path) -> Finished {
        let stderr = child.stderr.take().map(|mut pipe| {
            std::thread::spawn(move || {
                let mut kept: Vec<u8> = Vec::new();
                let mut buf = [0u8; 4096];
                while let Ok(n) = pipe.read(&mut buf) {
                    if n == 0 {
                        break;
                    }
                    kept.extend_from_slice(&buf[..n]);
                    if kept.len() > 2 * STDERR_KEPT {
                        kept.drain(..kept.len() - STDERR_KEPT);
                    }
                }
                String::from_utf8_lossy(&kept).into_owned()
            })
        });
        let start = Instant::now();
        let mut peak = None;
        let mut timed_out = false;
        let status = loop {
            match child.try_wait() {
                Ok(Some(status)) => break Ok(status),
                Ok(None) => {}
                Err(e) => break Err(e),
            }
            peak = peak_rss(child.id()).or(peak);
            if self.timeout.is_some_and(|t| start.elapsed() > t) {
                let _ = child.kill();
                timed_out = true;
                break child.wait();
            }
            std::thread::sleep(POLL);
        };
        let message = stderr
            .and_then(|h| h.join().ok())
            .map(|s| last_message(&s))
            .unwrap_or_default();
        let ran = match status {
            Err(e) => Ran::Failed(format!("lost the diagnosis of `{}`: {e}", log.display())),
            Ok(_) if timed_out => Ran::Failed(format!(
                "diagnosis of `{}` stopped after the {} s time limit (--timeout)",
                log.display(),
                self.timeout.map_or(0.0, |t| t.as_secs_f64())
            )),
            Ok(status) => outcome(status, log, json, message),
        };
        Finished {
            ran,
            peak_rss_bytes: peak,
        }
    }
}

/// Removes what the child `pid`, killed while it checked or wrote `json`, left beside
/// it: its probe of the folder and its staged copies of `json`. The JSON's name holds this
/// process's id and a counter, so nothing else matches.
fn remove_left_behind(json: &Path, pid: u32) {
    if let Some(dir) = json.parent() {
        let _ = std::fs::remove_file(paths::probe_path(dir, pid));
    }
    transaction::remove_staged_files(json);
}

/// What a finished child's exit status and output mean.
fn outcome(status: ExitStatus, log: &Path, json: &Path, message: String) -> Ran {
    let said = |fallback: String| {
        if message.is_empty() {
            fallback
        } else {
            message.clone()
        }
    };
    match status.code() {
        Some(0) => match std::fs::read_to_string(json)
            .ok()
            .and_then(|t| serde_json::from_str::<Value>(&t).ok())
        {
            Some(v) if v.is_object() => Ran::Kept(Outcome::Diagnosed(v)),
            _ => Ran::Failed(format!(
                "diagnosis of `{}` ended without its JSON",
                log.display()
            )),
        },
        Some(2) => Ran::Kept(Outcome::BadInput(said(format!(
            "bench log `{}`: refused as bad input",
            log.display()
        )))),
        Some(code) => Ran::Failed(format!(
            "diagnosis failed (exit status {code}): {}",
            said(format!("`{}`", log.display()))
        )),
        None => Ran::Failed(format!(
            "diagnosis of `{}` killed by {}",
            log.display(),
            signal_name(status)
        )),
    }
}

/// The child's message: its last `eha: error:` line without the prefix, else its last
/// non-empty line.
fn last_message(stderr: &str) -> String {
    let lines: Vec<&str> = stderr
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    lines
        .iter()
        .rev()
        .find_map(|l| l.strip_prefix("eha: error: "))
        .or(lines.last().copied())
        .unwrap_or("")
        .to_string()
}

#[cfg(unix)]
fn signal_name(status: ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    match status.signal() {
        Some(s) => {
            let name = match s {
                1 => " (SIGHUP)",
                2 => " (SIGINT)",
                6 => " (SIGABRT)",
                9 => " (SIGKILL, the out-of-memory killer or an operator)",
                11 => " (SIGSEGV)",
                15 => " (SIGTERM)",
                _ => "",
            };
            format!("signal {s}{name}")
        }
        None => format!("{status}"),
    }
}

#[cfg(not(unix))]
fn signal_name(status: ExitStatus) -> String {
    format!("{status}")
}

/// A process's peak resident set (`VmHWM`), on Linux. [bytes]
pub fn peak_rss(pid: u32) -> Option<u64> {
    vm_hwm(&format!("/proc/{pid}/status"))
}

/// This process's peak resident set, on Linux. [bytes]
pub fn own_peak_rss() -> Option<u64> {
    vm_hwm("/proc/self/status")
}

fn vm_hwm(status_file: &str) -> Option<u64> {
    let text = std::fs::read_to_string(status_file).ok()?;
    let line = text.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_message_is_the_last_error_line() {
        let s = "diagnosing x\n\neha: error: bench log `x`, line 5: bad\n";
        assert_eq!(last_message(s), "bench log `x`, line 5: bad");
        assert_eq!(last_message("  \nsomething else\n"), "something else");
        assert_eq!(last_message(""), "");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn own_peak_memory_is_read() {
        let peak = own_peak_rss().unwrap();
        assert!(peak > 100 * 1024, "{peak}");
    }

    #[test]
    fn a_killed_childs_probe_and_staged_copies_go_and_nothing_else() {
        let dir = tempfile::tempdir().unwrap();
        let json = dir.path().join(".run-7-3.json");
        let names = [
            ".eha-probe-41",
            ".eha-probe-42",
            "..run-7-3.json.Ab12Cd.eha-tmp",
            "..run-7-3.json.Zz99Yy.eha-tmp",
            "..run-7-31.json.Ab12Cd.eha-tmp",
            "..run-7-3.json.Ab12Cd.eha-staging",
            "x.json",
        ];
        for n in names {
            std::fs::write(dir.path().join(n), "{").unwrap();
        }
        remove_left_behind(&json, 42);
        let mut left: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(
            left,
            [
                "..run-7-3.json.Ab12Cd.eha-staging",
                "..run-7-31.json.Ab12Cd.eha-tmp",
                ".eha-probe-41",
                "x.json"
            ]
        );
    }
}
