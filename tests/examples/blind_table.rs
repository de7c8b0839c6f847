//! The held-out part of the blind suite: writes the generator's logs of `N` seeds from
//! `FROM` into `DIR` with a `truth.json` beside them in the layout of
//! `shared/data/foreign-logs-2/` (per log its `effect` and `parameters`, or for a pair
//! `"effect": "a+b"` and an `effects` list; and its `test`, `log_rate_hz`, `duration_s`,
//! `dropped` columns and `seed`), then scores the diagnosis on them exactly as the foreign
//! sets are scored (`tests::blind::table`: exactly the hidden effects, each main parameter
//! within 25 %), with the count by test, nothing hidden, one effect and pairs.
//!
//! The held-out seeds are [`tests::blind::HELD_OUT_SEEDS`]: the suite never runs them and
//! nothing is tuned on them. Draw a fresh range for each look and say which in the notes:
//!
//! ```text
//! cargo run --release -p tests --example blind_table -- DIR FROM N
//! ```
//!
//! `DIR` must not hold a `truth.json` already (nothing is overwritten). With `--score`
//! only the scoring runs, on logs written before.

use rayon::prelude::*;
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use tests::blind::judge::PARAMETER_TOLERANCE;
use tests::blind::table::score_dir;
use tests::blind::{generate, Hidden, Truth, HELD_OUT_SEEDS};

/// One hidden effect as `truth.json` gives it.
fn entry_of(h: &Hidden) -> Value {
    let parameters: Map<String, Value> = h
        .parameters
        .iter()
        .map(|(k, v)| (k.to_string(), json!(v)))
        .collect();
    json!({ "effect": h.name, "parameters": parameters })
}

/// The `truth.json` entry of one log.
fn truth_entry(seed: u64, t: &Truth) -> Value {
    let mut e = match t.effects.as_slice() {
        [] => json!({ "effect": "none", "parameters": {} }),
        [one] => entry_of(one),
        many => json!({
            "effect": t.label(),
            "effects": many.iter().map(entry_of).collect::<Vec<_>>(),
        }),
    };
    e["test"] = json!(t.test);
    e["log_rate_hz"] = json!(t.log_rate_hz);
    e["duration_s"] = json!(t.duration_s);
    e["dropped"] = json!(t.dropped);
    e["seed"] = json!(seed);
    e
}

/// Generates the seeds `from..from + n` into `dir` and writes its `truth.json`.
fn write_set(dir: &Path, from: u64, n: u64) -> Result<(), String> {
    let truth_path = dir.join("truth.json");
    if truth_path.exists() {
        return Err(format!(
            "{}: exists; use a new directory",
            truth_path.display()
        ));
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let written: Vec<Result<(PathBuf, u64, Truth), String>> = (from..from + n)
        .into_par_iter()
        .map(|seed| generate(seed, dir).map(|(p, t)| (p, seed, t)))
        .collect();
    let mut truth = Map::new();
    for w in written {
        let (path, seed, t) = w?;
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .ok_or("a generated log has no file name")?
            .to_string();
        eprintln!("seed {seed}: {} {} → {name}", t.test, t.label());
        truth.insert(name, truth_entry(seed, &t));
    }
    let text = serde_json::to_string_pretty(&Value::Object(truth)).map_err(|e| e.to_string())?;
    std::fs::write(&truth_path, text).map_err(|e| format!("{}: {e}", truth_path.display()))
}

fn run(args: &[String]) -> Result<(), String> {
    let usage = "usage: blind_table DIR FROM N | blind_table --score DIR";
    match args {
        [flag, dir] if flag == "--score" => score(Path::new(dir)),
        [dir, from, n] => {
            let parse = |x: &str, what: &str| {
                x.parse::<u64>()
                    .map_err(|e| format!("{what} `{x}`: {e}\n{usage}"))
            };
            let (from, n) = (parse(from, "FROM")?, parse(n, "N")?);
            if n == 0 {
                return Err(format!("N must be at least 1\n{usage}"));
            }
            if !HELD_OUT_SEEDS.contains(&from) || !HELD_OUT_SEEDS.contains(&(from + n - 1)) {
                eprintln!(
                    "blind_table: seeds {from}..{} are not all held out ({HELD_OUT_SEEDS:?})",
                    from + n
                );
            }
            write_set(Path::new(dir), from, n)?;
            score(Path::new(dir))
        }
        _ => Err(usage.into()),
    }
}

fn score(dir: &Path) -> Result<(), String> {
    let tally = score_dir(dir, &[], None)?;
    let (right, n) = tally.total();
    println!("\n{}", tally.markdown());
    println!(
        "{right} of {n} right (exactly the hidden effects, each main parameter within {:.0} %)",
        100.0 * PARAMETER_TOLERANCE
    );
    Ok(())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("blind_table: {e}");
            ExitCode::from(2)
        }
    }
}
