//! The `eha` binary as scripts call it (`shared/contracts/eha-cli.md`): exit statuses,
//! error messages that name the problem, no partial output, the rig round trip and the
//! accumulator-design numbers against hand computation.

mod common;

use common::{eha, s};
use host_sim::rig_file;
use plant_model::Rig;
use std::f64::consts::PI;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

fn status(o: &Output) -> i32 {
    o.status.code().expect("exited, not killed by a signal")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A fresh, empty folder per test.
fn scratch(name: &str) -> PathBuf {
    common::scratch("cli", name)
}

// ---------------------------------------------------------------- bench logs

const HEADER: &str = "t_s,p_ref_pa,p_pa,speed_rad_s,iq_a,id_a";

/// Two metadata lines (lines 1–2), the header (line 3), data rows from line 4.
fn log_text(rows: usize, header: &str, row: impl Fn(usize) -> String) -> String {
    let mut s = String::from("# source: bench\n# rig: nominal\n");
    s.push_str(header);
    s.push('\n');
    for i in 0..rows {
        s.push_str(&row(i));
        s.push('\n');
    }
    s
}

fn good_row(i: usize) -> String {
    format!(
        "{},5e6,{},5.86,0.4,0",
        i as f64 * 1e-3,
        5e6 + 100.0 * i as f64
    )
}

fn with_row(n: usize, text: &'static str) -> impl Fn(usize) -> String {
    move |i| {
        if i == n {
            text.to_string()
        } else {
            good_row(i)
        }
    }
}

#[test]
fn every_bad_log_exits_2_naming_file_line_and_column_and_writes_nothing() {
    // (case, file content, line, column) — lines counted by construction above.
    let cases: Vec<(&str, String, usize, &str)> = vec![
        (
            "missing-column",
            log_text(100, "t_s,p_ref_pa,p_pa,iq_a,id_a", |i| {
                format!("{i},0,0,0,0")
            }),
            3,
            "speed_rad_s",
        ),
        (
            "duplicate-column",
            log_text(100, &format!("{HEADER},iq_a"), |i| {
                format!("{},0", good_row(i))
            }),
            3,
            "iq_a",
        ),
        (
            "not-a-number",
            log_text(100, HEADER, with_row(10, "0.01,5e6,abc,5.86,0.4,0")),
            14,
            "p_pa",
        ),
        (
            "not-finite",
            log_text(100, HEADER, with_row(5, "0.005,5e6,5e6,5.86,inf,0")),
            9,
            "iq_a",
        ),
        (
            "time-not-increasing",
            log_text(100, HEADER, with_row(20, "0.0185,5e6,5e6,5.86,0.4,0")),
            24,
            "t_s",
        ),
        ("too-few-rows", log_text(99, HEADER, good_row), 102, "t_s"),
        (
            "wrong-field-count",
            log_text(100, HEADER, with_row(30, "0.03,5e6,5e6,5.86,0.4")),
            34,
            "id_a",
        ),
    ];
    for (case, text, line, column) in cases {
        let dir = scratch(&format!("bad-log-{case}"));
        let log = dir.join(format!("{case}.csv"));
        fs::write(&log, text).unwrap();
        let json = dir.join("out.json");
        let report = dir.join("report");
        for args in [
            vec![
                "diagnose",
                s(&log),
                "--json",
                s(&json),
                "--report",
                s(&report),
            ],
            vec!["tune", s(&log), "--loop", "pressure", "--json", s(&json)],
        ] {
            let o = eha(&args);
            let err = stderr(&o);
            assert_eq!(status(&o), 2, "{case} {args:?}: {err}");
            assert!(err.contains(s(&log)), "{case}: names the file: {err}");
            assert!(
                err.contains(&format!("line {line}")),
                "{case}: line {line}: {err}"
            );
            assert!(
                err.contains(&format!("column `{column}`")),
                "{case}: column {column}: {err}"
            );
            assert!(!err.contains("panicked"), "{err}");
            assert!(!json.exists(), "{case}: no output file");
            assert_eq!(
                fs::read_dir(&dir).unwrap().count(),
                1,
                "{case}: nothing left"
            );
        }
    }
}

#[test]
fn a_missing_log_exits_2_naming_it() {
    let o = eha(&["diagnose", "no/such/log.csv"]);
    assert_eq!(status(&o), 2, "{}", stderr(&o));
    assert!(stderr(&o).contains("no/such/log.csv"));
}

// ---------------------------------------------------------------- arguments

#[test]
fn bad_arguments_exit_2_naming_the_problem() {
    let cases: [(&[&str], &str); 7] = [
        (&["frobnicate"], "frobnicate"),
        (
            &[
                "simulate",
                "--scenario",
                "hold",
                "--out",
                "x.csv",
                "--precharge=-5e6",
            ],
            "--precharge",
        ),
        (&["sweep-precharge", "--values", "2e6,abc"], "abc"),
        (&["tune", "log.csv"], "--loop"),
        (&["tune", "log.csv", "--loop", "position"], "position"),
        (
            &[
                "simulate",
                "--scenario",
                "hold",
                "--out",
                "x.csv",
                "--effects",
                "warp_drive",
            ],
            "warp_drive",
        ),
        // Below the nominal 0.5 MPa fill pressure there is no holding point.
        (&["accumulator-design", "--pressure", "1e5"], "fill"),
    ];
    for (args, named) in cases {
        let o = eha(args);
        let err = stderr(&o);
        assert_eq!(status(&o), 2, "{args:?}: {err}");
        assert!(err.contains(named), "{args:?} should name {named}: {err}");
    }
}

#[test]
fn help_and_version_succeed() {
    for args in [
        &["--help"][..],
        &["--version"],
        &["accumulator-design", "--help"],
    ] {
        let o = eha(args);
        assert_eq!(status(&o), 0, "{args:?}");
        assert!(!stdout(&o).is_empty());
    }
    // The contract's subcommands are all there.
    let help = stdout(&eha(&["--help"]));
    for c in [
        "rig",
        "demo",
        "simulate",
        "sweep-precharge",
        "accumulator-design",
        "commission",
        "tune",
        "ingest",
        "diagnose",
        "watch",
    ] {
        assert!(help.contains(c), "{c} missing from --help");
    }
}

#[test]
fn demo_writes_a_png_beside_every_svg_and_the_pressure_figure_apart_from_the_reading() {
    let dir = scratch("demo-figures");
    let o = eha(&["demo", "--out", s(&dir)]);
    assert_eq!(status(&o), 0, "{}", stderr(&o));
    let mut svgs = 0;
    for e in fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "svg") {
            svgs += 1;
            let png = fs::read(p.with_extension("png")).expect("a PNG beside the SVG");
            assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{}", p.display());
        }
    }
    assert_eq!(svgs, 4);
    // The true pressures on one scale, the transducer's reading on a panel of its own.
    let svg = fs::read_to_string(dir.join("pressure_trace.svg")).unwrap();
    for label in [
        "true p - 5 MPa [kPa]",
        "measured p - 5 MPa [kPa]",
        "true, no absorber",
        "true, absorber fitted",
    ] {
        assert!(svg.contains(label), "{label}");
    }
}

// ---------------------------------------------------------------- rig files

#[test]
fn rig_prints_the_nominal_rig_and_reads_back_identically() {
    let o = eha(&["rig"]);
    assert_eq!(status(&o), 0, "{}", stderr(&o));
    let text = stdout(&o);
    let rig = rig_file::from_toml(&text, Path::new("<stdout>")).unwrap();
    assert_eq!(rig, Rig::nominal());

    // Through the binary again: load the printed file with --rig and print it.
    let dir = scratch("rig-round-trip");
    let file = dir.join("nominal.toml");
    fs::write(&file, &text).unwrap();
    let again = eha(&["--rig", s(&file), "rig"]);
    assert_eq!(status(&again), 0, "{}", stderr(&again));
    assert_eq!(stdout(&again), text);

    // JSON of the same rig, on stdout alone and to a file next to the TOML.
    let j = eha(&["rig", "--json", "-"]);
    let from_json: Rig = serde_json::from_slice(&j.stdout).unwrap();
    assert_eq!(from_json, Rig::nominal());
    let json = dir.join("rig.json");
    let both = eha(&["rig", "--json", s(&json)]);
    assert_eq!(stdout(&both), text);
    let from_file: Rig = serde_json::from_str(&fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(from_file, Rig::nominal());
}

#[test]
fn bad_rig_files_exit_2_naming_the_problem() {
    let nominal = rig_file::to_toml(&Rig::nominal());
    let dir = scratch("bad-rig");
    let edit = |name: &str, from: &str, to: &str| {
        assert_eq!(nominal.matches(from).count(), 1, "`{from}` must be unique");
        let p = dir.join(name);
        fs::write(&p, nominal.replace(from, to)).unwrap();
        p
    };

    let negative = edit(
        "negative.toml",
        "shell_volume_m3 = 0.0004",
        "shell_volume_m3 = -0.0004",
    );
    let o = eha(&["--rig", s(&negative), "accumulator-design"]);
    assert_eq!(status(&o), 2, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("absorber.shell_volume_m3"),
        "{}",
        stderr(&o)
    );
    assert!(stderr(&o).contains("negative.toml"), "{}", stderr(&o));
    assert!(stdout(&o).is_empty());

    let word = edit(
        "word.toml",
        "precharge_pa = 3000000.0",
        "precharge_pa = \"3 MPa\"",
    );
    let line = 1 + nominal[..nominal.find("precharge_pa = 3000000.0").unwrap()]
        .matches('\n')
        .count();
    let o = eha(&["--rig", s(&word), "rig"]);
    let err = stderr(&o);
    assert_eq!(status(&o), 2, "{err}");
    assert!(err.contains("absorber.precharge_pa"), "{err}");
    assert!(err.contains(&format!("line {line}")), "line {line}: {err}");
    assert!(err.contains("word.toml"), "{err}");

    let typo = edit("typo.toml", "bulk_modulus_pa", "bulk_modulus");
    let o = eha(&["--rig", s(&typo), "rig"]);
    assert_eq!(status(&o), 2, "{}", stderr(&o));
    assert!(stderr(&o).contains("bulk_modulus"), "{}", stderr(&o));

    let o = eha(&["--rig", "no/such/rig.toml", "rig"]);
    assert_eq!(status(&o), 2, "{}", stderr(&o));
    assert!(stderr(&o).contains("no/such/rig.toml"));
}

// ---------------------------------------------------------------- accumulator design

/// Nominal-rig values (nominal-rig.md) and the rig's assumed absorber inlet.
const V0: f64 = 400e-6; // m³
const N: f64 = 1.3;
const I: f64 = 3.85e5; // kg/m⁴
const R: f64 = 3e7; // Pa·s/m³
const P_ATM: f64 = 101_325.0;

/// Natural frequency [Hz] and damping ratio of the absorber precharged to `precharge`
/// at `pressure` (both gauge): gas volume V0·(p0/p)^(1/n), capacitance C = V/(n·p) in
/// absolute pressure, ω_n = 1/√(I·C), ζ = (R/2)·√(C/I).
fn hand_absorber(precharge: f64, pressure: f64) -> (f64, f64) {
    let (p0, p) = (precharge + P_ATM, pressure + P_ATM);
    let c = V0 * (p0 / p).powf(1.0 / N) / (N * p);
    (1.0 / (I * c).sqrt() / (2.0 * PI), R / 2.0 * (c / I).sqrt())
}

fn design_json(extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["accumulator-design", "--json", "-"];
    args.extend_from_slice(extra);
    let o = eha(&args);
    assert_eq!(status(&o), 0, "{}", stderr(&o));
    serde_json::from_slice(&o.stdout).expect("stdout is one JSON object")
}

fn f(v: &serde_json::Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("`{key}` is a number"))
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    ((a - b) / b).abs() < rel
}

#[test]
fn accumulator_design_matches_hand_computation() {
    let v = design_json(&[]);

    // Holding at 5 MPa: leakage 1e-13·(4.5e6 + 5e6 + 4.5e6) = 1.4e-6 m³/s through
    // 1.5 mL/rev → 0.9333 rev/s; 9 pistons → 18 pulses per revolution → 16.8 Hz.
    assert!(close(f(&v, "pulsation_frequency_hz"), 16.8, 1e-9));
    assert!(close(
        f(&v, "holding_speed_rad_s"),
        2.0 * PI * 1.4 / 1.5,
        1e-9
    ));

    // Absorber precharged to 3 MPa, at 5 MPa.
    let (f_n, zeta) = hand_absorber(3e6, 5e6);
    assert!(close(f(&v, "natural_frequency_hz"), f_n, 1e-9));
    assert!(close(f(&v, "damping_ratio"), zeta, 1e-9));

    // Eq. 31–32 at the precharge state: n·p/(I·V0) = ω_1² and R²·V0/(4·I·n·p) = 1/2.
    let w1 = 2.0 * PI * 16.8;
    let p11 = w1 * w1 * I * V0 / N - P_ATM;
    let p12 = R * R * V0 / (2.0 * N * I) - P_ATM;
    let range = v["precharge_range_pa"].as_array().expect("an array");
    assert_eq!(range.len(), 2);
    assert!(close(range[0].as_f64().unwrap(), p12, 1e-9));
    assert!(close(range[1].as_f64().unwrap(), p11, 1e-9));

    // The honest notes are in the output.
    let notes = v["notes"].as_array().unwrap();
    assert!(notes
        .iter()
        .any(|n| n.as_str().unwrap().contains("not reproduced")));
}

#[test]
fn accumulator_design_follows_the_rig_file_and_the_pressure() {
    // Precharge 4 MPa via a rig file, holding at 8 MPa.
    let mut rig = Rig::nominal();
    rig.absorber.precharge_pa = 4e6;
    let dir = scratch("design-rig");
    let file = dir.join("rig.toml");
    fs::write(&file, rig_file::to_toml(&rig)).unwrap();
    let v = design_json(&["--rig", s(&file), "--pressure", "8e6"]);
    let (f_n, zeta) = hand_absorber(4e6, 8e6);
    assert!(close(f(&v, "natural_frequency_hz"), f_n, 1e-9));
    assert!(close(f(&v, "damping_ratio"), zeta, 1e-9));
    // Leakage 1e-13·(7.5e6 + 8e6 + 7.5e6) = 2.3e-6 m³/s → 2.3/1.5 rev/s × 18.
    assert!(close(
        f(&v, "pulsation_frequency_hz"),
        18.0 * 2.3 / 1.5,
        1e-9
    ));
}

#[test]
fn accumulator_design_writes_json_file_and_prints_the_table() {
    let dir = scratch("design-json");
    let json = dir.join("design.json");
    let o = eha(&["accumulator-design", "--json", s(&json)]);
    assert_eq!(status(&o), 0, "{}", stderr(&o));
    assert!(stdout(&o).contains("precharge range"));
    let v: serde_json::Value = serde_json::from_str(&fs::read_to_string(&json).unwrap()).unwrap();
    for key in [
        "natural_frequency_hz",
        "damping_ratio",
        "pulsation_frequency_hz",
    ] {
        assert!(v[key].is_number(), "{key}");
    }
    assert_eq!(fs::read_dir(&dir).unwrap().count(), 1, "no temporary left");
    // A destination in a folder that does not exist is a bad argument, found before the
    // run (2), naming the folder.
    let o = eha(&[
        "accumulator-design",
        "--json",
        s(&dir.join("no/such/dir/x.json")),
    ]);
    assert_eq!(status(&o), 2, "{}", stderr(&o));
    assert!(stderr(&o).contains("no/such/dir"), "{}", stderr(&o));
}

#[test]
fn simulate_reports_its_real_time_factors_consistently() {
    // Measured from outside, the process's wall clock holds the command's own (rig, loop,
    // log written) and the comparison run's loop, which the command's leaves out; the
    // command's holds its loop's. So loop wall ≤ command wall, and command wall plus the
    // comparison's loop wall ≤ the process's wall as this test times it.
    let dir = scratch("simulate-json");
    let out = dir.join("hold.csv");
    let duration = 0.5;
    let started = std::time::Instant::now();
    let o = eha(&[
        "simulate",
        "--scenario",
        "pressure-hold",
        "--duration",
        "0.5",
        "--out",
        s(&out),
        "--compare-integrator",
        "rk4",
        "--json",
        "-",
    ]);
    let process_s = started.elapsed().as_secs_f64();
    assert_eq!(status(&o), 0, "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("one JSON object");
    let command_s = f(&v, "command_wall_s");
    let loop_s = duration / f(&v, "real_time_factor");
    let compared_s = duration / f(&v["compared"], "real_time_factor");
    assert!(loop_s > 0.0 && loop_s <= command_s, "{v}");
    assert!(command_s + compared_s <= process_s, "{v} in {process_s} s");
    assert!(
        close(
            f(&v, "command_real_time_factor") * command_s,
            duration,
            1e-9
        ),
        "{v}"
    );
    assert_eq!(v["compared"]["integrator"], "rk4", "{v}");
    assert!(fs::metadata(&out).is_ok_and(|m| m.len() > 0));
}
