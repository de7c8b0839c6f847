//! Scores `eha diagnose` on a directory of bench logs with a `truth.json` beside them, in
//! the layout of `shared/data/foreign-logs/` (gunzipped): each log diagnosed against the
//! nominal rig, the first-ranked cause compared with the hidden effect, and its main
//! parameter with the truth's.
//!
//! A log counts as right when the first cause is the hidden effect and its main parameter
//! lies within 25 % of the truth (`none`: named `none`), the standard of the foreign set.
//! Prints one Markdown row per log and the count; the wall time is of the diagnosis alone,
//! one run, logs taken one after another.
//!
//! ```text
//! cargo run --release -p tests --example foreign_table -- DIR
//! ```

use host_sim::bench_log;
use host_sim::diagnose::diagnose;
use plant_model::Rig;
use serde_json::Value;
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

/// Largest relative error of the main parameter of a log counted right. [1]
const PARAMETER_TOLERANCE: f64 = 0.25;

/// The parameter an effect is judged on: its size (the pistons' count and the phases are
/// not sizes).
fn main_parameter(effect: &str) -> Option<&'static str> {
    Some(match effect {
        "piston_ripple" => "amplitude_ratio",
        "cogging_torque" => "amplitude_nm",
        "flux_harmonics" => "t6_ratio",
        "dead_time" => "dead_time_s",
        "shaft_friction" => "coulomb_nm",
        "cylinder_friction" => "coulomb_n",
        "extra_leakage" => "coefficient_m3_s_pa",
        "entrained_air" => "effective_bulk_modulus_pa",
        "accumulator_precharge" => "precharge_pa",
        "pressure_sensor_lag" => "time_constant_s",
        "current_sensor_offset" => "offset_a",
        _ => return None,
    })
}

/// One log's row and whether it is right.
fn score(dir: &Path, name: &str, truth: &Value) -> Result<(String, bool), String> {
    let path = dir.join(name);
    let hidden = truth["effect"]
        .as_str()
        .ok_or(format!("truth.json: {name}: no \"effect\" string"))?;
    let log = bench_log::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let start = Instant::now();
    let d = diagnose(&log, &Rig::nominal()).map_err(|e| format!("{name}: {e}"))?;
    let seconds = start.elapsed().as_secs_f64();
    let json = serde_json::to_value(&d).map_err(|e| format!("{name}: to JSON: {e}"))?;
    let first = &json["causes"][0];
    let named = first["effect"].as_str().unwrap_or("?");
    let ratio = |part: &str, signal: &str| {
        json[part]["noise_ratio_by_signal"][signal]
            .as_f64()
            .map_or("—".into(), |v| format!("{v:.2}"))
    };
    let noise = ["p_pa", "speed_rad_s", "iq_a"]
        .map(|s| format!("{} → {}", ratio("baseline", s), ratio("extended", s)))
        .join(" | ");
    let (cells, right) = match main_parameter(hidden) {
        None => (
            "— | — | — | —".to_string(),
            hidden == "none" && named == "none",
        ),
        Some(p) => {
            let t = truth["parameters"][p]
                .as_f64()
                .ok_or(format!("truth.json: {name}: no parameter {p}"))?;
            let f = (named == hidden)
                .then(|| first["parameters"][p].as_f64())
                .flatten();
            let err = f.map(|f| (f - t) / t);
            let cells = match (f, err) {
                (Some(f), Some(e)) => format!("{p} | {t:.4e} | {f:.4e} | {:+.0} %", 100.0 * e),
                _ => format!("{p} | {t:.4e} | — | —"),
            };
            (cells, err.is_some_and(|e| e.abs() <= PARAMETER_TOLERANCE))
        }
    };
    let mark = if right { "right" } else { "**missed**" };
    Ok((
        format!("| {name} | {hidden} | {named} | {cells} | {noise} | {seconds:.1} | {mark} |"),
        right,
    ))
}

fn run(dir: &Path) -> Result<(usize, usize), String> {
    let truth_path = dir.join("truth.json");
    let text = std::fs::read_to_string(&truth_path)
        .map_err(|e| format!("{}: {e}", truth_path.display()))?;
    let truth: Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", truth_path.display()))?;
    let cases = truth
        .as_object()
        .ok_or(format!("{}: not a JSON object", truth_path.display()))?;
    let mut names: Vec<&String> = cases.keys().collect();
    names.sort();
    for name in &names {
        if !dir.join(name).is_file() {
            return Err(format!(
                "{}: missing (gunzip -k the .csv.gz first)",
                dir.join(name).display()
            ));
        }
    }
    println!(
        "| log | hidden | named | parameter | truth | fitted | error | noise ratio p_pa \
         | speed_rad_s | iq_a | time [s] | |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut right = 0;
    for name in &names {
        let (row, ok) = score(dir, name, &cases[name.as_str()])?;
        println!("{row}");
        right += usize::from(ok);
    }
    Ok((right, names.len()))
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [dir] = args.as_slice() else {
        eprintln!("usage: foreign_table DIR (bench logs and truth.json)");
        return ExitCode::from(2);
    };
    match run(Path::new(dir)) {
        Ok((right, n)) => {
            println!(
                "\n{right} of {n} named right (main parameter within {:.0} %)",
                100.0 * PARAMETER_TOLERANCE
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("foreign_table: {e}");
            ExitCode::from(2)
        }
    }
}
