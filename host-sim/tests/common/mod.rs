//! What the binary's integration tests share: running `eha`, a scratch folder per test, and
//! bench logs rewritten row by row.
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

/// `log` rewritten into `name` beside it: metadata and header kept, each data row `r` (from
/// 0) replaced by what `row` makes of it, or left out where it makes nothing.
pub fn rewritten(
    log: &Path,
    name: &str,
    mut row: impl FnMut(usize, &str) -> Option<String>,
) -> PathBuf {
    let text = fs::read_to_string(log).unwrap();
    let mut out = String::new();
    let mut header_seen = false;
    let mut r = 0;
    for line in text.lines() {
        let kept = if line.starts_with('#') || !header_seen {
            header_seen |= !line.starts_with('#');
            Some(line.to_string())
        } else {
            r += 1;
            row(r - 1, line)
        };
        if let Some(l) = kept {
            out.push_str(&l);
            out.push('\n');
        }
    }
    let path = log.with_file_name(name);
    fs::write(&path, out).unwrap();
    path
}

/// `log` with `column` rewritten row by row (`row index, old text → new text`) into `name`
/// beside it.
pub fn edited(
    log: &Path,
    name: &str,
    column: &str,
    mut f: impl FnMut(usize, &str) -> String,
) -> PathBuf {
    let text = fs::read_to_string(log).unwrap();
    let header = text.lines().find(|l| !l.starts_with('#')).unwrap();
    let col = header.split(',').position(|c| c == column);
    let c = col.unwrap_or_else(|| panic!("{column} in {header}"));
    rewritten(log, name, |r, line| {
        let mut fields: Vec<String> = line.split(',').map(str::to_string).collect();
        fields[c] = f(r, &fields[c]);
        Some(fields.join(","))
    })
}
