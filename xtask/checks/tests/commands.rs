//! The checks' executable as `cargo xtask` runs it: an unknown command is a usage error
//! (exit 2), `dbc --node N --out` addresses every message to node N and refuses a node the
//! protocol has not, and `rooms --root` fails on a checkout with a file over the line limit,
//! naming it.
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

/// The messages of a DBC file: (CAN id, name) of each `BO_` line.
fn messages(dbc: &str) -> Vec<(u32, String)> {
    dbc.lines()
        .filter_map(|l| l.strip_prefix("BO_ "))
        .map(|l| {
            let mut words = l.split_whitespace();
            let id = words.next().unwrap().parse().unwrap();
            (id, words.next().unwrap().trim_end_matches(':').to_string())
        })
        .collect()
}

/// Writes the DBC file for `node` with `dbc --node N --out FILE` and reads it back.
fn dbc_for(node: &str, dir: &Path) -> String {
    let file = dir.join(format!("node-{node}.dbc"));
    let out = checks(&["dbc", "--node", node, "--out", file.to_str().unwrap()]);
    assert!(out.status.success(), "{out:?}");
    std::fs::read_to_string(&file).unwrap()
}

#[test]
fn dbc_addresses_each_message_to_the_node() {
    // The protocol's addressing: a message's CAN id is its base plus the node (0..=15), so
    // node 3's file has the same messages as node 1's, each id higher by two.
    let dir = tempfile::tempdir().unwrap();
    let one = messages(&dbc_for("1", dir.path()));
    let three = messages(&dbc_for("3", dir.path()));
    assert!(one.len() >= 10, "{one:?}");
    assert_eq!(one.len(), three.len());
    for ((id1, name1), (id3, name3)) in one.iter().zip(&three) {
        assert_eq!(name1, name3);
        assert_eq!(id3 - id1, 2, "{name1}");
    }
    // A node the protocol has not is refused, and nothing is written.
    let file = dir.path().join("node-16.dbc");
    let out = checks(&["dbc", "--node", "16", "--out", file.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("node 16"));
    assert!(!file.exists());
}

#[test]
fn rooms_names_a_file_over_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let crates = [
        "firmware",
        "plant-model",
        "host-sim",
        "closed-loop",
        "tests",
        "pil",
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
    // An integration test is held to the same length; one at the limit is not named.
    let tests = dir.path().join("host-sim/tests");
    std::fs::create_dir_all(&tests).unwrap();
    std::fs::write(tests.join("long.rs"), "#[test]\nfn t() {}\n".repeat(326)).unwrap();
    std::fs::write(tests.join("at.rs"), "// a line\n".repeat(650)).unwrap();
    let out = checks(&["rooms", "--root", dir.path().to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("  700  host-sim/src/lib.rs"), "{text}");
    assert!(text.contains("  652  host-sim/tests/long.rs"), "{text}");
    assert!(!text.contains("at.rs"), "{text}");
    assert_eq!(text.matches("lib.rs").count(), 1, "{text}");
}
