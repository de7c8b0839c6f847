//! Where the residual the extended model leaves lives: for each log, per predicted signal,
//! the residual's RMS over the log's noise RMS on the validation segment (the contract's
//! `noise_ratio_by_signal`), and the same split between the rows where the drive is in a
//! transient (within [`GUARD_S`] of a speed reversal, of a jump of the speed reference, or
//! of the q current leaving its reference by more than [`FOLLOWING_A`]: the current loop
//! at its voltage or current limit) and the rest; and the share of the residual's energy
//! in those transient rows against their share of the time. The ratios are read on the
//! rows the analysis keeps of its traces (every k-th row, a few thousand a log).
//!
//! ```text
//! cargo run --release -p host-sim --example residual_budget -- LOG.csv…
//! ```

use host_sim::bench_log;
use host_sim::diagnose::analysis::analyse;
use plant_model::Rig;
use std::path::Path;

/// Time either side of a transient's rows counted with it. [s]
const GUARD_S: f64 = 0.05;

/// q current off its reference beyond which the current loop is not following. [A]
const FOLLOWING_A: f64 = 0.5;

/// Speed-reference change per row that counts as a jump. [rad/s]
const REFERENCE_JUMP_RAD_S: f64 = 2.0;

fn main() {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        eprintln!("usage: residual_budget LOG.csv…");
        std::process::exit(2);
    }
    println!("log | signal | ratio | ratio steady | ratio transient | transient time % | transient energy %");
    for p in &paths {
        let log = match bench_log::read(Path::new(p)) {
            Ok(l) => l,
            Err(e) => {
                eprintln!("{p}: {e}");
                std::process::exit(2);
            }
        };
        let a = match analyse(&log, &Rig::nominal()) {
            Ok(a) => a,
            Err(e) => {
                eprintln!("{p}: {e}");
                continue;
            }
        };
        let [v0, v1] = a.diagnosis.validation_segment_s;
        let rows: Vec<usize> = (0..a.t_s.len())
            .filter(|&k| a.t_s[k] >= v0 && a.t_s[k] <= v1)
            .collect();
        // The analysis keeps every k-th row of its traces: the transients are found on the
        // whole log and read at those rows' times.
        let whole = transient_rows(&log, &log.t_s);
        let transient: Vec<bool> = a
            .t_s
            .iter()
            .map(|t| whole[log.t_s.partition_point(|x| x < t).min(whole.len() - 1)])
            .collect();
        let name = Path::new(p)
            .file_name()
            .map_or(p.clone(), |n| n.to_string_lossy().into());
        for (signal, ratio) in &a.diagnosis.extended.noise_ratio_by_signal {
            let (Some(y), Some(yh)) = (
                a.measured.get(signal.as_str()),
                a.extended.get(signal.as_str()),
            ) else {
                continue;
            };
            let sq = |k: &usize| (y[*k] - yh[*k]).powi(2);
            let all: f64 = rows.iter().map(sq).sum();
            let (tr, st): (Vec<usize>, Vec<usize>) = rows.iter().partition(|&&k| transient[k]);
            let rms =
                |set: &[usize]| (set.iter().map(sq).sum::<f64>() / set.len().max(1) as f64).sqrt();
            let sigma = rms(&rows) / ratio.max(f64::MIN_POSITIVE);
            let e_tr: f64 = tr.iter().map(sq).sum();
            println!(
                "{name} | {signal} | {ratio:.2} | {:.2} | {:.2} | {:.1} | {:.1}",
                rms(&st) / sigma,
                rms(&tr) / sigma,
                100.0 * tr.len() as f64 / rows.len().max(1) as f64,
                100.0 * e_tr / all.max(f64::MIN_POSITIVE),
            );
        }
    }
}

/// Rows within [`GUARD_S`] of a speed reversal, a jump of the speed reference, or the q
/// current off its reference by more than [`FOLLOWING_A`].
fn transient_rows(log: &bench_log::BenchLog, t: &[f64]) -> Vec<bool> {
    let n = t.len();
    let mut mark = vec![false; n];
    for k in 1..n {
        let reversal = log.speed_rad_s[k].signum() != log.speed_rad_s[k - 1].signum()
            && log.speed_rad_s[k].abs().max(log.speed_rad_s[k - 1].abs()) > 0.5;
        let jump = log
            .speed_ref_rad_s
            .as_ref()
            .is_some_and(|r| (r[k] - r[k - 1]).abs() > REFERENCE_JUMP_RAD_S);
        let off = log
            .iq_ref_a
            .as_ref()
            .is_some_and(|r| (r[k] - log.iq_a[k]).abs() > FOLLOWING_A);
        mark[k] = reversal || jump || off;
    }
    let period = (t[n - 1] - t[0]) / (n - 1).max(1) as f64;
    let guard = (GUARD_S / period.max(f64::MIN_POSITIVE)).round() as usize;
    let mut out = vec![false; n];
    let mut last: Option<usize> = None;
    for k in 0..n {
        if mark[k] {
            last = Some(k);
        }
        if last.is_some_and(|l| k - l <= guard) {
            out[k] = true;
        }
    }
    let mut next: Option<usize> = None;
    for k in (0..n).rev() {
        if mark[k] {
            next = Some(k);
        }
        if next.is_some_and(|l| l - k <= guard) {
            out[k] = true;
        }
    }
    out
}
