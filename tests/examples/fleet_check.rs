//! Checks what `eha fleet` found on the generated fleet against the generator's truth and
//! prints the comparison: every drifting drive found, its rate within 20 %, its crossing
//! date within a month, no healthy drive flagged. Exit status 1 when one of them fails.
//!
//! ```text
//! cargo run --release -p tests --example fleet_check -- OUT_DIR FLEET_DIR/truth.json
//! ```

use host_sim::timestamp::parse_days;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Tolerances of the issue: rate within 20 %, crossing within a month.
const RATE_TOLERANCE: f64 = 0.20;
const CROSSING_TOLERANCE_DAYS: f64 = 365.2425 / 12.0;

fn fail(why: String) -> ! {
    eprintln!("fleet_check: {why}");
    std::process::exit(2);
}

/// `trends.csv` as (drive, parameter) → column → field.
fn read_trends(path: &PathBuf) -> BTreeMap<(String, String), BTreeMap<String, String>> {
    let mut r =
        csv::Reader::from_path(path).unwrap_or_else(|e| fail(format!("{}: {e}", path.display())));
    let header: Vec<String> = r
        .headers()
        .unwrap_or_else(|e| fail(format!("{}: {e}", path.display())))
        .iter()
        .map(str::to_string)
        .collect();
    let mut out = BTreeMap::new();
    for rec in r.records() {
        let rec = rec.unwrap_or_else(|e| fail(format!("{}: {e}", path.display())));
        let row: BTreeMap<String, String> = header
            .iter()
            .cloned()
            .zip(rec.iter().map(str::to_string))
            .collect();
        out.insert((row["drive"].clone(), row["parameter"].clone()), row);
    }
    out
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [out, truth] = args.as_slice() else {
        fail("usage: fleet_check OUT_DIR TRUTH.json".into())
    };
    let trends = read_trends(&PathBuf::from(out).join("trends.csv"));
    let truth: Value = serde_json::from_str(
        &std::fs::read_to_string(truth).unwrap_or_else(|e| fail(format!("{truth}: {e}"))),
    )
    .unwrap_or_else(|e| fail(format!("{truth}: {e}")));
    let flagged = |drive: &str| -> Vec<String> {
        trends
            .iter()
            .filter(|((d, _), row)| d == drive && row["drifting"] == "yes")
            .map(|((_, p), _)| p.clone())
            .collect()
    };
    let num = |s: &str| s.parse::<f64>().ok();
    println!("| drive | truth | flagged | rate truth [/day] | rate found ± s.e. | rate error | crossing truth | crossing found ± s.e. | crossing error [d] | verdict |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let (mut drifting, mut found, mut rate_ok, mut cross_ok, mut healthy, mut false_alarms) =
        (0, 0, 0, 0, 0, 0);
    let mut worst_rate: f64 = 0.0;
    let mut worst_cross: f64 = 0.0;
    let mut absent = Vec::new();
    for d in truth["drives"].as_array().unwrap_or(&Vec::new()) {
        let drive = d["drive"].as_str().unwrap_or("?");
        // A drive the table has no trend of (a run over part of the fleet) is not judged.
        if !trends.keys().any(|(d, _)| d == drive) {
            absent.push(drive.to_string());
            continue;
        }
        let flags = flagged(drive);
        let Some(param) = d["drifts"].as_str() else {
            healthy += 1;
            let verdict = if flags.is_empty() {
                "ok"
            } else {
                false_alarms += 1;
                "FALSE ALARM"
            };
            println!(
                "| {drive} | healthy | {} | | | | | | | {verdict} |",
                if flags.is_empty() {
                    "—".into()
                } else {
                    flags.join(", ")
                }
            );
            continue;
        };
        drifting += 1;
        let rate = d["rate_per_day"].as_f64().unwrap_or(f64::NAN);
        let cross_truth = d["crossing_day"].as_f64().unwrap_or(f64::NAN);
        let row = trends.get(&(drive.to_string(), param.to_string()));
        let is_found = row.is_some_and(|r| r["drifting"] == "yes");
        let mut verdict = Vec::new();
        let (mut rate_txt, mut err_txt, mut cross_txt, mut cross_err_txt) =
            (String::new(), String::new(), String::new(), String::new());
        if is_found {
            found += 1;
            let r = row.unwrap_or_else(|| unreachable!());
            let est = num(&r["rate_per_day"]).unwrap_or(f64::NAN);
            let se = num(&r["rate_se_per_day"]).unwrap_or(f64::NAN);
            let err = (est - rate) / rate.abs();
            worst_rate = worst_rate.max(err.abs());
            rate_txt = format!("{est:.4e} ± {se:.2e}");
            err_txt = format!("{:+.1} %", 100.0 * err);
            if err.abs() <= RATE_TOLERANCE {
                rate_ok += 1;
            } else {
                verdict.push("rate");
            }
            let date = &r["crossing_date"];
            match parse_days(&format!("{date}T12:00:00Z")) {
                Ok(c) => {
                    let e = c - cross_truth;
                    worst_cross = worst_cross.max(e.abs());
                    cross_txt = format!(
                        "{date} ± {:.0} d",
                        num(&r["crossing_se_days"]).unwrap_or(f64::NAN)
                    );
                    cross_err_txt = format!("{e:+.1}");
                    if e.abs() <= CROSSING_TOLERANCE_DAYS {
                        cross_ok += 1;
                    } else {
                        verdict.push("crossing");
                    }
                }
                Err(_) => verdict.push("no crossing"),
            }
        } else {
            verdict.push("NOT FOUND");
        }
        let others: Vec<String> = flags.into_iter().filter(|p| p != param).collect();
        println!(
            "| {drive} | {param} | {}{} | {rate:.4e} | {rate_txt} | {err_txt} | {} | {cross_txt} | {cross_err_txt} | {} |",
            if is_found { "yes" } else { "no" },
            if others.is_empty() { String::new() } else { format!(" (also {})", others.join(", ")) },
            d["crossing_date"].as_str().unwrap_or(""),
            if verdict.is_empty() { "ok".to_string() } else { verdict.join(", ") }
        );
    }
    println!();
    println!(
        "drifting drives found: {found} of {drifting}; rate within 20 %: {rate_ok} of {drifting} \
         (worst {:.1} %); crossing within a month: {cross_ok} of {drifting} (worst {worst_cross:.1} d); \
         healthy drives flagged: {false_alarms} of {healthy}",
        100.0 * worst_rate
    );
    if !absent.is_empty() {
        println!(
            "not in the table (not judged): {} of {} drives: {}",
            absent.len(),
            absent.len() + drifting + healthy,
            absent.join(", ")
        );
    }
    let pass = absent.is_empty()
        && found == drifting
        && rate_ok == drifting
        && cross_ok == drifting
        && false_alarms == 0;
    println!("{}", if pass { "PASS" } else { "FAIL" });
    if !pass {
        std::process::exit(1);
    }
}
