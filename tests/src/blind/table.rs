//! Scores the diagnosis on a directory of bench logs with a `truth.json` beside them, in
//! the layout of `shared/data/foreign-logs-2/` (an entry per log: `effect` and
//! `parameters`, or for a pair `"effect": "a+b"` and an `effects` list): each log diagnosed
//! against the nominal rig, one Markdown row per log, and the count right.
//!
//! A log is right when `extended.effects` is exactly the hidden set (`none`: empty) and
//! each hidden effect's main parameter, as its cause gives it, is within 25 %
//! ([`Standard::Main`]), the standard of the foreign sets. The time is of the diagnosis
//! alone, logs taken one after another. [`Tally`] counts the right ones by test, and apart
//! for nothing hidden, one effect and pairs.

use super::cut::Cut;
use super::judge::{failures, main_parameter, read_said, truth_of_entry, Named, Said, Standard};
use super::structure::drop_column;
use host_sim::bench_log::{self, Signal};
use host_sim::diagnose::diagnose;
use plant_model::Rig;
use serde_json::Value;
use std::path::Path;
use std::time::Instant;

/// The header of the table [`score_dir`] prints.
pub const HEADER: &str = "| log | test | hidden | named | main parameters: truth → fitted | \
noise ratio p_pa | speed_rad_s | iq_a | time [s] | |\n|---|---|---|---|---|---|---|---|---|---|";

fn label(names: &[&str]) -> String {
    let mut v = names.to_vec();
    v.sort_unstable();
    if v.is_empty() {
        "none".into()
    } else {
        v.join("+")
    }
}

/// Each hidden effect's main parameter, its truth and what the diagnosis fitted.
fn parameter_cells(hidden: &[Named], said: &Said) -> String {
    if hidden.is_empty() {
        return "—".into();
    }
    hidden
        .iter()
        .map(|h| {
            let Some(p) = main_parameter(&h.effect) else {
                return format!("{}: ?", h.effect);
            };
            let t = h.parameters.iter().find(|(k, _)| k == p).map(|(_, v)| *v);
            let f = said.cause(&h.effect).and_then(|c| {
                c.named
                    .parameters
                    .iter()
                    .find(|(k, _)| k == p)
                    .map(|(_, v)| *v)
            });
            match (t, f) {
                (Some(t), Some(f)) => {
                    format!("{p} {t:.3e} → {f:.3e} ({:+.0} %)", 100.0 * (f - t) / t)
                }
                (Some(t), None) => format!("{p} {t:.3e} → —"),
                _ => format!("{p} ?"),
            }
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// Logs right out of logs scored, by test and by how many effects they hide.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tally {
    /// (test name, right, scored), in the order the tests were first met.
    pub by_test: Vec<(String, usize, usize)>,
    /// Right and scored with nothing hidden, one effect hidden, two or more.
    pub by_count: [(usize, usize); 3],
}

impl Tally {
    /// Counts one log of `test` hiding `hidden` effects.
    pub fn add(&mut self, test: &str, hidden: usize, right: bool) {
        let k = match self.by_test.iter().position(|(t, _, _)| t == test) {
            Some(k) => k,
            None => {
                self.by_test.push((test.to_string(), 0, 0));
                self.by_test.len() - 1
            }
        };
        self.by_test[k].1 += usize::from(right);
        self.by_test[k].2 += 1;
        let c = &mut self.by_count[hidden.min(2)];
        c.0 += usize::from(right);
        c.1 += 1;
    }

    /// Right and scored over every log.
    pub fn total(&self) -> (usize, usize) {
        let (r, n) = self
            .by_count
            .iter()
            .fold((0, 0), |(r, n), (a, b)| (r + a, n + b));
        (r, n)
    }

    /// The tally as a Markdown table: one row per test, then nothing hidden, single
    /// effects, pairs and the total.
    pub fn markdown(&self) -> String {
        let mut out = String::from("| logs | right |\n|---|---|\n");
        for (test, r, n) in &self.by_test {
            out += &format!("| test `{test}` | {r} of {n} |\n");
        }
        let labels = ["nothing hidden", "one effect", "pairs"];
        for (label, (r, n)) in labels.iter().zip(self.by_count) {
            out += &format!("| {label} | {r} of {n} |\n");
        }
        let (r, n) = self.total();
        out += &format!("| **all** | **{r} of {n}** |\n");
        out
    }
}

/// One log's row, whether it is right, and its failures; the log is read without the
/// optional columns `drop`.
fn score(
    dir: &Path,
    name: &str,
    entry: &Value,
    drop: &[&str],
    cut: Option<Cut>,
) -> Result<(String, bool, Vec<String>), String> {
    let hidden = truth_of_entry(entry).map_err(|e| format!("truth.json: {name}: {e}"))?;
    let path = dir.join(name);
    let mut log = bench_log::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    for column in drop {
        drop_column(&mut log, column);
    }
    if let Some(c) = cut {
        log = c.apply(&log);
    }
    let start = Instant::now();
    let d = diagnose(&log, &Rig::nominal()).map_err(|e| format!("{name}: {e}"))?;
    let seconds = start.elapsed().as_secs_f64();
    let json = serde_json::to_value(&d).map_err(|e| format!("{name}: to JSON: {e}"))?;
    let said = read_said(&json).map_err(|e| format!("{name}: {e}"))?;
    let wrong = failures(&hidden, &said, Standard::Main);
    let ratio = |part: &str, signal: &str| {
        json[part]["noise_ratio_by_signal"][signal]
            .as_f64()
            .map_or("—".into(), |v| format!("{v:.2}"))
    };
    let noise = ["p_pa", "speed_rad_s", "iq_a"]
        .map(|s| format!("{} → {}", ratio("baseline", s), ratio("extended", s)))
        .join(" | ");
    let hidden_names: Vec<&str> = hidden.iter().map(|h| h.effect.as_str()).collect();
    let named: Vec<&str> = said.effects.iter().map(String::as_str).collect();
    let test = entry.get("test").and_then(Value::as_str).unwrap_or("—");
    let mark = if wrong.is_empty() {
        "right"
    } else {
        "**missed**"
    };
    let row = format!(
        "| {name} | {test} | {} | {} | {} | {noise} | {seconds:.1} | {mark} |",
        label(&hidden_names),
        label(&named),
        parameter_cells(&hidden, &said)
    );
    let mut detail = Vec::new();
    if !wrong.is_empty() {
        detail.push(format!("{name}: {}", wrong.join("; ")));
        for c in &said.causes {
            detail.push(format!("  {}: {}", c.named.effect, c.evidence));
        }
    }
    Ok((row, wrong.is_empty(), detail))
}

/// Scores every log `truth.json` in `dir` lists (in name order): prints the table, then the
/// failures with each cause's evidence line; returns the tally (a log whose entry gives no
/// `test` counts under `—`). Each log is read without the optional columns `drop` (a bench
/// that did not log them); a name that is not an optional column is an error.
pub fn score_dir(dir: &Path, drop: &[&str], cut: Option<Cut>) -> Result<Tally, String> {
    let optional = |c: &str| Signal::from_name(c).is_some_and(|s| !s.is_required());
    if let Some(bad) = drop.iter().find(|c| !optional(c)) {
        return Err(format!(
            "cannot drop `{bad}`: not an optional column of the bench-log contract"
        ));
    }
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
    println!("{HEADER}");
    let (mut tally, mut details) = (Tally::default(), Vec::new());
    for name in &names {
        let entry = &cases[name.as_str()];
        let (row, ok, detail) = score(dir, name, entry, drop, cut)?;
        println!("{row}");
        let hidden = truth_of_entry(entry).map_or(0, |h| h.len());
        tally.add(
            entry.get("test").and_then(Value::as_str).unwrap_or("—"),
            hidden,
            ok,
        );
        details.extend(detail);
    }
    if !details.is_empty() {
        println!(
            "\nmissed, with the causes' evidence:\n{}",
            details.join("\n")
        );
    }
    Ok(tally)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tally_counts_by_test_and_by_number_hidden() {
        let mut t = Tally::default();
        t.add("step", 0, true);
        t.add("stroke", 2, false);
        t.add("step", 1, true);
        t.add("stroke", 1, false);
        assert_eq!(
            t.by_test,
            vec![("step".to_string(), 2, 2), ("stroke".to_string(), 0, 2)]
        );
        assert_eq!(t.by_count, [(1, 1), (1, 2), (0, 1)]);
        assert_eq!(t.total(), (2, 4));
        assert!(t.markdown().contains("| pairs | 0 of 1 |"));
    }
}
