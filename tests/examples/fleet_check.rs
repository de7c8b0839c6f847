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

/// `trends.csv`'s rows: (drive, parameter) → column → field.
type Trends = BTreeMap<(String, String), BTreeMap<String, String>>;

/// Says why on standard error and exits with status 2 (bad arguments or unreadable input).
fn fail(why: String) -> ! {
    eprintln!("fleet_check: {why}");
    std::process::exit(2);
}

/// `trends.csv` as (drive, parameter) → column → field.
fn read_trends(path: &PathBuf) -> Trends {
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

/// The generator's `truth.json` at `path`, parsed.
fn read_truth(path: &str) -> Value {
    serde_json::from_str(
        &std::fs::read_to_string(path).unwrap_or_else(|e| fail(format!("{path}: {e}"))),
    )
    .unwrap_or_else(|e| fail(format!("{path}: {e}")))
}

/// The parameters `trends` flags as drifting on `drive`.
fn flagged(trends: &Trends, drive: &str) -> Vec<String> {
    trends
        .iter()
        .filter(|((d, _), row)| d == drive && row["drifting"] == "yes")
        .map(|((_, p), _)| p.clone())
        .collect()
}

/// A field of `trends.csv` as a number (`None` when empty or not one).
fn num(s: &str) -> Option<f64> {
    s.parse::<f64>().ok()
}

/// What the drives judged so far add up to.
#[derive(Default)]
struct Tally {
    /// Drives the truth says drift, and of them: found drifting, rate and crossing within
    /// tolerance.
    drifting: usize,
    found: usize,
    rate_ok: usize,
    cross_ok: usize,
    /// Healthy drives, and of them those flagged anyway.
    healthy: usize,
    false_alarms: usize,
    /// The largest relative rate error and crossing error [d] of the found drives.
    worst_rate: f64,
    worst_cross: f64,
    /// Drives of the truth with no trend in the table (not judged).
    absent: Vec<String>,
}

/// Prints the comparison table's header.
fn print_header() {
    println!("| drive | truth | flagged | rate truth [/day] | rate found ± s.e. | rate error | crossing truth | crossing found ± s.e. | crossing error [d] | verdict |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
}

/// Judges one drive of the truth (`d`) against `trends` and prints its row; a drive the
/// table has no trend of (a run over part of the fleet) is only noted as absent.
fn judge_drive(d: &Value, trends: &Trends, tally: &mut Tally) {
    let drive = d["drive"].as_str().unwrap_or("?");
    if !trends.keys().any(|(d, _)| d == drive) {
        tally.absent.push(drive.to_string());
        return;
    }
    let flags = flagged(trends, drive);
    match d["drifts"].as_str() {
        None => judge_healthy(drive, &flags, tally),
        Some(param) => judge_drifting(d, drive, param, flags, trends, tally),
    }
}

/// A healthy drive's row: ok when nothing is flagged, a false alarm otherwise.
fn judge_healthy(drive: &str, flags: &[String], tally: &mut Tally) {
    tally.healthy += 1;
    let verdict = if flags.is_empty() {
        "ok"
    } else {
        tally.false_alarms += 1;
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
}

/// A drifting drive's row: its drifting parameter `param` found or not, and when found its
/// rate and crossing against the truth `d`; `flags` are every parameter flagged on it.
fn judge_drifting(
    d: &Value,
    drive: &str,
    param: &str,
    flags: Vec<String>,
    trends: &Trends,
    tally: &mut Tally,
) {
    tally.drifting += 1;
    let rate = d["rate_per_day"].as_f64().unwrap_or(f64::NAN);
    let cross_truth = d["crossing_day"].as_f64().unwrap_or(f64::NAN);
    let row = trends.get(&(drive.to_string(), param.to_string()));
    let is_found = row.is_some_and(|r| r["drifting"] == "yes");
    let mut verdict = Vec::new();
    let (mut rate_txt, mut err_txt, mut cross_txt, mut cross_err_txt) =
        (String::new(), String::new(), String::new(), String::new());
    if is_found {
        tally.found += 1;
        let r = row.unwrap_or_else(|| unreachable!());
        (rate_txt, err_txt) = judge_rate(r, rate, tally, &mut verdict);
        (cross_txt, cross_err_txt) = judge_crossing(r, cross_truth, tally, &mut verdict);
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

/// The found trend `r`'s rate against the true `rate`: its text (estimate ± s.e.) and
/// relative error's, counted in `tally`, "rate" added to `verdict` when out of tolerance.
fn judge_rate(
    r: &BTreeMap<String, String>,
    rate: f64,
    tally: &mut Tally,
    verdict: &mut Vec<&str>,
) -> (String, String) {
    let est = num(&r["rate_per_day"]).unwrap_or(f64::NAN);
    let se = num(&r["rate_se_per_day"]).unwrap_or(f64::NAN);
    let err = (est - rate) / rate.abs();
    tally.worst_rate = tally.worst_rate.max(err.abs());
    if err.abs() <= RATE_TOLERANCE {
        tally.rate_ok += 1;
    } else {
        verdict.push("rate");
    }
    (
        format!("{est:.4e} ± {se:.2e}"),
        format!("{:+.1} %", 100.0 * err),
    )
}

/// The found trend `r`'s crossing date against the true crossing day `cross_truth`: its
/// text (date ± s.e.) and error's [d], counted in `tally`, "crossing" added to `verdict`
/// when out of tolerance, "no crossing" (and empty texts) when the date does not parse.
fn judge_crossing(
    r: &BTreeMap<String, String>,
    cross_truth: f64,
    tally: &mut Tally,
    verdict: &mut Vec<&str>,
) -> (String, String) {
    let date = &r["crossing_date"];
    let Ok(c) = parse_days(&format!("{date}T12:00:00Z")) else {
        verdict.push("no crossing");
        return (String::new(), String::new());
    };
    let e = c - cross_truth;
    tally.worst_cross = tally.worst_cross.max(e.abs());
    if e.abs() <= CROSSING_TOLERANCE_DAYS {
        tally.cross_ok += 1;
    } else {
        verdict.push("crossing");
    }
    (
        format!(
            "{date} ± {:.0} d",
            num(&r["crossing_se_days"]).unwrap_or(f64::NAN)
        ),
        format!("{e:+.1}"),
    )
}

/// Prints the summary lines after the table and the verdict (PASS or FAIL); returns
/// whether every drive of the truth was judged and passed.
fn report(tally: &Tally) -> bool {
    let Tally {
        drifting,
        found,
        rate_ok,
        cross_ok,
        healthy,
        false_alarms,
        worst_rate,
        worst_cross,
        ref absent,
    } = *tally;
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
    pass
}

/// Reads `OUT_DIR/trends.csv` and the truth, judges every drive of the truth, prints the
/// summary; exits 1 on FAIL, 2 on bad arguments or input.
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [out, truth] = args.as_slice() else {
        fail("usage: fleet_check OUT_DIR TRUTH.json".into())
    };
    let trends = read_trends(&PathBuf::from(out).join("trends.csv"));
    let truth = read_truth(truth);
    print_header();
    let mut tally = Tally::default();
    for d in truth["drives"].as_array().unwrap_or(&Vec::new()) {
        judge_drive(d, &trends, &mut tally);
    }
    if !report(&tally) {
        std::process::exit(1);
    }
}
