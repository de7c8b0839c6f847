//! Every `eha` subcommand under bad input, one test per class of case: bad paths, bad
//! numbers, unknown names, extreme rig values, logs the diagnosis or tuning cannot use,
//! garbled files, and interruption. Each must exit 2 (130 when interrupted) with a message
//! naming what and where, before any work, leaving nothing behind, never panicking.

mod common;

use common::{eha, s};
use host_sim::rig_file;
use plant_model::Rig;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

fn status(o: &Output) -> i32 {
    o.status.code().expect("exited, not killed by a signal")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn scratch(name: &str) -> PathBuf {
    common::scratch("bad-input", name)
}

/// Files and folders in `dir`, hidden ones included, sorted.
fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Runs `args`, expecting exit 2 with every one of `named` in the message, no panic.
fn refused(args: &[&str], named: &[&str]) -> String {
    let o = eha(args);
    let err = stderr(&o);
    assert_eq!(status(&o), 2, "{args:?}: {err}");
    for n in named {
        assert!(err.contains(n), "{args:?} should name `{n}`: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.lines().count() < 20, "{args:?}: a short message: {err}");
    err
}

/// A valid bench log of a pressure hold (simulated, 2 kHz, 1 s).
fn hold_log(dir: &Path) -> PathBuf {
    hold_log_of(dir, "hold.csv", "1")
}

/// A pressure-hold log of `seconds` written to `dir/name`.
fn hold_log_of(dir: &Path, name: &str, seconds: &str) -> PathBuf {
    common::simulated_hold(dir, name, seconds, &[])
}

/// `log` with `column` rewritten row by row (`row index, old text → new text`).
fn edited(log: &Path, name: &str, column: &str, f: impl Fn(usize, &str) -> String) -> PathBuf {
    let text = fs::read_to_string(log).unwrap();
    let mut out = String::new();
    let mut col = None;
    let mut row = 0;
    for line in text.lines() {
        if line.starts_with('#') {
            out.push_str(line);
        } else if col.is_none() {
            col = line.split(',').position(|c| c == column);
            assert!(col.is_some(), "{column} in {line}");
            out.push_str(line);
        } else {
            let mut fields: Vec<String> = line.split(',').map(str::to_string).collect();
            let c = col.unwrap();
            fields[c] = f(row, &fields[c]);
            out.push_str(&fields.join(","));
            row += 1;
        }
        out.push('\n');
    }
    let path = log.with_file_name(name);
    fs::write(&path, out).unwrap();
    path
}

#[test]
fn bad_paths_are_refused_before_the_run_and_leave_nothing() {
    let dir = scratch("paths");
    let log = hold_log(&dir);
    let rig = dir.join("rig.toml");
    fs::write(&rig, rig_file::to_toml(&Rig::nominal())).unwrap();
    let missing = dir.join("missing.csv");
    let sub = dir.join("sub");
    fs::create_dir(&sub).unwrap();
    let json = dir.join("out.json");
    let not_a_folder = dir.join("hold.csv/x.json");
    let link_to_log = dir.join("link.csv");
    std::os::unix::fs::symlink(&log, &link_to_log).unwrap();
    let dangling = dir.join("dangling.json");
    std::os::unix::fs::symlink(dir.join("nowhere"), &dangling).unwrap();
    let fifo = dir.join("fifo");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    // Output folders holding a special file where the command would write one of its own.
    let demo_out = dir.join("demo-out");
    fs::create_dir(&demo_out).unwrap();
    assert!(std::process::Command::new("mkfifo")
        .arg(demo_out.join("speed_step.svg"))
        .status()
        .unwrap()
        .success());
    std::os::unix::fs::symlink("/dev/null", demo_out.join("sweep.svg")).unwrap();
    let before = entries(&dir);
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (
            vec!["demo", "--out", s(&demo_out)],
            vec!["speed_step.svg", "FIFO"],
        ),
        (
            vec!["sweep-precharge", "--values", "5e6", "--out", s(&demo_out)],
            vec!["sweep.svg", "character device"],
        ),
        // Inputs: missing, a folder, a device.
        (
            vec!["diagnose", s(&missing)],
            vec!["missing.csv", "does not exist"],
        ),
        (
            vec!["tune", s(&sub), "--loop", "pressure"],
            vec!["sub", "folder"],
        ),
        (
            vec!["ingest", "/dev/zero", "--out", s(&json)],
            vec!["/dev/zero", "character device"],
        ),
        (vec!["--rig", s(&sub), "rig"], vec!["sub", "folder"]),
        (
            vec![
                "simulate",
                "--scenario",
                "pressure-hold",
                "--out",
                s(&json),
                "--plant-rig",
                s(&missing),
            ],
            vec!["--plant-rig", "does not exist"],
        ),
        // Outputs equal to an input, directly, through a link, or as the rig file.
        (
            vec!["diagnose", s(&log), "--json", s(&log)],
            vec!["--json", "is the input"],
        ),
        (
            vec![
                "tune",
                s(&log),
                "--loop",
                "pressure",
                "--json",
                s(&link_to_log),
            ],
            vec!["is the input"],
        ),
        (
            vec!["--rig", s(&rig), "rig", "--json", s(&rig)],
            vec!["--json", "is the input"],
        ),
        (
            vec!["ingest", s(&log), "--out", s(&log)],
            vec!["--out", "is the input"],
        ),
        (
            vec!["diagnose", s(&log), "--report", s(&log)],
            vec!["--report", "not a folder"],
        ),
        // Outputs that are special files, folders, dangling links, or unwritable.
        (
            vec!["ingest", s(&log), "--out", "/dev/null"],
            vec!["/dev/null", "character device"],
        ),
        (vec!["rig", "--json", s(&fifo)], vec!["FIFO"]),
        (vec!["commission", "--json", s(&sub)], vec!["folder"]),
        (
            vec!["accumulator-design", "--json", s(&dangling)],
            vec!["dangling"],
        ),
        (
            vec!["accumulator-design", "--json", s(&not_a_folder)],
            vec!["hold.csv", "not a folder"],
        ),
        (
            vec!["rig", "--json", "/proc/eha-test.json"],
            vec!["/proc", "cannot create files"],
        ),
        (
            vec!["demo", "--out", s(&log)],
            vec!["--out", "not a folder"],
        ),
        (
            vec!["sweep-precharge", "--out", s(&not_a_folder)],
            vec!["not a folder"],
        ),
        (
            vec![
                "simulate",
                "--scenario",
                "pressure-hold",
                "--out",
                "/dev/null",
            ],
            vec!["character device"],
        ),
        // Two outputs on one path.
        (
            vec![
                "simulate",
                "--scenario",
                "pressure-hold",
                "--out",
                s(&json),
                "--json",
                s(&json),
            ],
            vec!["--out", "--json", "both name"],
        ),
        (
            vec!["sweep-precharge", "--json", "-", "--out", "-"],
            vec!["both name"],
        ),
    ];
    for (args, named) in cases {
        refused(&args, &named);
        assert_eq!(
            entries(&dir),
            before,
            "{args:?}: nothing written or removed"
        );
    }
    // The special files are still what they were.
    use std::os::unix::fs::FileTypeExt;
    assert!(fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
    assert!(fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
    assert!(fs::symlink_metadata(&link_to_log)
        .unwrap()
        .file_type()
        .is_symlink());
    // A link to a regular output file is followed: the file is replaced, the link stays.
    let target = dir.join("target.json");
    fs::write(&target, "old").unwrap();
    let link = dir.join("to-target.json");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    assert_eq!(status(&eha(&["rig", "--json", s(&link)])), 0);
    assert!(fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    let v: serde_json::Value = serde_json::from_str(&fs::read_to_string(&target).unwrap()).unwrap();
    assert!(v["motor"].is_object());
}

#[test]
fn bad_numbers_are_refused_naming_the_flag() {
    let dir = scratch("numbers");
    // The targets are checked before the log is read; the log need only exist.
    let some_log = scratch("numbers-log").join("x.csv");
    fs::write(&some_log, "").unwrap();
    let x = s(&some_log);
    let out = dir.join(x);
    let o = s(&out);
    let sim = |flag: &'static str, v: &'static str| {
        vec![
            "simulate",
            "--scenario",
            "pressure-hold",
            "--out",
            o,
            flag,
            v,
        ]
    };
    let mut cases: Vec<(Vec<&str>, &str)> = Vec::new();
    for v in ["0", "-1", "NaN", "inf", "abc", ""] {
        cases.push((sim("--duration", v), "--duration"));
        cases.push((sim("--precharge", v), "--precharge"));
        cases.push((sim("--log-rate", v), "--log-rate"));
        cases.push((vec!["accumulator-design", "--pressure", v], "--pressure"));
        cases.push((vec!["commission", "--bandwidth", v], "--bandwidth"));
        cases.push((vec!["sweep-precharge", "--values", v], "--values"));
    }
    for v in ["-1", "NaN", "inf"] {
        cases.push((
            vec!["tune", x, "--loop", "speed", "--overshoot", v],
            "--overshoot",
        ));
    }
    // Huge: beyond the rows a bench log holds, the rig's ranges, the firmware's bounds.
    cases.extend([
        (sim("--duration", "1e300"), "--duration"),
        (sim("--duration", "1e9"), "10000000"),
        (sim("--duration", "1e6"), "--duration"),
        (sim("--log-rate", "1e-300"), "at least 100"),
        (sim("--log-rate", "1e9"), "20000"),
        (sim("--precharge", "1e30"), "--precharge"),
        (vec!["accumulator-design", "--pressure", "1e300"], "relief"),
        (vec!["commission", "--bandwidth", "1e300"], "--bandwidth"),
        (vec!["commission", "--bandwidth", "1e-300"], "--bandwidth"),
        (vec!["commission", "--bandwidth", "1e5"], "tenth of the"),
        (
            vec!["sweep-precharge", "--values", "1e30"],
            "absorber.precharge_pa",
        ),
        (vec!["sweep-precharge", "--values", "5e6,5e6"], "twice"),
        (
            vec!["tune", x, "--loop", "pressure", "--settling", "1e308"],
            "--settling",
        ),
        (
            vec!["tune", x, "--loop", "pressure", "--settling", "100"],
            "10 s",
        ),
        (
            vec!["tune", x, "--loop", "speed", "--overshoot", "1e9"],
            "--overshoot",
        ),
    ]);
    let many: String = (1..=40)
        .map(|k| format!("{k}e5"))
        .collect::<Vec<_>>()
        .join(",");
    cases.push((vec!["sweep-precharge", "--values", &many], "at most 32"));
    for (args, named) in cases {
        let err = refused(&args, &[named]);
        // Numbers are quoted short: 1e300 is not 301 digits.
        assert!(!err.contains("000000000000000000000"), "{args:?}: {err}");
    }
    assert!(entries(&dir).is_empty(), "nothing written");
}

#[test]
fn unknown_names_are_refused_listing_the_known_ones() {
    let dir = scratch("names");
    let out = dir.join("x.csv");
    let o = s(&out);
    let sim = |extra: &[&'static str]| {
        let mut v = vec!["simulate", "--scenario", "pressure-hold", "--out", o];
        v.extend_from_slice(extra);
        v
    };
    let cases: Vec<(Vec<&str>, &[&str])> = vec![
        (
            vec!["simulate", "--scenario", "nope", "--out", o],
            &["nope", "pressure-step"],
        ),
        (
            sim(&["--effects", "warp_drive"]),
            &["warp_drive", "cogging_torque"],
        ),
        (
            sim(&["--effects", "cogging_torque:amplitude=1"]),
            &["amplitude"],
        ),
        (
            sim(&["--effects", "cogging_torque:amplitude_nm=NaN"]),
            &["finite"],
        ),
        (
            sim(&["--effects", "cogging_torque:amplitude_nm=1e30"]),
            &["motor.cogging.amplitude_nm"],
        ),
        (
            sim(&["--effects", "extra_leakage:coefficient_m3_s_pa=1"]),
            &["leakage"],
        ),
        (sim(&["--effects", ","]), &["no effect"]),
        (vec!["tune", "x.csv", "--loop", "position"], &["position"]),
        (vec!["frobnicate"], &["frobnicate"]),
    ];
    for (args, named) in cases {
        refused(&args, named);
    }
    assert!(entries(&dir).is_empty());
}

/// Every numeric leaf of the nominal rig's TOML, as (line index, key).
fn numeric_lines(toml: &str) -> Vec<(usize, String)> {
    toml.lines()
        .enumerate()
        .filter_map(|(i, l)| {
            let (k, v) = l.split_once(" = ")?;
            v.trim().parse::<f64>().ok()?;
            Some((i, k.trim().to_string()))
        })
        .collect()
}

#[test]
fn extreme_rig_values_are_refused_naming_the_key() {
    let dir = scratch("rig-values");
    let nominal = rig_file::to_toml(&Rig::nominal());
    let lines: Vec<&str> = nominal.lines().collect();
    let leaves = numeric_lines(&nominal);
    assert!(leaves.len() > 60, "{} numeric parameters", leaves.len());
    let file = dir.join("extreme.toml");
    for (i, key) in &leaves {
        for v in ["1e30", "-1e30"] {
            let mut edited: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
            edited[*i] = format!("{key} = {v}");
            fs::write(&file, edited.join("\n")).unwrap();
            // Every subcommand loads the rig first; `rig` is the quickest.
            let err = refused(&["--rig", s(&file), "rig"], &["extreme.toml"]);
            assert!(err.contains(key.as_str()), "{key} = {v}: {err}");
        }
    }
    for (key, v) in [("max_step_s", "1e-30"), ("max_step_s", "1e-9")] {
        fs::write(
            &file,
            nominal.replace("max_step_s = 0.00005", &format!("{key} = {v}")),
        )
        .unwrap();
        refused(
            &["--rig", s(&file), "commission"],
            &["integration.max_step_s"],
        );
    }
    // A file that is no rig at all: binary, or far too large.
    fs::write(&file, [0u8, 159, 146, 150, 255, 0, 1]).unwrap();
    let err = refused(&["--rig", s(&file), "rig"], &["extreme.toml", "UTF-8"]);
    assert!(!err.contains("Utf8Error"), "{err}");
    fs::write(&file, vec![b'#'; 2 << 20]).unwrap();
    refused(&["--rig", s(&file), "rig"], &["larger than"]);
}

#[test]
fn logs_the_diagnosis_cannot_replay_are_refused_before_it_starts() {
    let dir = scratch("replayable");
    let log = hold_log(&dir);
    let report = dir.join("report");
    let json = dir.join("d.json");
    let cases = [
        (
            edited(&log, "huge.csv", "p_pa", |k, v| match k {
                500 => "1e308".into(),
                501 => "-1e308".into(),
                _ => v.into(),
            }),
            vec!["p_pa", "line", "physical range"],
        ),
        (
            edited(&log, "plow.csv", "p_low_pa", |_, _| "1e305".into()),
            vec!["p_low_pa", "physical range"],
        ),
        (
            edited(&log, "stroke.csv", "x_m", |_, _| "0.5".into()),
            vec!["x_m", "stroke", "cylinder.half_stroke_m"],
        ),
        (
            edited(&log, "constant.csv", "p_pa", |_, _| "5e6".into()),
            vec!["p_pa", "whole log"],
        ),
        (
            edited(&log, "sparse.csv", "t_s", |k, _| {
                format!("{}", k as f64 * 0.1)
            }),
            vec!["t_s", "100 Hz"],
        ),
        (
            edited(&log, "gap.csv", "t_s", |k, _| {
                let t = k as f64 * 5e-4;
                format!("{}", if k >= 1000 { t + 100.0 } else { t })
            }),
            vec!["gap", "split the log"],
        ),
        (
            edited(&log, "long.csv", "t_s", |k, _| {
                format!("{}", k as f64 * 0.4)
            }),
            vec!["600"],
        ),
    ];
    let before = entries(&dir);
    for (bad, named) in cases {
        let before = entries(&dir);
        refused(
            &[
                "diagnose",
                s(&bad),
                "--json",
                s(&json),
                "--report",
                s(&report),
            ],
            &named,
        );
        assert_eq!(
            entries(&dir),
            before,
            "{bad:?}: no report, no staging folder, no JSON"
        );
    }
    assert!(before.len() > 1);
}

#[test]
fn tune_refuses_a_dropped_sample_naming_its_time() {
    let dir = scratch("tune-glitch");
    let log = dir.join("step.csv");
    let o = eha(&["simulate", "--scenario", "pressure-step", "--out", s(&log)]);
    assert_eq!(status(&o), 0, "{}", stderr(&o));
    // One reading of 0 Pa in the middle of the 3 → 5 MPa step at 2 kHz (t = 0.6 s).
    let bad = edited(&log, "dropped.csv", "p_pa", |k, v| {
        if k == 1200 {
            "0".into()
        } else {
            v.into()
        }
    });
    let json = dir.join("t.json");
    let err = refused(
        &["tune", s(&bad), "--loop", "pressure", "--json", s(&json)],
        &["p_pa", "t = 0.6000 s"],
    );
    assert!(err.contains("dropped or corrupted"), "{err}");
    assert!(!json.exists());
    // The clean log tunes.
    let o = eha(&["tune", s(&log), "--loop", "pressure", "--json", s(&json)]);
    assert_eq!(status(&o), 0, "{}", stderr(&o));
}

#[test]
fn garbled_files_get_short_readable_messages() {
    let dir = scratch("garbled");
    let header = "t_s,p_ref_pa,p_pa,speed_rad_s,iq_a,id_a\n";
    let rows = |f: &dyn Fn(usize) -> String| -> String {
        (0..150).map(|i| f(i) + "\n").collect::<String>()
    };
    let good = |i: usize| format!("{},5e6,{},5.86,0.4,0", i as f64 * 1e-3, 5e6 + i as f64);
    let write = |name: &str, bytes: Vec<u8>| {
        let p = dir.join(name);
        fs::write(&p, bytes).unwrap();
        p
    };
    // Binary: not a Rust debug structure, no byte dump.
    let binary = write(
        "binary.csv",
        (0..4096u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
            .collect(),
    );
    // A 2 MB field (beyond the longest line), a 60 kB one (quoted as an excerpt), an empty
    // field, a 2 MB line without break.
    let field = |n: usize| {
        format!(
            "{header}{}",
            rows(&|i| if i == 5 {
                format!("0.005,5e6,{},5.86,0.4,0", "9".repeat(n) + "x")
            } else {
                good(i)
            })
        )
    };
    let huge_field = write("field.csv", field(2_000_000).into_bytes());
    let long_field = write("long-field.csv", field(60_000).into_bytes());
    let empty = write(
        "empty.csv",
        format!(
            "{header}{}",
            rows(&|i| if i == 7 {
                "0.007,5e6,,5.86,0.4,0".into()
            } else {
                good(i)
            })
        )
        .into_bytes(),
    );
    let endless = write("endless.csv", vec![b'7'; 2 << 20]);
    for (path, named) in [
        (&binary, vec!["binary.csv", "line 1"]),
        (&huge_field, vec!["field.csv", "line 7", "longer than"]),
        (
            &long_field,
            vec!["long-field.csv", "line 7", "p_pa", "60001 bytes"],
        ),
        (&empty, vec!["empty.csv", "line 9", "p_pa", "empty"]),
        (&endless, vec!["endless.csv", "line 1", "longer than"]),
    ] {
        let err = refused(&["diagnose", s(path)], &named);
        assert!(err.len() < 400, "short: {err}");
        for debug in ["Utf8 {", "pos:", "ErrorKind", "Position {", "os error"] {
            assert!(!err.contains(debug), "no debug output: {err}");
        }
        assert!(!err.contains("``"), "an empty field is said so: {err}");
    }
    // The same for a 100 kB argument.
    // (One argument may hold at most 128 kB on Linux.)
    let arg = "8".repeat(100_000);
    let err = refused(
        &["accumulator-design", "--pressure", &arg],
        &["--pressure", "bytes"],
    );
    assert!(err.len() < 600, "{} bytes", err.len());
    // Ingest: binary, an endless line, values beyond any sensor, unknown fault codes.
    let out = dir.join("ingested.csv");
    refused(
        &["ingest", s(&endless), "--out", s(&out)],
        &["endless.csv", "line 1", "longer than"],
    );
    let mut lines = String::new();
    for i in 0..150 {
        let p = if i == 3 { "1e38" } else { "5000000" };
        let fault = if i == 4 { 200 } else { 0 };
        lines.push_str(&format!(
            "EHA1 t_s={} p_ref_pa=5000000 p_pa={p} speed_rad_s=6 iq_a=0.5 id_a=0 theta_m_rad=1 speed_ref_rad_s=6 iq_ref_a=0.5 ud_v=0 uq_v=1 udc_v=280 mode=3 fault={fault} status=0\n",
            i as f64 * 1e-3
        ));
    }
    let telemetry = write("telemetry.log", lines.into_bytes());
    let err = refused(
        &["ingest", s(&telemetry), "--out", s(&out)],
        &[
            "telemetry.log:4",
            "p_pa",
            "physical range",
            "telemetry.log:5",
        ],
    );
    let last = firmware::FaultCode::ALL
        .iter()
        .map(|c| c.code())
        .max()
        .unwrap();
    assert!(
        err.contains(&format!("1..={last}")),
        "fault codes 1..={last}: {err}"
    );
    assert!(!out.exists());
}

#[test]
fn an_interrupted_run_leaves_nothing_behind() {
    let dir = scratch("interrupt");
    // Long enough that the diagnosis is still running when the signal arrives.
    let log = hold_log_of(&dir, "hold.csv", "20");
    let report = dir.join("report");
    let json = dir.join("d.json");
    let before = entries(&dir);
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_eha"))
        .args([
            "diagnose",
            s(&log),
            "--json",
            s(&json),
            "--report",
            s(&report),
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(300));
    let kill = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let o = child.wait_with_output().unwrap();
    assert_eq!(status(&o), 130, "{}", stderr(&o));
    assert!(stderr(&o).contains("interrupted"), "{}", stderr(&o));
    assert_eq!(
        entries(&dir),
        before,
        "no report, JSON, staging or temporary file"
    );
}

/// The mean of column `name` over the last half of the bench log at `path`.
fn late_mean(path: &Path, name: &str) -> f64 {
    let text = fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let col = lines
        .next()
        .unwrap()
        .split(',')
        .position(|c| c == name)
        .unwrap();
    let v: Vec<f64> = lines
        .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
        .collect();
    assert!(
        v.iter().all(|x| x.is_finite()),
        "{}: {name} finite",
        path.display()
    );
    let late = &v[v.len() / 2..];
    late.iter().sum::<f64>() / late.len() as f64
}

#[test]
fn a_pressure_sensor_lag_shorter_than_the_step_simulates_stably() {
    // A transducer lag of 1 µs against the 50 µs step, asked for as an effect, in the rig
    // file and in the plant's rig file: a lag that short is invisible to a 20 kHz sampler,
    // so the hold looks like the hold without it (mean pressure within a few LSB of the
    // lag-free run's, both at the 5 MPa set point).
    let d = scratch("short-lag");
    let mut rig = Rig::nominal();
    rig.sensors.pressure.lag_time_constant_s = 1e-6;
    let rig_path = d.join("lag.toml");
    fs::write(&rig_path, rig_file::to_toml(&rig)).unwrap();
    let free = common::simulated_hold(&d, "free.csv", "0.5", &[]);
    let p_free = late_mean(&free, "p_pa");
    assert!((p_free - 5e6).abs() < 20e3, "lag-free hold at {p_free} Pa");
    for (name, extra) in [
        (
            "effect.csv",
            vec!["--effects", "pressure_sensor_lag:time_constant_s=1e-6"],
        ),
        ("rig.csv", vec!["--rig", s(&rig_path)]),
        ("plant-rig.csv", vec!["--plant-rig", s(&rig_path)]),
    ] {
        let log = common::simulated_hold(&d, name, "0.5", &extra);
        let p = late_mean(&log, "p_pa");
        assert!(
            (p - p_free).abs() < 2e3,
            "{name}: mean pressure {p} Pa against {p_free} Pa without the lag"
        );
    }
}
