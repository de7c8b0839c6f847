//! Every `eha` subcommand under bad input, one test per class of case: bad paths, bad
//! numbers, unknown names, extreme rig values, logs the diagnosis or tuning cannot use,
//! garbled files, and interruption. Each must exit 2 (130 when interrupted) with a message
//! naming what and where, before any work, leaving nothing behind, never panicking.

#[path = "../common/mod.rs"]
mod common;

mod arguments;
mod logs;
mod outputs;

use common::{edited, eha, s};
use host_sim::rig_file;
use plant_model::Rig;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

fn status(o: &Output) -> i32 {
    o.status.code().expect("exited, not killed by a signal")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn scratch(name: &str) -> PathBuf {
    common::scratch("bad-input", name)
}

/// Files and folders in `dir`, hidden ones included, sorted.
fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The arguments of `eha simulate`'s 0.1 s pressure holding with its log at `sim`, followed
/// by `more`.
fn short_hold<'a>(sim: &'a Path, more: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "simulate",
        "--scenario",
        "pressure-hold",
        "--duration",
        "0.1",
        "--out",
        s(sim),
    ];
    args.extend_from_slice(more);
    args
}

/// Runs `args`, expecting exit 2 with every one of `named` in the message, no panic.
fn refused(args: &[&str], named: &[&str]) -> String {
    let o = eha(args);
    let err = stderr(&o);
    assert_eq!(status(&o), 2, "{args:?}: {err}");
    for n in named {
        assert!(err.contains(n), "{args:?} should name `{n}`: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.lines().count() < 20, "{args:?}: a short message: {err}");
    err
}

/// A valid bench log of a pressure hold (simulated, 2 kHz, 1 s).
fn hold_log(dir: &Path) -> PathBuf {
    hold_log_of(dir, "hold.csv", "1")
}

/// A pressure-hold log of `seconds` written to `dir/name`.
fn hold_log_of(dir: &Path, name: &str, seconds: &str) -> PathBuf {
    common::simulated_hold(dir, name, seconds, &[])
}
