//! The trend figure of each drifting drive: one panel per drifting parameter, the logs'
//! estimates with their standard errors, the fitted line and its ±2σ band carried on to
//! the limit, and the predicted crossing with its ±2σ interval
//! ([`crate::plots::trend`]). Named `<drive>.svg` (and `.png`), the drive's name kept to
//! letters, digits, `-`, `_` and `.`.

use super::drift::DriveTrend;
use crate::output::{CliError, StagedFolder};
use crate::plots::trend::{trend_chart, TrendPanel};
use crate::timestamp::date;
use std::collections::BTreeMap;

/// Days per (Gregorian mean) year. [day]
const DAYS_PER_YEAR: f64 = 365.2425;

/// The longest the line is drawn beyond the latest log. [day]
const HORIZON_DAYS: f64 = 10.0 * DAYS_PER_YEAR;

/// Points along a drawn line.
const LINE_POINTS: usize = 100;

/// Decimal year of a day since the Unix epoch.
fn year(days: f64) -> f64 {
    1970.0 + days / DAYS_PER_YEAR
}

/// The file stem of a drive's figure: its name with anything but letters, digits, `-`,
/// `_` and `.` replaced by `_` (and a leading `.` too), so that it is one plain file name.
pub fn file_stem(drive: &str) -> String {
    let mut s: String = drive
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() || s.starts_with('.') {
        s.insert(0, '_');
    }
    s
}

/// A power of 1000 that brings `magnitude` into [1, 1000), and its label suffix.
fn scale(magnitude: f64) -> (f64, String) {
    if !(magnitude.is_finite() && magnitude > 0.0) {
        return (1.0, String::new());
    }
    let exp = ((magnitude.log10() / 3.0).floor() * 3.0) as i32;
    if exp == 0 {
        (1.0, String::new())
    } else {
        (10f64.powi(exp), format!(" [×1e{exp}]"))
    }
}

/// One parameter's panel.
fn panel(t: &DriveTrend) -> TrendPanel {
    let magnitude = t.points.iter().map(|p| p.value.abs()).fold(0.0, f64::max);
    let (k, suffix) = scale(magnitude);
    let first = t
        .points
        .iter()
        .map(|p| p.t_days)
        .fold(f64::INFINITY, f64::min);
    let mut end = t.now_days;
    if let Some((c, se)) = t.crossing {
        end = end.max(c + 2.0 * se);
    }
    let end = end.min(t.now_days + HORIZON_DAYS);
    let line = (0..=LINE_POINTS)
        .map(|i| {
            let d = first + (end - first) * i as f64 / LINE_POINTS as f64;
            let (v, se) = t.trend.value_at(d);
            (year(d), v / k, (v - 2.0 * se) / k, (v + 2.0 * se) / k)
        })
        .collect();
    let crossing = t.crossing.map(|(c, se)| {
        let label = format!(
            "crosses the limit {} ± {:.0} d (bar: ±2σ)",
            date(c).unwrap_or_default(),
            se
        );
        (
            (
                year(c),
                year(c - 2.0 * se).max(year(first)),
                year(c + 2.0 * se).min(year(end)),
            ),
            label,
        )
    });
    TrendPanel {
        y_label: format!("{}{suffix}", t.parameter),
        points: t
            .points
            .iter()
            .map(|p| (year(p.t_days), p.value / k, p.se / k))
            .collect(),
        line,
        limit: t.limit.map(|l| l.value() / k),
        crossing,
    }
}

/// The files the figures' folder holds: each drive's SVG and the PNG beside it.
pub const FILES: &[&str] = &["*.svg", "*.png"];

/// Writes the figure of every drive with a drifting parameter into the staged folder `d`;
/// returns the names of the SVG files written.
pub fn write(d: &StagedFolder, trends: &[DriveTrend]) -> Result<Vec<String>, CliError> {
    let mut by_drive: BTreeMap<&str, Vec<&DriveTrend>> = BTreeMap::new();
    for t in trends.iter().filter(|t| t.drifting()) {
        by_drive.entry(&t.drive).or_default().push(t);
    }
    let mut used: std::collections::BTreeSet<String> = std::collections::BTreeSet::new();
    let mut written = Vec::new();
    for (drive, ts) in by_drive {
        // Two drives whose names differ only in replaced characters get numbered files.
        let base = file_stem(drive);
        let mut stem = base.clone();
        let mut n = 1;
        while !used.insert(stem.clone()) {
            n += 1;
            stem = format!("{base}-{n}");
        }
        let name = format!("{stem}.svg");
        let panels: Vec<TrendPanel> = ts.iter().map(|t| panel(t)).collect();
        trend_chart(
            &name,
            &format!("drive {drive}: drifting parameters"),
            &panels,
        )
        .map_err(CliError::Failed)?
        .write_into(d, &name)?;
        written.push(name);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drive_names_become_plain_file_names() {
        assert_eq!(file_stem("D-07_a.b"), "D-07_a.b");
        assert_eq!(file_stem("press 7/left"), "press_7_left");
        assert_eq!(file_stem("../x"), "_.._x");
        assert_eq!(file_stem(""), "_");
    }

    #[test]
    fn scales_are_powers_of_a_thousand() {
        assert_eq!(scale(3e6), (1e6, " [×1e6]".to_string()));
        assert_eq!(scale(2.5e-13).1, " [×1e-15]");
        assert_eq!(scale(12.0), (1.0, String::new()));
    }
}
