//! `eha fleet` end to end on logs `eha simulate` writes (two drives, two logs each, their
//! drive and time in the logs' metadata): the table and its statuses, a corrupt log, an
//! unreadable file and a special file each a row with its reason, the exit status, the
//! resumption from the kept diagnoses, shards that concatenate into the whole table, a
//! manifest, a diagnosis killed mid-run or stopped by the time limit, bad arguments.

mod common;

use common::{eha, s, scratch};
use serde_json::Value;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// The four simulated logs (drive, time, file name), made once for every test.
const LOGS: [(&str, &str, &str); 4] = [
    ("press-a", "2026-01-05T08:00:00Z", "a1.csv"),
    ("press-a", "2026-02-05T08:00:00Z", "a2.csv"),
    ("press-b", "2026-01-07T08:00:00Z", "b1.csv"),
    ("press-b", "2026-02-07T08:00:00Z", "b2.csv"),
];

/// The folder of [`LOGS`], simulated once (1 s of pressure holding each).
fn simulated() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let d = scratch("fleet", "logs");
        for (k, (drive, at, name)) in LOGS.iter().enumerate() {
            let seed = (k + 1).to_string();
            let o = eha(&[
                "simulate",
                "--scenario",
                "pressure-hold",
                "--duration",
                "1",
                "--log-rate",
                "1000",
                "--seed",
                &seed,
                "--drive",
                drive,
                "--recorded-at",
                at,
                "--out",
                s(&d.join(name)),
            ]);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        }
        d
    })
}

/// A fresh folder `logs/` holding copies of the simulated logs, and its parent.
fn fleet_folder(name: &str) -> (PathBuf, PathBuf) {
    let d = scratch("fleet", name);
    let logs = d.join("logs");
    fs::create_dir_all(&logs).unwrap();
    for (_, _, f) in LOGS {
        fs::copy(simulated().join(f), logs.join(f)).unwrap();
    }
    (d, logs)
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// The CSV's rows as field vectors (header first).
fn csv_rows(path: &Path) -> Vec<Vec<String>> {
    let mut r = csv::ReaderBuilder::new()
        .has_headers(false)
        .from_path(path)
        .unwrap();
    r.records()
        .map(|x| x.unwrap().iter().map(str::to_string).collect())
        .collect()
}

fn column<'a>(rows: &'a [Vec<String>], name: &str) -> Vec<&'a str> {
    let c = rows[0].iter().position(|h| h == name).unwrap();
    rows[1..].iter().map(|r| r[c].as_str()).collect()
}

/// A copy of `good` with one value of data row 50 made unreadable.
fn corrupt(good: &Path, to: &Path) {
    let t = fs::read_to_string(good).unwrap();
    let mut lines: Vec<String> = t.lines().map(str::to_string).collect();
    let header = lines.iter().position(|l| !l.starts_with('#')).unwrap();
    let row = &mut lines[header + 50];
    let comma = row.find(',').unwrap();
    row.replace_range(comma + 1..comma + 1, "x");
    fs::write(to, lines.join("\n") + "\n").unwrap();
}

#[test]
fn bad_logs_are_rows_with_their_reason_and_a_second_run_resumes() {
    let (d, logs) = fleet_folder("resume");
    corrupt(&logs.join("a1.csv"), &logs.join("corrupt.csv"));
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(d.join("nowhere.csv"), logs.join("dangling.csv")).unwrap();
        let fifo = Command::new("mkfifo")
            .arg(logs.join("fifo.csv"))
            .status()
            .unwrap();
        assert!(fifo.success());
    }
    fs::write(logs.join("notes.txt"), "not a log").unwrap();
    let out = d.join("out");
    let summary = d.join("summary.json");
    let o = eha(&[
        "fleet",
        s(&logs),
        "--out",
        s(&out),
        "--jobs",
        "2",
        "--json",
        s(&summary),
    ]);
    // Some logs failed: status 1, the message points at the table.
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("fleet.csv"), "{}", text(&o.stderr));
    let rows = csv_rows(&out.join("fleet.csv"));
    let paths = column(&rows, "path");
    let status = column(&rows, "status");
    let expected_rows = if cfg!(unix) { 7 } else { 5 };
    assert_eq!(rows.len() - 1, expected_rows, "{paths:?}");
    // Rows without a drive first (the unreadable ones), then by drive and time; the
    // corrupt copy of a1 keeps a1's drive and time and follows it by name.
    let drives = column(&rows, "drive");
    let ok: Vec<usize> = (0..status.len()).filter(|&i| status[i] == "ok").collect();
    assert_eq!(
        ok.iter().map(|&i| drives[i]).collect::<Vec<_>>(),
        ["press-a", "press-a", "press-b", "press-b"]
    );
    let n_bad = expected_rows - 4;
    assert!(
        drives[..n_bad - 1].iter().all(|d| d.is_empty()),
        "{drives:?}"
    );
    let reason = |name: &str| status[paths.iter().position(|p| p.ends_with(name)).unwrap()];
    // The corrupt log: the diagnosis's own message, naming the line and column.
    let c = reason("corrupt.csv");
    assert!(c.starts_with("error: bench log"), "{c}");
    assert!(
        c.contains("line") && c.contains("not a finite number"),
        "{c}"
    );
    if cfg!(unix) {
        assert!(reason("dangling.csv").contains("does not exist"));
        assert!(reason("fifo.csv").contains("not a regular file"));
    }
    // Every good row has its hash, its noise ratios, and `none` named on a nominal rig.
    let effects = column(&rows, "effects");
    let ratios = column(&rows, "noise_ratio.extended.p_pa");
    for &i in &ok {
        assert!(!effects[i].is_empty(), "{effects:?}");
        assert!(ratios[i].parse::<f64>().is_ok(), "{ratios:?}");
    }
    let s1: Value = serde_json::from_str(&fs::read_to_string(&summary).unwrap()).unwrap();
    assert_eq!(s1["diagnosed_now"], 5, "{s1}");
    assert_eq!(s1["failed"], expected_rows - 4);
    assert!(
        s1["worker_peak_rss_bytes"].as_u64().is_some_and(|b| b > 0) || !cfg!(target_os = "linux")
    );
    let json: Value =
        serde_json::from_str(&fs::read_to_string(out.join("fleet.json")).unwrap()).unwrap();
    assert_eq!(json["rows"].as_array().unwrap().len(), expected_rows);
    // Nothing half-written is left beside the tables.
    let hidden: Vec<_> = fs::read_dir(&out)
        .unwrap()
        .chain(fs::read_dir(out.join("diagnoses")).unwrap())
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");

    // Again: nothing is diagnosed twice (the corrupt log's refusal is kept too), and the
    // table is the same.
    let before = fs::read(out.join("fleet.csv")).unwrap();
    let o = eha(&["fleet", s(&logs), "--out", s(&out), "--json", s(&summary)]);
    assert_eq!(o.status.code(), Some(1));
    let s2: Value = serde_json::from_str(&fs::read_to_string(&summary).unwrap()).unwrap();
    assert_eq!(s2["diagnosed_now"], 0, "{s2}");
    assert_eq!(s2["read_back"], 5);
    assert_eq!(fs::read(out.join("fleet.csv")).unwrap(), before);

    // Two shards, their kept diagnoses copied from the whole run, concatenate into it.
    let mut concatenated = vec![rows[0].clone()];
    let mut json_rows = Vec::new();
    for k in 0..2 {
        let shard_out = d.join(format!("shard-{k}"));
        copy_dir(&out.join("diagnoses"), &shard_out.join("diagnoses"));
        let o = eha(&[
            "fleet",
            s(&logs),
            "--out",
            s(&shard_out),
            "--shard",
            &format!("{k}/2"),
            "--json",
            s(&summary),
        ]);
        assert!(o.status.code().is_some(), "{}", text(&o.stderr));
        let sj: Value = serde_json::from_str(&fs::read_to_string(&summary).unwrap()).unwrap();
        assert_eq!(sj["diagnosed_now"], 0);
        let part = csv_rows(&shard_out.join("fleet.csv"));
        assert_eq!(part[0], rows[0]);
        concatenated.extend(part[1..].iter().cloned());
        let pj: Value =
            serde_json::from_str(&fs::read_to_string(shard_out.join("fleet.json")).unwrap())
                .unwrap();
        json_rows.extend(pj["rows"].as_array().unwrap().iter().cloned());
    }
    assert_eq!(concatenated, rows);
    assert_eq!(Value::Array(json_rows), json["rows"]);
    fs::remove_dir_all(&d).unwrap();
}

fn copy_dir(from: &Path, to: &Path) {
    fs::create_dir_all(to).unwrap();
    for e in fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
}

#[test]
fn a_manifest_names_the_drive_and_time_of_logs_without_them() {
    let d = scratch("fleet", "manifest");
    // A log without drive and time lines: the metadata stripped.
    let t = fs::read_to_string(simulated().join("a1.csv")).unwrap();
    let bare: String = t
        .lines()
        .filter(|l| !l.starts_with("# drive") && !l.starts_with("# recorded_at"))
        .map(|l| format!("{l}\n"))
        .collect();
    fs::create_dir_all(d.join("logs")).unwrap();
    fs::write(d.join("logs/bare.csv"), bare).unwrap();
    let manifest = d.join("manifest.csv");
    fs::write(
        &manifest,
        "path,drive,recorded_at\nlogs/bare.csv,press-z,2026-03-01T10:00:00+01:00\n",
    )
    .unwrap();
    let out = d.join("out");
    let o = eha(&["fleet", "--manifest", s(&manifest), "--out", s(&out)]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let rows = csv_rows(&out.join("fleet.csv"));
    assert_eq!(column(&rows, "drive"), ["press-z"]);
    assert_eq!(column(&rows, "recorded_at"), ["2026-03-01T10:00:00+01:00"]);
    assert!(column(&rows, "path")[0].ends_with("bare.csv"));
    fs::remove_dir_all(&d).unwrap();
}

/// The `eha` children of process `parent` (Linux: `/proc/PID/stat`'s fourth field).
#[cfg(target_os = "linux")]
fn children(parent: u32) -> Vec<u32> {
    let mut out = Vec::new();
    for e in fs::read_dir("/proc").unwrap().filter_map(|e| e.ok()) {
        let Ok(pid) = e.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        let Ok(stat) = fs::read_to_string(format!("/proc/{pid}/stat")) else {
            continue;
        };
        // pid (comm) state ppid …: comm may hold spaces, so read after its closing ')'.
        let after = stat.rsplit_once(')').map_or("", |x| x.1);
        let ppid = after
            .split_whitespace()
            .nth(1)
            .and_then(|p| p.parse::<u32>().ok());
        if ppid == Some(parent) {
            out.push(pid);
        }
    }
    out
}

#[cfg(target_os = "linux")]
#[test]
fn a_diagnosis_killed_mid_run_is_reported_and_run_again_next_time() {
    let (d, logs) = fleet_folder("killed");
    let out = d.join("out");
    let summary = d.join("summary.json");
    let fleet = Command::new(env!("CARGO_BIN_EXE_eha"))
        .args(["fleet", s(&logs), "--out", s(&out), "--jobs", "1"])
        .args(["--json", s(&summary)])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The first diagnosis the fleet starts is killed, as the out-of-memory killer would.
    let start = Instant::now();
    let victim = loop {
        if let Some(&pid) = children(fleet.id()).first() {
            break pid;
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no diagnosis started"
        );
        std::thread::sleep(Duration::from_millis(5));
    };
    let killed = Command::new("kill")
        .args(["-KILL", &victim.to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let o = fleet.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    let rows = csv_rows(&out.join("fleet.csv"));
    let status = column(&rows, "status");
    assert_eq!(status.len(), 4, "every log has its row");
    let bad: Vec<&&str> = status.iter().filter(|s| **s != "ok").collect();
    assert_eq!(bad.len(), 1, "{status:?}");
    assert!(bad[0].contains("killed by signal 9"), "{}", bad[0]);
    // Its diagnosis is not kept, and no staging file is left: the next run tries it alone.
    let kept = fs::read_dir(out.join("diagnoses")).unwrap().count();
    assert_eq!(kept, 3);
    let o = eha(&["fleet", s(&logs), "--out", s(&out), "--json", s(&summary)]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let sj: Value = serde_json::from_str(&fs::read_to_string(&summary).unwrap()).unwrap();
    assert_eq!(sj["diagnosed_now"], 1, "{sj}");
    assert!(column(&csv_rows(&out.join("fleet.csv")), "status")
        .iter()
        .all(|s| *s == "ok"));
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn the_time_limit_stops_a_diagnosis_and_keeps_nothing() {
    let (d, logs) = fleet_folder("timeout");
    let out = d.join("out");
    let o = eha(&[
        "fleet",
        s(&logs.join("a1.csv")),
        "--out",
        s(&out),
        "--timeout",
        "0.01",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    let rows = csv_rows(&out.join("fleet.csv"));
    let st = column(&rows, "status");
    assert!(st[0].contains("time limit"), "{st:?}");
    assert_eq!(fs::read_dir(out.join("diagnoses")).unwrap().count(), 0);
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn bad_arguments_exit_with_status_2_before_any_work() {
    let d = scratch("fleet", "args");
    let out = d.join("out");
    let manifest = d.join("m.csv");
    fs::write(&manifest, "file,drive\nx.csv,d\n").unwrap();
    fs::create_dir_all(d.join("empty")).unwrap();
    for (args, says) in [
        (vec!["fleet", "nowhere", "--out", s(&out)], "does not exist"),
        (
            vec!["fleet", s(&d), "--out", s(&out), "--shard", "2/2"],
            "below N",
        ),
        (vec!["fleet", s(&d), "--out", s(&out), "--jobs", "0"], "0"),
        (
            vec!["fleet", "--manifest", s(&manifest), "--out", s(&out)],
            "path",
        ),
        (
            vec!["fleet", s(&d.join("empty")), "--out", s(&out)],
            "no bench logs",
        ),
        (vec!["fleet", s(&d)], "--out"),
    ] {
        let o = eha(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o.stderr));
        assert!(
            text(&o.stderr).contains(says),
            "{args:?}: {}",
            text(&o.stderr)
        );
    }
    assert!(!out.join("fleet.csv").exists());
    fs::remove_dir_all(&d).unwrap();
}
