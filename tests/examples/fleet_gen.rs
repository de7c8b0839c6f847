//! Generates the demonstration fleet of `eha fleet` (`tests::fleet`): monthly pressure-step
//! logs of drives built within their tolerances, some absorbers losing gas, some pumps
//! wearing, the rest healthy; the truth beside them as `DIR/truth.json`.
//!
//! ```text
//! cargo run --release -p tests --example fleet_gen -- DIR [--drives N] [--logs N]
//!     [--gas-loss N] [--wear N] [--duration S] [--seed N] [--jobs N]
//! ```
//!
//! Defaults: 20 drives × 30 logs of 4 s, 6 losing gas, 4 wearing, seed 1, all cores. A
//! log already in DIR is not written again (the draws do not depend on what exists).

use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Instant;
use tests::fleet::{draw, truth, write_log, FleetPlan};

fn usage(why: &str) -> ! {
    eprintln!(
        "fleet_gen: {why}\nusage: fleet_gen DIR [--drives N] [--logs N] [--gas-loss N] [--wear N] \
         [--duration S] [--seed N] [--jobs N]"
    );
    std::process::exit(2);
}

fn main() {
    let mut args = std::env::args().skip(1);
    let mut plan = FleetPlan::default();
    let mut dir: Option<PathBuf> = None;
    let mut jobs: Option<usize> = None;
    while let Some(a) = args.next() {
        let mut value = |name: &str| -> f64 {
            let v = args
                .next()
                .unwrap_or_else(|| usage(&format!("{name} needs a value")));
            v.parse()
                .unwrap_or_else(|_| usage(&format!("{name} {v}: not a number")))
        };
        match a.as_str() {
            "--drives" => plan.drives = value("--drives") as usize,
            "--logs" => plan.logs = value("--logs") as usize,
            "--gas-loss" => plan.gas_loss = value("--gas-loss") as usize,
            "--wear" => plan.wear = value("--wear") as usize,
            "--duration" => plan.duration_s = value("--duration"),
            "--seed" => plan.seed = value("--seed") as u64,
            "--jobs" => jobs = Some(value("--jobs") as usize),
            _ if dir.is_none() && !a.starts_with("--") => dir = Some(PathBuf::from(a)),
            _ => usage(&format!("unexpected `{a}`")),
        }
    }
    let dir = dir.unwrap_or_else(|| usage("no DIR"));
    if plan.gas_loss + plan.wear > plan.drives || plan.logs < 2 || plan.drives == 0 {
        usage("needs at least 2 logs and no more drifting drives than drives");
    }
    if let Some(j) = jobs {
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(j.max(1))
            .build_global();
    }
    let start = Instant::now();
    let drives = draw(&plan);
    let work: Vec<(usize, usize)> = (0..drives.len())
        .flat_map(|d| (0..plan.logs).map(move |k| (d, k)))
        .collect();
    let failures: Vec<String> = work
        .par_iter()
        .filter_map(|&(d, k)| {
            if drives[d].log_path(&dir, k).exists() {
                return None;
            }
            write_log(&drives[d], k, &plan, &dir)
                .err()
                .map(|e| format!("{} log {k}: {e}", drives[d].name))
        })
        .collect();
    for f in &failures {
        eprintln!("fleet_gen: {f}");
    }
    let text = serde_json::to_string_pretty(&truth(&plan, &drives)).expect("JSON of the truth");
    std::fs::write(dir.join("truth.json"), text + "\n").expect("write truth.json");
    println!(
        "{} logs of {} drives in {} ({:.0} s); truth in {}",
        work.len() - failures.len(),
        drives.len(),
        dir.display(),
        start.elapsed().as_secs_f64(),
        dir.join("truth.json").display()
    );
    if !failures.is_empty() {
        std::process::exit(1);
    }
}
