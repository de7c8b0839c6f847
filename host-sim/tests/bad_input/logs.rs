//! Logs the commands cannot use: ones the diagnosis cannot replay, a dropped sample, garbled
//! text, a time axis no sampler makes, a header without end, a table's trailer, and a step the
//! loop did not follow, each refused with the true reason.

use super::*;

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
    let o = eha(&short_hold(&out, &["--effects", "cogging_torque"]));
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
