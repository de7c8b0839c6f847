//! The checks' executable as `cargo xtask` runs it: an unknown command is a usage error
//! (exit 2), `dbc --out` writes what the checked-in `eha.dbc` holds for the default node,
//! and `rooms --root` fails on a checkout with a file over the line limit, naming it.
//!
//! Cargo builds the executable for these tests, so the workspace's linted test build makes
//! it with the features the whole workspace resolves (what `cargo xtask test` runs).

use std::path::Path;
use std::process::{Command, Output};

fn checks(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xtask-checks"))
        .args(args)
        .output()
        .expect("the checks' executable starts")
}

#[test]
fn an_unknown_command_is_a_usage_error() {
    let out = checks(&["lint"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).starts_with("usage: xtask-checks"));
}

#[test]
fn dbc_writes_the_checked_in_file() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("eha.dbc");
    let out = checks(&["dbc", "--out", file.to_str().unwrap()]);
    assert!(out.status.success(), "{out:?}");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let checked_in = std::fs::read_to_string(root.join("eha.dbc")).unwrap();
    assert_eq!(std::fs::read_to_string(&file).unwrap(), checked_in);
}

#[test]
fn rooms_names_a_file_over_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let crates = [
        "firmware",
        "plant-model",
        "host-sim",
        "closed-loop",
        "xtask",
        "xtask/checks",
    ];
    for krate in crates {
        let src = dir.path().join(krate).join("src");
        std::fs::create_dir_all(&src).unwrap();
        std::fs::write(src.join("lib.rs"), "pub fn f() {}\n").unwrap();
    }
    let long: String = (0..700)
        .map(|i| format!("pub const C{i}: u32 = {i};\n"))
        .collect();
    std::fs::write(dir.path().join("host-sim/src/lib.rs"), long).unwrap();
    let out = checks(&["rooms", "--root", dir.path().to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("  700  host-sim/src/lib.rs"), "{text}");
    assert_eq!(text.matches("lib.rs").count(), 1, "{text}");
}
