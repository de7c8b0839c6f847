//! What the binary's integration tests share: running `eha`, a scratch folder per test.
// Each test crate compiles this module and uses part of it.
#![allow(dead_code)]

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the `eha` binary with `args`.
pub fn eha(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_eha"))
        .args(args)
        .output()
        .expect("the eha binary runs")
}

/// A fresh, empty folder `<prefix>-<name>` under the target's test scratch space.
pub fn scratch(prefix: &str, name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("{prefix}-{name}"));
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}

/// A path as the `&str` an argument list takes.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `eha simulate`'s pressure holding of `seconds` written to `dir/name`, with the further
/// arguments `extra` (it must succeed).
pub fn simulated_hold(dir: &Path, name: &str, seconds: &str, extra: &[&str]) -> PathBuf {
    let log = dir.join(name);
    let mut args = vec![
        "simulate",
        "--scenario",
        "pressure-hold",
        "--duration",
        seconds,
        "--out",
        s(&log),
    ];
    args.extend_from_slice(extra);
    let o = eha(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    log
}
