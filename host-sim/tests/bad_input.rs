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
    // Output folders holding a special file, or a link to one, where the command would
    // write one of its own.
    let demo_out = dir.join("demo-out");
    fs::create_dir(&demo_out).unwrap();
    assert!(std::process::Command::new("mkfifo")
        .arg(demo_out.join("speed_step.svg"))
        .status()
        .unwrap()
        .success());
    let sweep_out = dir.join("sweep-out");
    fs::create_dir(&sweep_out).unwrap();
    std::os::unix::fs::symlink("/dev/null", sweep_out.join("sweep.svg")).unwrap();
    let before = entries(&dir);
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (
            vec!["demo", "--out", s(&demo_out)],
            vec!["speed_step.svg", "FIFO"],
        ),
        (
            vec!["sweep-precharge", "--values", "5e6", "--out", s(&sweep_out)],
            vec!["sweep.svg", "symbolic link to `/dev/null`"],
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
        (sim("--duration", "1e9"), "6428571"),
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

/// A bench log of `rows` rows of a 5 MPa hold whose times are `t(i)`, with `meta` before
/// the header.
fn hold_rows(meta: &str, rows: usize, t: impl Fn(usize) -> f64) -> String {
    let mut text = String::from(meta);
    text.push_str("t_s,p_ref_pa,p_pa,speed_rad_s,iq_a,id_a\n");
    for i in 0..rows {
        text.push_str(&format!("{:?},5e6,{},5.86,0.4,0\n", t(i), 5e6 + i as f64));
    }
    text
}

#[test]
fn a_time_axis_no_sampler_makes_is_refused_naming_the_row() {
    let dir = scratch("time-axis");
    // A simulated hold whose time steps by one float ulp at 1 s (2.2e-16 s): increasing,
    // but no sampler's.
    let hold = hold_log_of(&dir, "hold.csv", "0.5");
    let ulps = edited(&hold, "ulps.csv", "t_s", |i, _| {
        format!("{:?}", 1.0 + i as f64 * 2.3e-16)
    });
    let json = dir.join("d.json");
    // The second data row, after the metadata and the header.
    let text = fs::read_to_string(&ulps).unwrap();
    let line = text.lines().take_while(|l| l.starts_with('#')).count() + 3;
    let err = refused(
        &["diagnose", s(&ulps), "--json", s(&json)],
        &["ulps.csv", &format!("line {line},"), "t_s", "1e-6 s apart"],
    );
    assert!(err.contains("2.220e-16 s"), "the step said: {err}");
    assert!(!json.exists());
    // One short step among 1 kHz rows is named where it is (header line 1, row k at k + 2).
    let glitch = dir.join("glitch.csv");
    let t = |i: usize| {
        if i == 60 {
            0.059 + 1e-9
        } else {
            i as f64 * 1e-3
        }
    };
    fs::write(&glitch, hold_rows("", 150, t)).unwrap();
    refused(
        &["tune", s(&glitch), "--loop", "pressure"],
        &["line 62", "t_s", "1e-6 s apart"],
    );
    // The same rule for telemetry.
    let mut lines = String::new();
    for i in 0..150 {
        lines.push_str(&format!(
            "EHA1 t_s={:?} p_ref_pa=5000000 p_pa=5000000 speed_rad_s=6 iq_a=0.5 id_a=0 theta_m_rad=1 speed_ref_rad_s=6 iq_ref_a=0.5 ud_v=0 uq_v=1 udc_v=280 mode=3 fault=0 status=0\n",
            1.0 + i as f64 * 2.3e-16
        ));
    }
    let telemetry = dir.join("telemetry.log");
    fs::write(&telemetry, lines).unwrap();
    let out = dir.join("ingested.csv");
    refused(
        &["ingest", s(&telemetry), "--out", s(&out)],
        &["telemetry.log:2", "t_s", "1e-6 s apart"],
    );
    assert!(!out.exists());
}

#[test]
fn metadata_beyond_a_header_is_refused_naming_the_line() {
    let dir = scratch("metadata");
    // Ten thousand lines are a header still; one more is not.
    let lines = |n: usize| {
        (0..n)
            .map(|k| format!("# key{k}: value\n"))
            .collect::<String>()
    };
    let many = dir.join("many.csv");
    fs::write(&many, hold_rows(&lines(10_001), 150, |i| i as f64 * 1e-3)).unwrap();
    let err = refused(
        &["tune", s(&many), "--loop", "pressure"],
        &["many.csv", "line 10001"],
    );
    assert!(err.contains("10000 metadata lines"), "{err}");
    let fine = dir.join("fine.csv");
    fs::write(&fine, hold_rows(&lines(10_000), 150, |i| i as f64 * 1e-3)).unwrap();
    let err = refused(
        &["tune", s(&fine), "--loop", "pressure"],
        &["no pressure setpoint step"],
    );
    assert!(!err.contains("metadata"), "{err}");
    // Twenty lines of 60 kB each are more bytes than a header holds (1 MiB).
    let long = format!("# note: {}\n", "x".repeat(60_000)).repeat(20);
    let bulky = dir.join("bulky.csv");
    fs::write(&bulky, hold_rows(&long, 150, |i| i as f64 * 1e-3)).unwrap();
    refused(
        &["tune", s(&bulky), "--loop", "pressure"],
        &["bulky.csv", "line 18", "bytes of metadata"],
    );
}

#[test]
fn a_table_trailer_id_is_read_whole() {
    use firmware::compensation::record::{Encoder, CRC, RECORD_LEN};
    use host_sim::compensate::flow::FlowParams;
    let dir = scratch("trailer-id");
    let mut record = [0u8; RECORD_LEN];
    Encoder::write_all(&firmware::compensation::Table::ZERO, &mut record);
    let trailer = FlowParams {
        pistons: 9,
        ratio: 0.0152,
        phase_rad: 0.0,
        inertia_kg_m2: 8e-4,
    }
    .trailer();
    // The first parameter's id field (offset 8, four bytes) set to `id`, the CRC renewed.
    let table = |id: u32| {
        let mut t = trailer.clone();
        t[8..12].copy_from_slice(&id.to_le_bytes());
        let n = t.len();
        let crc = CRC.checksum(&t[..n - 4]);
        t[n - 4..].copy_from_slice(&crc.to_le_bytes());
        let path = dir.join(format!("id{id}.table"));
        fs::write(&path, [&record[..], &t].concat()).unwrap();
        path
    };
    let out = dir.join("run.csv");
    let sim = |t: &Path| {
        vec![
            "simulate".to_string(),
            "--scenario".into(),
            "pressure-hold".into(),
            "--duration".into(),
            "0.1".into(),
            "--out".into(),
            s(&out).into(),
            "--compensation".into(),
            s(t).into(),
        ]
    };
    // 320 = 0x140 and 9999 = 0x270F end in the bytes of ids 64 and 15.
    for id in [320u32, 9999, 0x0100_0040] {
        let args = sim(&table(id));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let err = refused(&args, &[&format!("unknown parameter id {id}")]);
        assert!(!err.contains("id 64") && !err.contains("id 15"), "{err}");
    }
    assert!(!out.exists());
    // The id as written (64) still loads.
    let args = sim(&table(64));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = eha(&args);
    assert_eq!(status(&o), 0, "{}", stderr(&o));
}

#[test]
fn messages_give_the_true_reason() {
    let dir = scratch("reasons");
    let out = dir.join("x.csv");
    // A cogging order is a count: a fraction, a negative, a huge number and 0 are said to
    // be no count of cycles, not "no finite number".
    for v in ["0.5", "-3", "1e30", "0"] {
        let effects = format!("cogging_torque:order={v}");
        let err = refused(
            &[
                "simulate",
                "--scenario",
                "pressure-hold",
                "--out",
                s(&out),
                "--effects",
                &effects,
            ],
            &["order", "whole number from 1 to 10000"],
        );
        assert!(!err.contains("finite"), "{err}");
    }
    // Left out, the order is the rig's LCM(9 slots, 8 poles) = 72, and the log says 72.
    let o = eha(&[
        "simulate",
        "--scenario",
        "pressure-hold",
        "--duration",
        "0.1",
        "--out",
        s(&out),
        "--effects",
        "cogging_torque",
    ]);
    assert_eq!(status(&o), 0, "{}", stderr(&o));
    let text = fs::read_to_string(&out).unwrap();
    let effects = text.lines().find(|l| l.starts_with("# effects:")).unwrap();
    assert!(effects.contains("order=72"), "{effects}");
    fs::remove_file(&out).unwrap();
    // Telemetry codes beyond the firmware's are said to be codes, not "no number".
    let line = |i: usize, mode: &str, fault: &str| {
        format!(
            "EHA1 t_s={} p_ref_pa=5000000 p_pa=5000000 speed_rad_s=6 iq_a=0.5 id_a=0 theta_m_rad=1 speed_ref_rad_s=6 iq_ref_a=0.5 ud_v=0 uq_v=1 udc_v=280 mode={mode} fault={fault} status=0\n",
            i as f64 * 1e-3
        )
    };
    let text: String = (0..150)
        .map(|i| match i {
            3 => line(i, "999", "0"),
            4 => line(i, "3", "-1"),
            _ => line(i, "3", "0"),
        })
        .collect();
    let telemetry = dir.join("codes.log");
    fs::write(&telemetry, text).unwrap();
    let err = refused(
        &["ingest", s(&telemetry), "--out", s(&out)],
        &[
            "codes.log:4",
            "not a mode code",
            "codes.log:5",
            "not a fault code",
        ],
    );
    assert!(!err.contains("is not a number"), "{err}");
    assert!(!out.exists());
}

#[test]
fn tune_proposes_no_gains_from_a_step_the_loop_did_not_follow() {
    let dir = scratch("tune-unfollowed");
    let log = dir.join("step.csv");
    let o = eha(&["simulate", "--scenario", "pressure-step", "--out", s(&log)]);
    assert_eq!(status(&o), 0, "{}", stderr(&o));
    // The setpoint steps 3 → 5 MPa at 0.5 s; the pressure reads on as it did before the
    // step (its first 0.45 s again and again: a loop left open, a sensor on another port).
    let before: Vec<f64> = host_sim::bench_log::read(&log).unwrap().p_pa[..900].to_vec();
    let flat = edited(&log, "flat.csv", "p_pa", |k, _| before[k % 900].to_string());
    let (json, can) = (dir.join("t.json"), dir.join("t.log"));
    let o = eha(&[
        "tune",
        s(&flat),
        "--loop",
        "pressure",
        "--json",
        s(&json),
        "--can-log",
        s(&can),
    ]);
    let err = stderr(&o);
    assert_eq!(status(&o), 2, "{err}");
    assert!(
        err.contains("does not follow") && err.contains("p_pa"),
        "{err}"
    );
    assert!(err.contains("0 % of the way"), "{err}");
    assert!(
        String::from_utf8_lossy(&o.stdout).trim().is_empty(),
        "no CAN lines"
    );
    assert!(!json.exists() && !can.exists());
}

#[test]
fn help_on_a_full_standard_output_is_an_error() {
    for args in [&["--help"][..], &["--version"], &["rig"]] {
        let full = fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_eha"))
            .args(args)
            .stdout(full)
            .output()
            .unwrap();
        assert_eq!(status(&o), 1, "{args:?}");
        assert!(
            stderr(&o).to_lowercase().contains("no space left"),
            "{args:?}: {}",
            stderr(&o)
        );
    }
}

/// Runs `args` with the environment `env` (the binary's test hooks).
fn eha_with(env: &[(&str, &str)], args: &[&str]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_eha"))
        .args(args)
        .envs(env.iter().copied())
        .output()
        .expect("the eha binary runs")
}

/// Every file of `dir` (hidden ones included) with its bytes, sorted.
fn contents(dir: &Path) -> Vec<(String, Vec<u8>)> {
    entries(dir)
        .into_iter()
        .map(|n| {
            let bytes = fs::read(dir.join(&n)).unwrap_or_default();
            (n, bytes)
        })
        .collect()
}

#[test]
fn links_in_output_folders_are_never_written_through() {
    let dir = scratch("folder-links");
    let log = hold_log_of(&dir, "in.csv", "0.5");
    let rig = dir.join("rig.toml");
    fs::write(&rig, rig_file::to_toml(&Rig::nominal())).unwrap();
    let before = |p: &Path| fs::read(p).unwrap();
    let (log_bytes, rig_bytes) = (before(&log), before(&rig));
    let folder = |name: &str, file: &str, to: &Path| {
        let d = dir.join(name);
        fs::create_dir(&d).unwrap();
        std::os::unix::fs::symlink(to, d.join(file)).unwrap();
        d
    };
    // The report, a figure of it, the sweep's plot and the demo's log, each a link to an
    // input: refused before any work, naming the link and its target.
    let report = folder("report", "report.md", Path::new("../in.csv"));
    let figure = folder("figure", "trace_p_pa.svg", &log);
    let sweep = folder("sweep", "sweep.svg", Path::new("../rig.toml"));
    let demo = folder("demo", "pressure-hold.csv", &log);
    for (args, named) in [
        (
            vec!["diagnose", s(&log), "--report", s(&report)],
            vec!["report.md", "symbolic link to `../in.csv`"],
        ),
        (
            vec!["diagnose", s(&log), "--report", s(&figure)],
            vec!["trace_p_pa.svg", "symbolic link"],
        ),
        (
            vec![
                "--rig",
                s(&rig),
                "sweep-precharge",
                "--values",
                "5e6",
                "--out",
                s(&sweep),
            ],
            vec!["sweep.svg", "symbolic link to `../rig.toml`"],
        ),
        (
            vec!["demo", "--out", s(&demo)],
            vec!["pressure-hold.csv", "symbolic link"],
        ),
    ] {
        let err = refused(&args, &named);
        assert!(err.contains("never writes through"), "{err}");
    }
    assert_eq!(before(&log), log_bytes, "the log is untouched");
    assert_eq!(before(&rig), rig_bytes, "the rig file is untouched");
    // Other things an output folder must not hold: the input itself, a file of the user's,
    // a folder; and no output file may lie inside an output folder (replaced whole).
    let holds_input = dir.join("holds-input");
    fs::create_dir(&holds_input).unwrap();
    let inner = hold_log_of(&holds_input, "in.csv", "0.5");
    refused(
        &["diagnose", s(&inner), "--report", s(&holds_input)],
        &["the input"],
    );
    let user = dir.join("user");
    fs::create_dir_all(user.join("sub")).unwrap();
    refused(
        &["sweep-precharge", "--values", "5e6", "--out", s(&user)],
        &["`sub`, a folder"],
    );
    fs::remove_dir(user.join("sub")).unwrap();
    fs::write(user.join("notes.txt"), "mine").unwrap();
    refused(
        &["sweep-precharge", "--values", "5e6", "--out", s(&user)],
        &["`notes.txt`", "none of the files eha writes there"],
    );
    assert_eq!(fs::read_to_string(user.join("notes.txt")).unwrap(), "mine");
    let fresh = dir.join("fresh");
    fs::create_dir(&fresh).unwrap();
    refused(
        &[
            "sweep-precharge",
            "--values",
            "5e6",
            "--out",
            s(&fresh),
            "--json",
            s(&fresh.join("sweep.json")),
        ],
        &["--json", "lies in the --out folder"],
    );
    assert!(entries(&fresh).is_empty());
    refused(&["demo", "--out", "."], &["names no folder"]);
}

#[test]
fn reusing_an_output_folder_leaves_no_file_of_an_earlier_run() {
    let dir = scratch("folder-reuse");
    let out = dir.join("sweep");
    let sweep = |values: &str| {
        let o = eha(&["sweep-precharge", "--values", values, "--out", s(&out)]);
        assert_eq!(status(&o), 0, "{}", stderr(&o));
    };
    sweep("4e6,5e6");
    assert!(out.join("precharge-4.0MPa.csv").exists());
    sweep("5e6");
    assert_eq!(
        entries(&out),
        [
            "no-absorber.csv",
            "precharge-5.0MPa.csv",
            "pressure_traces.png",
            "pressure_traces.svg",
            "sweep.png",
            "sweep.svg"
        ],
        "the 4 MPa run's log is gone with the earlier sweep"
    );
    // A folder named through a link is the one replaced; the link stays.
    let real = dir.join("real");
    fs::create_dir(&real).unwrap();
    fs::write(real.join("precharge-9.0MPa.csv"), "old").unwrap();
    let link = dir.join("link");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    let o = eha(&["sweep-precharge", "--values", "5e6", "--out", s(&link)]);
    assert_eq!(status(&o), 0, "{}", stderr(&o));
    assert!(fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(real.join("sweep.svg").exists() && !real.join("precharge-9.0MPa.csv").exists());
    // A report folder: the earlier log's residual spectra do not stay beside the new report
    // (a spectrum of oil_temp_c, which this log does not have, stands for them).
    let log = hold_log_of(&dir, "hold.csv", "1");
    let report = dir.join("report");
    fs::create_dir(&report).unwrap();
    for stale in [
        "residual_spectrum_oil_temp_c.svg",
        "residual_spectrum_oil_temp_c.png",
    ] {
        fs::write(report.join(stale), "of an earlier log").unwrap();
    }
    let o = eha(&["diagnose", s(&log), "--report", s(&report)]);
    assert_eq!(status(&o), 0, "{}", stderr(&o));
    let now = entries(&report);
    assert!(now.contains(&"report.md".to_string()), "{now:?}");
    assert!(!now.iter().any(|n| n.contains("oil_temp_c")), "{now:?}");
    assert!(
        entries(&dir).iter().all(|n| !n.starts_with('.')),
        "nothing hidden left"
    );
}

#[test]
fn a_full_disk_on_the_last_output_leaves_nothing() {
    let dir = scratch("full-disk");
    let full = |n: &'static str| [("EHA_TEST_FULL_AT", n)];
    let sim = dir.join("s.csv");
    let json = dir.join("s.json");
    // The bench log was written before; the run's log and its summary fail together.
    fs::write(&sim, "an earlier run").unwrap();
    let o = eha_with(
        &full("staged:2"),
        &[
            "simulate",
            "--scenario",
            "pressure-hold",
            "--duration",
            "0.1",
            "--out",
            s(&sim),
            "--json",
            s(&json),
        ],
    );
    let err = stderr(&o);
    assert_eq!(status(&o), 1, "{err}");
    assert!(
        err.contains("s.json") && err.contains("no space left on device"),
        "{err}"
    );
    assert!(
        err.contains("no output written") && !err.contains("written to"),
        "{err}"
    );
    assert_eq!(fs::read_to_string(&sim).unwrap(), "an earlier run");
    assert_eq!(entries(&dir), ["s.csv"], "no JSON, no temporary file");
    // Tuning: the CAN log and the JSON.
    let step = dir.join("step.csv");
    let o = eha(&["simulate", "--scenario", "pressure-step", "--out", s(&step)]);
    assert_eq!(status(&o), 0, "{}", stderr(&o));
    let (can, tuned) = (dir.join("t.log"), dir.join("t.json"));
    let o = eha_with(
        &full("staged:2"),
        &[
            "tune",
            s(&step),
            "--loop",
            "pressure",
            "--can-log",
            s(&can),
            "--json",
            s(&tuned),
        ],
    );
    assert_eq!(status(&o), 1, "{}", stderr(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout).is_empty(),
        "no CAN lines printed"
    );
    assert!(!can.exists() && !tuned.exists());
    // Learning a table: the table and its CAN log.
    let hold = hold_log_of(&dir, "hold.csv", "1");
    let (table, load) = (dir.join("t.table"), dir.join("load.log"));
    let o = eha_with(
        &full("staged:2"),
        &[
            "compensate",
            s(&hold),
            "--out",
            s(&table),
            "--can-log",
            s(&load),
        ],
    );
    assert_eq!(status(&o), 1, "{}", stderr(&o));
    assert!(!table.exists() && !load.exists());
    // A folder and the JSON after it: the folder as it was, no JSON.
    let out = dir.join("sweep");
    let summary = dir.join("sweep.json");
    let sweep = |env: &[(&str, &str)]| {
        eha_with(
            env,
            &[
                "sweep-precharge",
                "--values",
                "5e6",
                "--out",
                s(&out),
                "--json",
                s(&summary),
            ],
        )
    };
    let o = sweep(&[]);
    assert_eq!(status(&o), 0, "{}", stderr(&o));
    fs::remove_file(&summary).unwrap();
    let was = contents(&out);
    let listing = entries(&dir);
    for point in ["staged:1", "staged:2"] {
        let o = sweep(&full(point));
        assert_eq!(status(&o), 1, "{point}: {}", stderr(&o));
        assert!(stderr(&o).contains("no output written"), "{}", stderr(&o));
        assert_eq!(contents(&out), was, "{point}: the folder as it was");
        assert_eq!(
            entries(&dir),
            listing,
            "{point}: no JSON, no staging folder"
        );
    }
}

#[test]
fn an_interrupt_in_the_write_phase_leaves_every_output_or_none() {
    let dir = scratch("interrupt-points");
    let (sim, json) = (dir.join("s.csv"), dir.join("s.json"));
    let run = |point: &str| {
        eha_with(
            &[("EHA_TEST_INTERRUPT_AT", point)],
            &[
                "simulate",
                "--scenario",
                "pressure-hold",
                "--duration",
                "0.1",
                "--out",
                s(&sim),
                "--json",
                s(&json),
            ],
        )
    };
    // Earlier outputs stand for what must survive an interrupted run whole.
    let earlier = |dir: &Path| {
        fs::write(&sim, "earlier log").unwrap();
        fs::write(&json, "earlier summary").unwrap();
        contents(dir)
    };
    // Before the commit: nothing of the run, the earlier files as they were.
    for point in ["staged:1", "staged:2"] {
        let was = earlier(&dir);
        let o = run(point);
        assert_eq!(status(&o), 130, "{point}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("interrupted; no output written"),
            "{}",
            stderr(&o)
        );
        assert_eq!(
            contents(&dir),
            was,
            "{point}: no output, nothing hidden left"
        );
    }
    // During the commit (signals held) and after it: every output, whole.
    for point in ["committed:1", "committed:2", "done"] {
        earlier(&dir);
        let o = run(point);
        assert_eq!(status(&o), 130, "{point}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("interrupted after every output was written"),
            "{point}: {}",
            stderr(&o)
        );
        assert_eq!(entries(&dir), ["s.csv", "s.json"], "{point}");
        let log = host_sim::bench_log::read(&sim).unwrap();
        assert_eq!(log.len(), 200, "{point}: 0.1 s at 2 kHz");
        let v: serde_json::Value =
            serde_json::from_str(&fs::read_to_string(&json).unwrap()).unwrap();
        assert_eq!(v["rows"], 200, "{point}");
    }
    // A folder: interrupted once it is staged, the earlier sweep stays as it was and no
    // staging folder is left; during the commit, the new sweep is there whole.
    let out = dir.join("deep/sweep");
    let summary = dir.join("sweep.json");
    let sweep = |values: &str, point: &str| {
        eha_with(
            &[("EHA_TEST_INTERRUPT_AT", point)],
            &[
                "sweep-precharge",
                "--values",
                values,
                "--out",
                s(&out),
                "--json",
                s(&summary),
            ],
        )
    };
    let o = sweep("5e6", "staged:1");
    assert_eq!(status(&o), 130, "{}", stderr(&o));
    assert!(
        !dir.join("deep").exists(),
        "not even the folder made for it"
    );
    let o = sweep("5e6", "none");
    assert_eq!(status(&o), 0, "{}", stderr(&o));
    let was = contents(&out);
    let o = sweep("4e6", "staged:2");
    assert_eq!(status(&o), 130, "{}", stderr(&o));
    assert_eq!(contents(&out), was);
    assert_eq!(entries(&dir.join("deep")), ["sweep"], "no staging folder");
    let o = sweep("4e6", "committed:1");
    assert_eq!(status(&o), 130, "{}", stderr(&o));
    assert!(out.join("precharge-4.0MPa.csv").exists() && summary.exists());
    assert!(!out.join("precharge-5.0MPa.csv").exists());
    assert_eq!(
        entries(&dir.join("deep")),
        ["sweep"],
        "no earlier folder kept aside"
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

#[test]
fn the_demo_folder_is_written_whole_or_not_at_all() {
    // `eha demo --out D` has one output, its folder: a full disk or an interrupt while it
    // is staged leaves a fresh D absent (not an empty folder) and an earlier D as it was,
    // with no staging folder beside it.
    let dir = scratch("demo-transaction");
    let out = dir.join("d");
    let demo = |env: &[(&str, &str)]| eha_with(env, &["demo", "--out", s(&out)]);
    let o = demo(&[("EHA_TEST_FULL_AT", "staged:1")]);
    assert_eq!(status(&o), 1, "{}", stderr(&o));
    assert!(stderr(&o).contains("no output written"), "{}", stderr(&o));
    assert!(entries(&dir).is_empty(), "{:?}", entries(&dir));
    let o = demo(&[("EHA_TEST_INTERRUPT_AT", "staged:1")]);
    assert_eq!(status(&o), 130, "{}", stderr(&o));
    assert!(entries(&dir).is_empty(), "{:?}", entries(&dir));
    let o = demo(&[]);
    assert_eq!(status(&o), 0, "{}", stderr(&o));
    let was = contents(&out);
    assert!(
        was.iter().any(|(n, _)| n == "pressure_trace.png"),
        "{was:?}"
    );
    for env in [
        ("EHA_TEST_FULL_AT", "staged:1"),
        ("EHA_TEST_INTERRUPT_AT", "staged:1"),
    ] {
        let o = demo(&[env]);
        assert_ne!(status(&o), 0, "{env:?}");
        assert_eq!(contents(&out), was, "{env:?}: the folder as it was");
        assert_eq!(entries(&dir), ["d"], "{env:?}: no staging folder");
    }
}
