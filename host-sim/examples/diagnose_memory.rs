//! Peak memory of `eha diagnose` against the size of the log it reads: the benchmark of
//! `docs/memory.md`. Simulates logs of several tests, rates and lengths with `eha
//! simulate`, writes each also with only the six required columns at six significant
//! digits in their shortest form (the tersest a bench logger writes, a few tens of bytes a
//! row), and diagnoses each in a child process of its own, whose peak resident memory the
//! kernel reports (`wait4`'s `ru_maxrss`). Prints a Markdown table: each log's rows, its
//! size, the diagnosis's peak and their ratio, and the bytes a row the diagnosis holds above
//! what it holds for the shortest log (the program itself) against the bytes a row of the
//! file.
//!
//! ```text
//! cargo build --release -p host-sim --bin eha
//! cargo run --release -p host-sim --example diagnose_memory -- [target/release/eha]
//! ```

use host_sim::bench_log::{self, BenchLog};
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};

/// One log of the benchmark.
struct Case {
    /// Scenario of `eha simulate`.
    scenario: &'static str,
    /// Simulated duration. [s]
    duration_s: u32,
    /// Log rate. [Hz]
    rate_hz: u32,
    /// Written with only the required columns, tersely.
    terse: bool,
}

const CASES: &[Case] = &[
    Case {
        scenario: "pressure-hold",
        duration_s: 120,
        rate_hz: 1000,
        terse: true,
    },
    Case {
        scenario: "pressure-hold",
        duration_s: 600,
        rate_hz: 1000,
        terse: true,
    },
    Case {
        scenario: "staircase",
        duration_s: 120,
        rate_hz: 1000,
        terse: true,
    },
    Case {
        scenario: "pressure-step",
        duration_s: 60,
        rate_hz: 10000,
        terse: true,
    },
    Case {
        scenario: "pressure-hold",
        duration_s: 120,
        rate_hz: 1000,
        terse: false,
    },
    Case {
        scenario: "stroke",
        duration_s: 120,
        rate_hz: 1000,
        terse: false,
    },
];

/// Rows of the shortest log, whose peak is the program's own memory.
const SHORTEST_ROWS: usize = 2000;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let [flag, eha, log, json] = args.as_slice() {
        if flag == MEASURE {
            return measure(Path::new(eha), Path::new(log), Path::new(json));
        }
    }
    let eha = args.first().map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/release/eha"),
        PathBuf::from,
    );
    if !eha.is_file() {
        eprintln!(
            "diagnose_memory: no `eha` at {} (build it: cargo build --release -p host-sim --bin eha)",
            eha.display()
        );
        return ExitCode::from(2);
    }
    let dir = std::env::temp_dir().join(format!("eha-diagnose-memory-{}", std::process::id()));
    let result = run(&eha, &dir);
    let _ = std::fs::remove_dir_all(&dir);
    match result {
        Ok(table) => {
            print!("{table}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("diagnose_memory: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Every case simulated, written and diagnosed in `dir`; the table.
fn run(eha: &Path, dir: &Path) -> Result<String, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut logs = Vec::new();
    for (k, c) in CASES.iter().enumerate() {
        let raw = dir.join(format!("{k}_{}.csv", c.scenario));
        simulate(eha, c, &raw)?;
        let log = bench_log::read(&raw).map_err(|e| e.to_string())?;
        let path = if c.terse {
            let terse = dir.join(format!("{k}_{}_terse.csv", c.scenario));
            write_terse(&log, log.len(), &terse)?;
            terse
        } else {
            raw
        };
        if k == 0 {
            let shortest = dir.join("shortest_terse.csv");
            write_terse(&log, SHORTEST_ROWS, &shortest)?;
            logs.push((
                format!("the first {SHORTEST_ROWS} rows of the next"),
                shortest,
            ));
        }
        let what = format!(
            "{} {} s at {} Hz, {}",
            c.scenario,
            c.duration_s,
            c.rate_hz,
            if c.terse {
                "6 columns, terse"
            } else {
                "as `eha simulate` writes it"
            }
        );
        logs.push((what, path));
    }
    let mut table = String::from(
        "| log | rows | file [MB] | peak [MiB] | peak / file | B a row above the shortest's peak | file's B a row |\n\
         | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    let mut own_kib = None;
    for (what, path) in &logs {
        let rows = data_rows(path)?;
        let bytes = std::fs::metadata(path).map_err(|e| e.to_string())?.len() as f64;
        let kib = peak_kib(eha, path, &dir.join("diagnosis.json"))?;
        let own = *own_kib.get_or_insert(kib);
        let _ = writeln!(
            table,
            "| {what} | {rows} | {:.2} | {:.1} | {:.2} | {:.0} | {:.0} |",
            bytes / 1e6,
            kib as f64 / 1024.0,
            kib as f64 * 1024.0 / bytes,
            (kib.saturating_sub(own)) as f64 * 1024.0 / rows as f64,
            bytes / rows as f64,
        );
    }
    Ok(table)
}

/// Runs `eha simulate` for `c` into `out`.
fn simulate(eha: &Path, c: &Case, out: &Path) -> Result<(), String> {
    let status = Command::new(eha)
        .args(["simulate", "--scenario", c.scenario, "--seed", "7"])
        .args(["--duration", &c.duration_s.to_string()])
        .args(["--log-rate", &c.rate_hz.to_string()])
        .arg("--out")
        .arg(out)
        .stdout(Stdio::null())
        .status()
        .map_err(|e| format!("eha simulate: {e}"))?;
    status
        .success()
        .then_some(())
        .ok_or_else(|| format!("eha simulate --scenario {} failed: {status}", c.scenario))
}

/// `v` to `digits` significant digits in the shorter of its plain and exponent forms.
fn terse(v: f64, digits: usize) -> String {
    let e = format!("{:.*e}", digits.saturating_sub(1), v);
    let (mantissa, exponent) = e.split_once('e').unwrap_or((&e, "0"));
    let mantissa = if mantissa.contains('.') {
        mantissa.trim_end_matches('0').trim_end_matches('.')
    } else {
        mantissa
    };
    let exp_form = if exponent == "0" {
        mantissa.to_string()
    } else {
        format!("{mantissa}e{exponent}")
    };
    let plain = exp_form
        .parse::<f64>()
        .map_or(exp_form.clone(), |x| x.to_string());
    if plain.len() < exp_form.len() {
        plain
    } else {
        exp_form
    }
}

/// The first `rows` rows of `log`'s six required columns written tersely to `out` (time
/// to the microsecond, so that it keeps increasing).
fn write_terse(log: &BenchLog, rows: usize, out: &Path) -> Result<(), String> {
    let mut text = String::from("t_s,p_ref_pa,p_pa,speed_rad_s,iq_a,id_a\n");
    for k in 0..rows.min(log.len()) {
        let _ = writeln!(
            text,
            "{},{},{},{},{},{}",
            (log.t_s[k] * 1e6).round() / 1e6,
            terse(log.p_ref_pa[k], 6),
            terse(log.p_pa[k], 6),
            terse(log.speed_rad_s[k], 6),
            terse(log.iq_a[k], 6),
            terse(log.id_a[k], 6),
        );
    }
    std::fs::File::create(out)
        .and_then(|mut f| f.write_all(text.as_bytes()))
        .map_err(|e| format!("{}: {e}", out.display()))
}

/// Data rows of the CSV at `path`: its lines less the metadata and the header.
fn data_rows(path: &Path) -> Result<usize, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
        .count()
        .saturating_sub(1))
}

/// The argument that makes this program measure one diagnosis and print its peak.
const MEASURE: &str = "--measure";

/// The peak resident memory of `eha diagnose LOG --json JSON`, measured by a fresh copy of
/// this program: a child's peak as the kernel counts it includes the memory of the process
/// it was started from (its address space until `exec`), and this one holds the logs it
/// wrote. [KiB]
fn peak_kib(eha: &Path, log: &Path, json: &Path) -> Result<u64, String> {
    let me = std::env::current_exe().map_err(|e| format!("this program's path: {e}"))?;
    let out = Command::new(me)
        .arg(MEASURE)
        .args([eha, log, json])
        .output()
        .map_err(|e| format!("{MEASURE}: {e}"))?;
    let text = String::from_utf8_lossy(&out.stdout);
    match text.trim().parse() {
        Ok(kib) if out.status.success() => Ok(kib),
        _ => Err(String::from_utf8_lossy(&out.stderr).trim().to_string()),
    }
}

/// Prints the peak of one diagnosis ([`child_peak_kib`]), in KiB.
fn measure(eha: &Path, log: &Path, json: &Path) -> ExitCode {
    match child_peak_kib(eha, log, json) {
        Ok(kib) => {
            println!("{kib}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}

/// The peak resident memory of `eha diagnose LOG --json JSON` in a child of its own. [KiB]
fn child_peak_kib(eha: &Path, log: &Path, json: &Path) -> Result<u64, String> {
    let child = Command::new(eha)
        .arg("diagnose")
        .arg(log)
        .arg("--json")
        .arg(json)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|e| format!("eha diagnose: {e}"))?;
    let mut status = 0;
    // SAFETY: an all-zero rusage is a valid value for wait4 to fill in.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: the pid is this process's child, not yet waited for; status and usage are
    // valid for writes.
    let pid = unsafe { libc::wait4(child.id() as libc::pid_t, &mut status, 0, &mut usage) };
    if pid < 0 {
        return Err(format!("wait4: {}", std::io::Error::last_os_error()));
    }
    if !(libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0) {
        return Err(format!(
            "eha diagnose {} failed (status {status})",
            log.display()
        ));
    }
    Ok(usage.ru_maxrss as u64)
}
