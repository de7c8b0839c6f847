//! The processor-in-the-loop step of `cargo xtask test`: the `pil` binary built for the
//! Cortex-M4F and run in `qemu-system-arm -machine mps2-an386 -icount shift=0`; its defmt
//! frames decoded with the ELF's table (`defmt-decoder`); the telemetry turned into a bench
//! log by `eha ingest`, and piped into `eha watch` in tmux (`watch_check`); the same
//! scenario run on the host by `eha simulate` and the two logs compared sample by sample;
//! the figures written to `target/pil/report.json`; the current-loop step's instruction
//! count checked against `pil/budget.toml`; the stack's high-water mark of the run checked
//! against the firmware's stack: at least [`STACK_MARGIN_MIN`] times over.

use anyhow::{bail, Context, Result};
use defmt_decoder::{DecodeError, Table};
use std::collections::BTreeMap;
use std::fs::{self, File};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Longest a PIL run may take in QEMU (it takes about 10 s on this machine). [s]
const QEMU_TIMEOUT_S: u64 = 300;
/// The scenario, simulated time and seed the PIL binary runs (pil/src/target.rs).
const SCENARIO: &str = "pressure-hold";
const DURATION_S: &str = "0.5";
const SEED: &str = "1";
/// What the regression guard allows above the recorded current-loop budget. [%]
const BUDGET_TOLERANCE_PERCENT: f64 = 10.0;
/// How many times the PIL's stack high-water mark must fit in the firmware's stack.
const STACK_MARGIN_MIN: f64 = 4.0;
/// Signals compared between the PIL and the host run.
const COMPARED: [&str; 4] = ["p_pa", "speed_rad_s", "iq_a", "id_a"];

/// Builds, runs, decodes, ingests, compares, reports, and checks the budget.
pub fn pil() -> Result<()> {
    let qemu = "qemu-system-arm";
    require(qemu)?;
    xtask::images::build("PIL image (warnings denied)", "pil")?;

    let target_dir = xtask::workspace::target_dir();
    let elf = target_dir
        .join(xtask::setup::TARGET)
        .join("release")
        .join("pil");
    let out_dir = target_dir.join("pil");
    fs::create_dir_all(&out_dir)?;

    let raw = out_dir.join("defmt.bin");
    let wall_s = run_qemu(qemu, &elf, &raw, &out_dir.join("qemu-stderr.txt"))?;
    let defmt_log = out_dir.join("defmt.log");
    let lines = decode(&elf, &raw, &defmt_log)?;
    let figures = pil_figures(&lines)?;
    eprintln!(
        "PIL: {} defmt lines decoded to {}, {wall_s:.1} s in QEMU",
        lines.len(),
        defmt_log.display()
    );
    let per_tick = figure(&figures, "instructions_per_tick_measured")?;
    if (per_tick - 40.0).abs() > 0.4 {
        bail!(
            "QEMU counted {per_tick:.2} instructions per SysTick tick instead of 40: the \
             instruction counts need `-icount shift=0` on mps2-an386"
        );
    }

    let (target_log, host_log) = both_runs(&defmt_log, &out_dir)?;
    let diffs = compare(&target_log, &host_log)?;
    let current = figure(&figures, "current_loop_instructions")?;
    let (budget, goal) = budget()?;
    let stack_peak = figure(&figures, "stack_peak_bytes")?;
    // The check holds the run to the stack the budget guarantees the firmware (its RAM
    // less the static-RAM budget); the image's own figure is reported beside it.
    let firmware_stack_min =
        (crate::firmware_image::FIRMWARE_RAM - crate::firmware_image::RAM_BUDGET) as f64;
    let stack_margin = firmware_stack_min / stack_peak.max(1.0);
    let report = serde_json::json!({
        "current_loop_instructions": current,
        "speed_loop_instructions": figure(&figures, "speed_loop_instructions")?,
        "pressure_loop_instructions": figure(&figures, "pressure_loop_instructions")?,
        "closed_loop_step_instructions": figure(&figures, "closed_loop_step_instructions")?,
        "current_loop_parts_instructions": {
            "sin_cos": figure(&figures, "sin_cos_instructions")?,
            "svpwm": figure(&figures, "svpwm_instructions")?,
        },
        "max_abs_diff": diffs.iter().map(|(k, d)| (k.to_string(), serde_json::json!(d)))
            .collect::<serde_json::Map<_, _>>(),
        "simulated_s": figure(&figures, "simulated_s")?,
        "telemetry_rows": target_log.rows,
        "calls_measured": figure(&figures, "calls")?,
        "instructions_per_tick_measured": per_tick,
        "current_loop_budget_instructions": budget,
        "current_loop_goal_instructions": goal,
        "qemu_wall_s": wall_s,
        "stack": stack_report(&figures, firmware_stack_min, stack_margin)?,
    });
    let report_path = out_dir.join("report.json");
    fs::write(&report_path, format!("{report:#}\n"))?;
    eprintln!("PIL figures in {}:\n{report:#}", report_path.display());
    // The f32 control code and the f64 plant (libm, IEEE arithmetic in hardware or soft
    // float) compute the same bits on both machines; the closed loop would amplify any
    // difference, so there is no meaningful tolerance: a non-zero one means shared code
    // took a different float path on the host (std's inherent `sin`/`sqrt`, a fused
    // multiply-add) or a different input.
    if let Some((name, d)) = diffs.iter().find(|(_, d)| *d != 0.0) {
        bail!(
            "the PIL and host runs differ ({name} by {d}): shared code must call float \
             functions through libm or the firmware's own tables on both (see \
             target/pil/pil.csv and host.csv)"
        );
    }
    if stack_margin < STACK_MARGIN_MIN {
        bail!(
            "the PIL run's stack reached {stack_peak:.0} bytes: the firmware's stack of at \
             least {firmware_stack_min:.0} bytes holds it only {stack_margin:.1} times, below \
             {STACK_MARGIN_MIN}"
        );
    }
    check_budget(current, budget, goal)
}

/// Fails unless `qemu` runs, saying how to install it.
fn require(qemu: &str) -> Result<()> {
    if Command::new(qemu)
        .arg("--version")
        .stdout(Stdio::null())
        .status()
        .is_err()
    {
        bail!(
            "{qemu} is missing: the PIL runs the control code on QEMU's Cortex-M4F \
             (mps2-an386). Install it with `apt-get install qemu-system-arm` (Debian/Ubuntu; \
             `apt-get update` first on a fresh machine)"
        );
    }
    Ok(())
}

/// The PIL run's telemetry (`defmt_log`) as a bench log by `eha ingest`, checked in
/// `eha watch`, and the same scenario simulated on the host by `eha simulate`; both logs
/// written into `out_dir` and read back.
fn both_runs(defmt_log: &Path, out_dir: &Path) -> Result<(Log, Log)> {
    let eha_bin = xtask::workspace::eha_binary("eha for the PIL comparison")?;
    let pil_csv = out_dir.join("pil.csv");
    let host_csv = out_dir.join("host.csv");
    xtask::workspace::run(
        "eha ingest (PIL telemetry)",
        eha(&eha_bin).args(["ingest", path_str(defmt_log)?, "--out", path_str(&pil_csv)?]),
    )?;
    crate::watch_check::check(&eha_bin, defmt_log, &pil_csv, out_dir)?;
    xtask::workspace::run(
        "eha simulate (same scenario on the host)",
        eha(&eha_bin).args([
            "simulate",
            "--scenario",
            SCENARIO,
            "--duration",
            DURATION_S,
            "--seed",
            SEED,
            "--out",
            path_str(&host_csv)?,
        ]),
    )?;
    Ok((read_log(&pil_csv)?, read_log(&host_csv)?))
}

/// The report's stack figures: the PIL run's peak and region, each measured part's, and
/// the firmware's stack against the run's peak (`margin`, at least [`STACK_MARGIN_MIN`]).
fn stack_report(
    figures: &BTreeMap<String, f64>,
    firmware_stack_min: f64,
    margin: f64,
) -> Result<serde_json::Value> {
    Ok(serde_json::json!({
        "pil_peak_bytes": figure(figures, "stack_peak_bytes")?,
        "pil_region_bytes": figure(figures, "stack_size_bytes")?,
        "closed_loop_step_bytes": figure(figures, "closed_loop_step_stack_bytes")?,
        "telemetry_emit_bytes": figure(figures, "telemetry_emit_stack_bytes")?,
        "firmware_boot_bytes": figure(figures, "boot_stack_bytes")?,
        "parameter_save_bytes": figure(figures, "parameter_save_stack_bytes")?,
        "can_serve_bytes": figure(figures, "can_serve_stack_bytes")?,
        "harness_setup_bytes": figure(figures, "harness_setup_stack_bytes")?,
        "firmware_stack_min_bytes": firmware_stack_min,
        "firmware_stack_bytes": firmware_stack_bytes(),
        "margin": margin,
        "margin_min": STACK_MARGIN_MIN,
    }))
}

/// Fails when the current-loop step's instruction count `current` exceeds its ceiling
/// `goal` or its recorded `budget` by more than [`BUDGET_TOLERANCE_PERCENT`].
fn check_budget(current: f64, budget: f64, goal: f64) -> Result<()> {
    if current > goal {
        bail!(
            "the current-loop step takes {current:.0} instructions, above its ceiling of \
             {goal:.0} (pil/budget.toml, current_loop_goal_instructions)"
        );
    }
    if current > budget * (1.0 + BUDGET_TOLERANCE_PERCENT / 100.0) {
        bail!(
            "the current-loop step takes {current:.0} instructions, more than \
             {BUDGET_TOLERANCE_PERCENT} % over its recorded budget of {budget:.0} \
             (pil/budget.toml): a change slowed the hot path"
        );
    }
    Ok(())
}

/// The firmware image's stack region (`_stack_start − _stack_end`, as flip-link placed
/// it), when the image has been built. [bytes]
fn firmware_stack_bytes() -> Option<u64> {
    use object::{Object, ObjectSymbol};
    let elf = xtask::workspace::target_dir()
        .join(xtask::setup::TARGET)
        .join("release")
        .join("firmware");
    let data = fs::read(elf).ok()?;
    let file = object::File::parse(&*data).ok()?;
    let symbol = |name: &str| {
        file.symbols()
            .find(|s| s.name() == Ok(name))
            .map(|s| s.address())
    };
    symbol("_stack_start")?.checked_sub(symbol("_stack_end")?)
}

/// `eha` from the workspace, as the host tests build it ([`xtask::workspace::eha_binary`]).
fn eha(bin: &Path) -> Command {
    Command::new(bin)
}

fn path_str(p: &Path) -> Result<&str> {
    p.to_str()
        .with_context(|| format!("path {} is not UTF-8", p.display()))
}

/// Runs the image in QEMU, its semihosting output (the defmt frames) into `raw`; returns
/// the wall-clock time. Fails on a non-zero exit code or after [`QEMU_TIMEOUT_S`].
fn run_qemu(qemu: &str, elf: &Path, raw: &Path, stderr: &Path) -> Result<f64> {
    let mut cmd = Command::new(qemu);
    cmd.args([
        "-machine",
        "mps2-an386",
        "-cpu",
        "cortex-m4",
        "-icount",
        "shift=0",
        "-semihosting-config",
        "enable=on,target=native",
        "-nographic",
        "-monitor",
        "none",
        "-serial",
        "none",
        "-kernel",
    ])
    .arg(elf)
    .stdin(Stdio::null())
    .stdout(File::create(raw)?)
    .stderr(File::create(stderr)?);
    eprintln!("\n=== PIL in QEMU: {cmd:?}");
    let started = Instant::now();
    let mut child = cmd
        .spawn()
        .with_context(|| format!("could not start {qemu}"))?;
    let status = loop {
        if let Some(s) = child.try_wait()? {
            break s;
        }
        if started.elapsed() > Duration::from_secs(QEMU_TIMEOUT_S) {
            let _ = child.kill();
            let _ = child.wait();
            bail!("the PIL run did not finish within {QEMU_TIMEOUT_S} s in QEMU");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let wall = started.elapsed().as_secs_f64();
    if !status.success() {
        let err = fs::read_to_string(stderr).unwrap_or_default();
        bail!(
            "the PIL run failed in QEMU ({status}; 101 = panic, 102 = HardFault; its defmt \
             output is in {}): {err}",
            raw.display()
        );
    }
    Ok(wall)
}

/// Decodes the defmt frames in `raw` with the table of `elf` into text lines
/// `LEVEL message` (the layout `defmt-print` uses, without timestamps), written to `out`.
fn decode(elf: &Path, raw: &Path, out: &Path) -> Result<Vec<String>> {
    let elf_bytes = fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let table = Table::parse(&elf_bytes)
        .with_context(|| format!("reading the defmt table of {}", elf.display()))?
        .with_context(|| format!("{} has no .defmt section", elf.display()))?;
    let bytes = fs::read(raw).with_context(|| format!("reading {}", raw.display()))?;
    let mut decoder = table.new_stream_decoder();
    decoder.received(&bytes);
    let mut lines = Vec::new();
    loop {
        match decoder.decode() {
            Ok(frame) => {
                let level = frame
                    .level()
                    .map(|l| format!("{l:?}").to_uppercase())
                    .unwrap_or_else(|| "PRINT".into());
                lines.push(format!("{level:<5} {}", frame.display_message()));
            }
            Err(DecodeError::UnexpectedEof) => break,
            Err(DecodeError::Malformed) => bail!(
                "malformed defmt frame after {} good ones in {} (an ELF other than the one \
                 that ran?)",
                lines.len(),
                raw.display()
            ),
        }
    }
    let mut text = lines.join("\n");
    text.push('\n');
    fs::write(out, text)?;
    Ok(lines)
}

/// The `PIL key=value …` line the binary ends with.
fn pil_figures(lines: &[String]) -> Result<BTreeMap<String, f64>> {
    let line = lines
        .iter()
        .find_map(|l| l.split_once("PIL current_loop_instructions=").map(|_| l))
        .context("the PIL run printed no `PIL …` figures line")?;
    let start = line.find("PIL ").unwrap_or(0) + 4;
    line[start..]
        .split_whitespace()
        .map(|kv| {
            let (k, v) = kv
                .split_once('=')
                .with_context(|| format!("`{kv}` in the PIL line is not key=value"))?;
            let v: f64 = v
                .parse()
                .with_context(|| format!("`{kv}` in the PIL line is not a number"))?;
            Ok((k.to_string(), v))
        })
        .collect()
}

fn figure(figures: &BTreeMap<String, f64>, key: &str) -> Result<f64> {
    figures
        .get(key)
        .copied()
        .with_context(|| format!("the PIL line has no `{key}`"))
}

/// The recorded current-loop budget and the goal, from `pil/budget.toml`. [instructions]
fn budget() -> Result<(f64, f64)> {
    let path = xtask::workspace::root().join("pil").join("budget.toml");
    let text = fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let table: toml::Table = text
        .parse()
        .with_context(|| format!("parsing {}", path.display()))?;
    let get = |k: &str| -> Result<f64> {
        match table.get(k) {
            Some(toml::Value::Integer(i)) => Ok(*i as f64),
            Some(toml::Value::Float(f)) => Ok(*f),
            _ => bail!("{}: `{k}` must be a number", path.display()),
        }
    };
    Ok((
        get("current_loop_instructions")?,
        get("current_loop_goal_instructions")?,
    ))
}

/// The columns of a bench log that the comparison needs.
struct Log {
    file: PathBuf,
    rows: usize,
    columns: BTreeMap<String, Vec<f64>>,
}

fn read_log(path: &Path) -> Result<Log> {
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_path(path)
        .with_context(|| format!("reading {}", path.display()))?;
    let headers = reader.headers()?.clone();
    let mut columns: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    let mut rows = 0;
    for record in reader.records() {
        let record = record.with_context(|| format!("reading {}", path.display()))?;
        for (name, field) in headers.iter().zip(record.iter()) {
            if name == "t_s" || COMPARED.contains(&name) {
                let v: f64 = field
                    .parse()
                    .with_context(|| format!("{}: `{field}` in column {name}", path.display()))?;
                columns.entry(name.to_string()).or_default().push(v);
            }
        }
        rows += 1;
    }
    Ok(Log {
        file: path.to_path_buf(),
        rows,
        columns,
    })
}

fn column<'a>(log: &'a Log, name: &str) -> Result<&'a [f64]> {
    log.columns
        .get(name)
        .map(Vec::as_slice)
        .with_context(|| format!("{} has no column {name}", log.file.display()))
}

/// Largest absolute difference per compared signal, after checking that the rows are the
/// same instants.
fn compare(target: &Log, host: &Log) -> Result<Vec<(&'static str, f64)>> {
    if target.rows != host.rows {
        bail!(
            "the PIL log has {} rows, the host log {}: not the same run",
            target.rows,
            host.rows
        );
    }
    // Row k of both logs is the same PWM period; both stamp it with the instant its
    // measurements were sampled, so the offset must be zero — checked as a constant offset
    // so a mismatch is reported plainly.
    let (tt, th) = (column(target, "t_s")?, column(host, "t_s")?);
    let offset = match (tt.first(), th.first()) {
        (Some(a), Some(b)) => a - b,
        _ => bail!("{} is empty", target.file.display()),
    };
    if let Some((i, (a, b))) = tt
        .iter()
        .zip(th)
        .enumerate()
        .find(|(_, (a, b))| (*a - *b - offset).abs() > 1e-9)
    {
        bail!(
            "row {i}: the PIL log is at {a} s, the host log at {b} s, not {offset} s apart \
             like the first rows"
        );
    }
    COMPARED
        .iter()
        .map(|name| {
            let d = column(target, name)?
                .iter()
                .zip(column(host, name)?)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            Ok((*name, d))
        })
        .collect()
}
