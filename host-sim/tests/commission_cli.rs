//! `eha commission` as scripts call it (`shared/contracts/eha-cli.md`): the contract's JSON
//! fields, exit status 0 on success and 2 for a bad `--bandwidth`, nothing written then.

use std::fs;
use std::path::Path;
use std::process::{Command, Output};

fn eha(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_eha"))
        .args(args)
        .output()
        .expect("the eha binary runs")
}

fn scratch(name: &str) -> std::path::PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("commission-{name}"));
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn json_has_the_contract_fields_and_table_1_gains() {
    let dir = scratch("json");
    let json = dir.join("c.json");
    let o = eha(&["commission", "--json", json.to_str().unwrap()]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&fs::read(&json).unwrap()).unwrap();
    for side in ["identified", "true"] {
        for f in ["R_s", "L_d", "L_q", "psi_f", "encoder_offset_rad"] {
            assert!(v[side][f].is_f64(), "{side}.{f} missing: {v}");
        }
    }
    // The paper's Table 1 at the default 1100 rad/s, within 3 %.
    for (f, paper) in [("kp_d", 5.775), ("kp_q", 13.2), ("ki", 1053.8)] {
        let got = v["current_gains"][f].as_f64().expect(f);
        assert!(
            (got / paper - 1.0).abs() < 0.03,
            "{f} = {got}, Table 1 {paper}"
        );
    }
    let d = v["duration_s"].as_f64().expect("duration_s");
    assert!(d > 0.0 && d < 20.0, "duration_s {d}");
    // The table names every quantity on standard output.
    let table = String::from_utf8_lossy(&o.stdout);
    for q in ["R_s", "L_d", "L_q", "psi_f", "encoder offset"] {
        assert!(table.contains(q), "{q} missing from\n{table}");
    }
}

#[test]
fn bandwidth_scales_the_gains() {
    // Kp = L·ω_c, Ki = R_s·ω_c: half the bandwidth, half the gains.
    let o = eha(&["commission", "--bandwidth", "550", "--json", "-"]);
    assert_eq!(o.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for (f, paper) in [("kp_d", 5.775), ("kp_q", 13.2), ("ki", 1053.8)] {
        let got = v["current_gains"][f].as_f64().expect(f);
        assert!((2.0 * got / paper - 1.0).abs() < 0.03, "{f} = {got}");
    }
}

#[test]
fn a_bad_bandwidth_is_exit_2_and_writes_nothing() {
    let dir = scratch("bad");
    let json = dir.join("c.json");
    for bw in ["-5", "abc", "0", "1e6"] {
        let o = eha(&[
            "commission",
            "--bandwidth",
            bw,
            "--json",
            json.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "--bandwidth {bw}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(bw) || err.contains("bandwidth"), "{err}");
        assert!(!json.exists(), "--bandwidth {bw} wrote output");
    }
}
