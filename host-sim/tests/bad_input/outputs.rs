//! What the commands write when the run is cut short or the place is unsafe: an interrupt
//! before or during the write phase, a full disk, a full standard output, links inside an
//! output folder and a folder reused: every output whole or none, no file of an earlier run.

use super::*;

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
    let o = eha_with(&full("staged:2"), &short_hold(&sim, &["--json", s(&json)]));
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
            &short_hold(&sim, &["--json", s(&json)]),
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
