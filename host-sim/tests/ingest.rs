//! `eha ingest` through the binary: a decoder's output with interleaved logs becomes a
//! bench log that reads back with the frames' values; a malformed telemetry line exits 2
//! naming file and line, and no output file appears.

mod common;

use common::eha;
use firmware::{Mode, TelemetryFrame};
use host_sim::bench_log;
use std::fs;
use std::path::PathBuf;

fn scratch(name: &str) -> PathBuf {
    common::scratch("ingest", name)
}

/// A frame whose values are exact in f32 and differ per sample.
fn frame(i: usize) -> TelemetryFrame {
    TelemetryFrame {
        t_s: i as f64 * 1e-3,
        p_ref_pa: 5e6,
        p_pa: 5e6 + 16.0 * i as f32,
        speed_rad_s: 6.0 + 0.25 * i as f32,
        iq_a: 0.5,
        id_a: -0.125,
        theta_m_rad: 0.5,
        speed_ref_rad_s: 6.0,
        iq_ref_a: 0.5,
        ud_v: 1.0,
        uq_v: 2.0,
        udc_v: 280.0,
        mode: Mode::Pressure,
        fault: None,
        command_status: 0,
    }
}

/// 120 frames as defmt-print shows them, each with a location line, and a boot message.
fn decoder_output() -> String {
    let mut s = String::from("0.000000 INFO  EHA drive up\n");
    for i in 0..120 {
        let mut line = String::new();
        frame(i).write_line(&mut line).unwrap();
        s.push_str(&format!("{:.6} INFO  {line}\n", i as f64 * 1e-3));
        s.push_str("└─ firmware::telemetry @ firmware/src/telemetry.rs:140\n");
    }
    s
}

#[test]
fn decoder_output_becomes_a_bench_log_with_the_frames_values() {
    let d = scratch("good");
    let (input, out) = (d.join("run.log"), d.join("run.csv"));
    fs::write(&input, decoder_output()).unwrap();
    let o = eha(&[
        "ingest",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("120 telemetry lines"), "{err}");
    assert!(err.contains("121 other lines skipped"), "{err}");
    let log = bench_log::read(&out).unwrap();
    assert_eq!(log.len(), 120);
    assert_eq!(log.meta("source"), Some("firmware telemetry"));
    for i in [0, 37, 119] {
        let f = frame(i);
        assert_eq!(log.t_s[i], f.t_s);
        assert_eq!(log.p_pa[i], f.p_pa as f64);
        assert_eq!(log.speed_rad_s[i], f.speed_rad_s as f64);
        assert_eq!(log.id_a[i], -0.125);
    }
}

#[test]
fn a_malformed_telemetry_line_exits_2_naming_file_and_line_and_writes_nothing() {
    let d = scratch("bad");
    let (input, out) = (d.join("run.log"), d.join("run.csv"));
    // Line 1 is the boot message, frame i on line 2 + 2i: frame 10 is on line 22.
    let text = decoder_output().replacen(" iq_a=0.5 ", " iq_a=0.5.1 ", 11);
    let text = text.replacen(" iq_a=0.5.1 ", " iq_a=0.5 ", 10);
    fs::write(&input, text).unwrap();
    let o = eha(&[
        "ingest",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("1 malformed telemetry line"), "{err}");
    assert!(
        err.contains(&format!("{}:22: field `iq_a`", input.display())),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn a_missing_input_exits_2_naming_it() {
    let d = scratch("missing");
    let o = eha(&[
        "ingest",
        d.join("nope.log").to_str().unwrap(),
        "--out",
        d.join("x.csv").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("nope.log"));
}
