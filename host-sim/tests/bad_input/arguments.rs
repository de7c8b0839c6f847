//! The command line's own faults: paths that are missing, special or an input's, numbers
//! out of range, unknown names, and rig values no plant has (or a lag shorter than the step,
//! which must simulate, not be refused).

use super::*;

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
