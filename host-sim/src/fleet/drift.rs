//! Each drive's trends: for every parameter the diagnoses estimate with a standard error
//! (named or not — within its tolerance band the diagnosis names nothing but still reports
//! the released fit), the straight-line trend over the drive's logs ([`super::trend`]),
//! whether it drifts, its value now (at the drive's latest log), its limit
//! ([`super::limits`]) and the date the line crosses it.
//!
//! Angles (`phase_rad`) and whole numbers (`pistons`, `order`) are not trended: a phase
//! wraps and means nothing where its effect is absent, a count does not drift.

use super::limits::Limits;
use super::table::Row;
use super::trend::{fit, Limit, Point, Trend};
use crate::bench_log::format_value;
use crate::timestamp::date;
use std::collections::BTreeMap;
use std::io::{self, Write};

/// One parameter of one drive over time.
#[derive(Clone, Debug, PartialEq)]
pub struct DriveTrend {
    /// The drive.
    pub drive: String,
    /// `effect.parameter`.
    pub parameter: String,
    /// The estimates fitted.
    pub points: Vec<Point>,
    /// The fitted line.
    pub trend: Trend,
    /// Time of the drive's latest log. [day since the Unix epoch]
    pub now_days: f64,
    /// The parameter's limit, if it has one.
    pub limit: Option<Limit>,
    /// When a drifting line crosses the limit, and that time's standard error. [day]
    pub crossing: Option<(f64, f64)>,
}

impl DriveTrend {
    /// Whether the parameter drifts significantly.
    pub fn drifting(&self) -> bool {
        self.trend.drifting()
    }
}

/// Whether a parameter is trended (not an angle or a count).
fn trended(parameter: &str) -> bool {
    let name = parameter.rsplit('.').next().unwrap_or(parameter);
    !(name.ends_with("phase_rad") || name == "pistons" || name == "order")
}

/// The trends of every drive in `rows` (rows without a drive, a time or a diagnosis are
/// left out), by drive then parameter.
pub fn trends(rows: &[Row], limits: &Limits) -> Vec<DriveTrend> {
    let mut by_drive: BTreeMap<&str, BTreeMap<&str, Vec<Point>>> = BTreeMap::new();
    let mut now: BTreeMap<&str, f64> = BTreeMap::new();
    for row in rows {
        let (Some(drive), Some(t), Ok(f)) = (&row.drive, row.t_days, &row.result) else {
            continue;
        };
        let latest = now.entry(drive).or_insert(t);
        *latest = latest.max(t);
        let params = by_drive.entry(drive).or_default();
        for (k, e) in &f.released {
            if !trended(k) {
                continue;
            }
            if let Some(se) = e.se {
                params.entry(k).or_default().push(Point {
                    t_days: t,
                    value: e.value,
                    se,
                });
            }
        }
    }
    let mut out = Vec::new();
    for (drive, params) in by_drive {
        let now_days = now[drive];
        for (parameter, points) in params {
            let Some(trend) = fit(&points) else { continue };
            let limit = limits.of(parameter);
            let crossing = limit
                .filter(|_| trend.drifting())
                .and_then(|l| trend.crossing(l));
            out.push(DriveTrend {
                drive: drive.to_string(),
                parameter: parameter.to_string(),
                points,
                trend,
                now_days,
                limit,
                crossing,
            });
        }
    }
    out
}

/// The columns of `trends.csv`.
pub const HEADER: [&str; 17] = [
    "drive",
    "parameter",
    "logs",
    "first_log",
    "last_log",
    "rate_per_day",
    "rate_se_per_day",
    "t_statistic",
    "p_value",
    "drifting",
    "scatter",
    "value_now",
    "value_now_se",
    "limit",
    "limit_kind",
    "crossing_date",
    "crossing_se_days",
];

fn num(v: f64) -> String {
    let mut s = String::new();
    if v.is_finite() {
        format_value(&mut s, v);
    }
    s
}

/// One trend's fields in [`HEADER`]'s order.
pub fn fields(t: &DriveTrend) -> Vec<String> {
    let first = t
        .points
        .iter()
        .map(|p| p.t_days)
        .fold(f64::INFINITY, f64::min);
    let (now, now_se) = t.trend.value_at(t.now_days);
    let (limit, kind) = match t.limit {
        Some(Limit::Lower(v)) => (num(v), "lower"),
        Some(Limit::Upper(v)) => (num(v), "upper"),
        None => (String::new(), ""),
    };
    let (cross, cross_se) = match t.crossing {
        Some((c, se)) => (date(c).unwrap_or_default(), num(se)),
        None => (String::new(), String::new()),
    };
    vec![
        t.drive.clone(),
        t.parameter.clone(),
        t.trend.points.to_string(),
        date(first).unwrap_or_default(),
        date(t.now_days).unwrap_or_default(),
        num(t.trend.rate_per_day),
        num(t.trend.rate_se_per_day),
        num(t.trend.t_statistic),
        num(t.trend.p_value),
        if t.drifting() { "yes" } else { "no" }.into(),
        num(t.trend.scatter),
        num(now),
        num(now_se),
        limit,
        kind.into(),
        cross,
        cross_se,
    ]
}

/// Writes `trends.csv`.
pub fn write_csv(w: &mut dyn Write, trends: &[DriveTrend]) -> io::Result<()> {
    let mut csv = csv::Writer::from_writer(w);
    csv.write_record(HEADER)?;
    for t in trends {
        csv.write_record(fields(t))?;
    }
    csv.flush()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fleet::table::{Estimate, Findings};
    use crate::timestamp::parse_days;

    fn row(drive: &str, month: u32, precharge: f64, phase: f64) -> Row {
        let at = format!("2026-{month:02}-01T00:00:00Z");
        let mut f = Findings::default();
        f.released.insert(
            "accumulator_precharge.precharge_pa".into(),
            Estimate {
                value: precharge,
                se: Some(1e4),
            },
        );
        f.released.insert(
            "cogging_torque.phase_rad".into(),
            Estimate {
                value: phase,
                se: Some(0.1),
            },
        );
        Row {
            path: format!("{drive}-{month}.csv"),
            drive: Some(drive.into()),
            t_days: Some(parse_days(&at).unwrap()),
            recorded_at: Some(at),
            sha256: None,
            result: Ok(f),
        }
    }

    #[test]
    fn a_losing_absorber_crosses_its_limit_and_a_steady_one_does_not() {
        let limits = Limits {
            precharge_pa: 2.0e6,
            leakage_m3_s_pa: 3e-13,
            working_pressure_pa: 5e6,
        };
        let mut rows = Vec::new();
        for m in 1..=12u32 {
            // D1 loses exactly 1 kPa a day from 3 MPa on 2026-01-01; D2 holds 3 MPa
            // within its 10 kPa errors (alternating ±5 kPa).
            let days = parse_days(&format!("2026-{m:02}-01T00:00:00Z")).unwrap()
                - parse_days("2026-01-01T00:00:00Z").unwrap();
            rows.push(row("D1", m, 3e6 - 1e3 * days, 0.1 * f64::from(m)));
            let wiggle = if m % 2 == 0 { 5e3 } else { -5e3 };
            rows.push(row("D2", m, 3e6 + wiggle, 0.0));
        }
        let t = trends(&rows, &limits);
        // Phases are not trended: one trend per drive.
        assert_eq!(t.len(), 2);
        let d1 = &t[0];
        assert!(d1.drifting());
        assert!((d1.trend.rate_per_day + 1e3).abs() < 1e-6);
        // 1 MPa at 1 kPa/day: 1000 days after 2026-01-01 is 2028-09-27.
        let f = fields(d1);
        assert_eq!(f[15], "2028-09-27");
        assert_eq!(f[4], "2026-12-01");
        assert_eq!(f[13], "2000000");
        assert_eq!(f[14], "lower");
        let d2 = &t[1];
        assert!(!d2.drifting(), "{:?}", d2.trend);
        assert_eq!(d2.crossing, None);
        assert_eq!(fields(d2)[15], "");
    }
}
