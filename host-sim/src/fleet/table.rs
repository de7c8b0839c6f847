//! The fleet table: one row per log with its drive, time, status, the effects the diagnosis
//! names and their parameters with standard errors, the gain in fit points and the noise
//! ratios — and, for the trends, every tested effect's released estimate.
//!
//! The CSV has one fixed set of columns, the catalogue's (`shared/contracts/effects.md`),
//! whatever the logs hold, so that the tables of shards concatenate into the whole table;
//! a parameter is filled where its effect is named in that log. The JSON carries the same
//! rows.

use crate::bench_log::format_value;
use serde_json::{json, Map, Value};
use std::collections::BTreeMap;
use std::io::{self, Write};

/// Every effect of the catalogue with its parameters, as the table's columns.
pub const PARAMETERS: [(&str, &[&str]); 11] = [
    (
        "piston_ripple",
        &["pistons", "amplitude_ratio", "phase_rad"],
    ),
    ("cogging_torque", &["amplitude_nm", "order", "phase_rad"]),
    ("flux_harmonics", &["t6_ratio", "phase_rad"]),
    ("dead_time", &["dead_time_s"]),
    ("shaft_friction", &["coulomb_nm", "static_nm"]),
    ("cylinder_friction", &["coulomb_n", "static_n"]),
    ("extra_leakage", &["coefficient_m3_s_pa"]),
    ("entrained_air", &["effective_bulk_modulus_pa"]),
    ("accumulator_precharge", &["precharge_pa"]),
    ("pressure_sensor_lag", &["time_constant_s"]),
    ("current_sensor_offset", &["offset_a"]),
];

/// The signals whose noise ratios the table carries (those the diagnosis predicts).
pub const SIGNALS: [&str; 5] = ["p_pa", "speed_rad_s", "iq_a", "ud_v", "uq_v"];

/// A parameter estimate with its standard error (`None`: the log does not bound it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// The value. [SI]
    pub value: f64,
    /// Its standard error. [SI]
    pub se: Option<f64>,
}

/// What the diagnosis of one log says, as the table needs it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Findings {
    /// The named effects, largest share of the gain first (empty: none).
    pub effects: Vec<String>,
    /// The named effects' parameters, by effect and parameter.
    pub named: BTreeMap<String, BTreeMap<String, Estimate>>,
    /// Every tested effect's released parameters, named or not, by `effect.parameter`.
    pub released: BTreeMap<String, Estimate>,
    /// Extended minus baseline pressure fit. [percentage points]
    pub fit_points: Option<f64>,
    /// Baseline residual RMS over noise RMS, per signal. [1]
    pub noise_baseline: BTreeMap<String, f64>,
    /// Extended residual RMS over noise RMS, per signal. [1]
    pub noise_extended: BTreeMap<String, f64>,
}

/// One row of the table.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The log's path as given or found.
    pub path: String,
    /// Its drive, if known.
    pub drive: Option<String>,
    /// When it started, as written, if known.
    pub recorded_at: Option<String>,
    /// `recorded_at` in days since the Unix epoch. [day]
    pub t_days: Option<f64>,
    /// SHA-256 of its bytes, if it could be read.
    pub sha256: Option<String>,
    /// The diagnosis, or why there is none.
    pub result: Result<Findings, String>,
}

fn number(v: &Value) -> Option<f64> {
    v.as_f64().filter(|x| x.is_finite())
}

fn numbers(v: &Value) -> BTreeMap<String, f64> {
    v.as_object()
        .map(|m| {
            m.iter()
                .filter_map(|(k, v)| Some((k.clone(), number(v)?)))
                .collect()
        })
        .unwrap_or_default()
}

/// The findings in `eha diagnose`'s JSON; `None` when it is not that JSON.
pub fn findings(d: &Value) -> Option<Findings> {
    let effects: Vec<String> = d["extended"]["effects"]
        .as_array()?
        .iter()
        .filter_map(|e| e.as_str().map(str::to_string))
        .collect();
    let mut f = Findings {
        fit_points: number(&d["gain"]["fit_points"]),
        noise_baseline: numbers(&d["baseline"]["noise_ratio_by_signal"]),
        noise_extended: numbers(&d["extended"]["noise_ratio_by_signal"]),
        ..Findings::default()
    };
    for cause in d["causes"].as_array()? {
        let Some(effect) = cause["effect"].as_str() else {
            continue;
        };
        let ses = &cause["standard_errors"];
        let estimates: BTreeMap<String, Estimate> = cause["parameters"]
            .as_object()
            .map(|m| {
                m.iter()
                    .filter_map(|(k, v)| {
                        let value = number(v)?;
                        let se = number(&ses[k]).filter(|s| *s >= 0.0);
                        Some((k.clone(), Estimate { value, se }))
                    })
                    .collect()
            })
            .unwrap_or_default();
        for (k, e) in &estimates {
            f.released.entry(format!("{effect}.{k}")).or_insert(*e);
        }
        if effects.iter().any(|n| n == effect) {
            f.named.entry(effect.to_string()).or_insert(estimates);
        }
    }
    f.effects = effects;
    Some(f)
}

/// The CSV header.
pub fn header() -> Vec<String> {
    let mut h: Vec<String> = [
        "path",
        "drive",
        "recorded_at",
        "status",
        "sha256",
        "effects",
        "fit_points",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for (effect, params) in PARAMETERS {
        for p in params {
            h.push(format!("{effect}.{p}"));
            h.push(format!("{effect}.{p}.se"));
        }
    }
    for which in ["baseline", "extended"] {
        for s in SIGNALS {
            h.push(format!("noise_ratio.{which}.{s}"));
        }
    }
    h
}

fn num(v: Option<f64>) -> String {
    let mut s = String::new();
    if let Some(v) = v.filter(|v| v.is_finite()) {
        format_value(&mut s, v);
    }
    s
}

/// The row's status: `ok`, or the error.
pub fn status(row: &Row) -> String {
    match &row.result {
        Ok(_) => "ok".into(),
        Err(e) => format!("error: {e}"),
    }
}

/// The row's CSV fields, in [`header`]'s order.
fn fields(row: &Row) -> Vec<String> {
    let mut r = vec![
        row.path.clone(),
        row.drive.clone().unwrap_or_default(),
        row.recorded_at.clone().unwrap_or_default(),
        status(row),
        row.sha256.clone().unwrap_or_default(),
    ];
    let f = row.result.as_ref().ok();
    r.push(f.map_or(String::new(), |f| {
        if f.effects.is_empty() {
            "none".into()
        } else {
            f.effects.join(";")
        }
    }));
    r.push(num(f.and_then(|f| f.fit_points)));
    for (effect, params) in PARAMETERS {
        for p in params {
            let e = f.and_then(|f| f.named.get(effect)?.get(*p));
            r.push(num(e.map(|e| e.value)));
            r.push(num(e.and_then(|e| e.se)));
        }
    }
    for map in [f.map(|f| &f.noise_baseline), f.map(|f| &f.noise_extended)] {
        for s in SIGNALS {
            r.push(num(map.and_then(|m| m.get(s).copied())));
        }
    }
    r
}

/// Writes the table as CSV.
pub fn write_csv(w: &mut dyn Write, rows: &[Row]) -> io::Result<()> {
    let mut csv = csv::Writer::from_writer(w);
    csv.write_record(header())?;
    for row in rows {
        csv.write_record(fields(row))?;
    }
    csv.flush()
}

fn estimates_json(m: &BTreeMap<String, BTreeMap<String, Estimate>>) -> (Value, Value) {
    let mut values = Map::new();
    let mut ses = Map::new();
    for (effect, params) in m {
        values.insert(
            effect.clone(),
            params
                .iter()
                .map(|(k, e)| (k.clone(), json!(e.value)))
                .collect(),
        );
        ses.insert(
            effect.clone(),
            params
                .iter()
                .map(|(k, e)| (k.clone(), json!(e.se)))
                .collect(),
        );
    }
    (Value::Object(values), Value::Object(ses))
}

/// One row as JSON: the CSV's content, nested (named effects' `parameters` and
/// `standard_errors` by effect, noise ratios by model and signal).
pub fn row_json(row: &Row) -> Value {
    let mut v = json!({
        "path": row.path,
        "drive": row.drive,
        "recorded_at": row.recorded_at,
        "status": status(row),
        "sha256": row.sha256,
    });
    if let Ok(f) = &row.result {
        let (values, ses) = estimates_json(&f.named);
        v["effects"] = json!(f.effects);
        v["parameters"] = values;
        v["standard_errors"] = ses;
        v["fit_points"] = json!(f.fit_points);
        v["noise_ratio_by_signal"] = json!({
            "baseline": f.noise_baseline,
            "extended": f.noise_extended,
        });
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use plant_model::effects::EFFECT_NAMES;
    use plant_model::Effect;

    #[test]
    fn the_columns_hold_every_parameter_of_the_catalogue() {
        // The plant model's catalogue (what `eha simulate --effects` takes) against the
        // table's columns: every effect but `none`, every parameter it has.
        for name in EFFECT_NAMES.iter().filter(|n| **n != "none") {
            let cols = PARAMETERS
                .iter()
                .find(|(e, _)| e == name)
                .unwrap_or_else(|| panic!("{name} has no columns"))
                .1;
            let e = Effect::parse(name).unwrap();
            for (p, _) in e.parameters().iter().flatten() {
                assert!(cols.contains(p), "{name}.{p} has no column");
            }
        }
        assert_eq!(PARAMETERS.len(), EFFECT_NAMES.len() - 1);
    }

    #[test]
    fn a_diagnosis_becomes_a_row_with_named_and_released_estimates() {
        // A diagnosis as the contract writes it: one named effect, one tested but not
        // named, an infinite standard error written as null.
        let d = json!({
            "extended": {"effects": ["accumulator_precharge"],
                         "noise_ratio_by_signal": {"p_pa": 1.1}},
            "baseline": {"noise_ratio_by_signal": {"p_pa": 3.6, "iq_a": 1.0}},
            "gain": {"fit_points": 12.5},
            "causes": [
                {"effect": "accumulator_precharge", "parameters": {"precharge_pa": 1.8e6},
                 "standard_errors": {"precharge_pa": 2.0e4}},
                {"effect": "extra_leakage", "parameters": {"coefficient_m3_s_pa": 1e-14},
                 "standard_errors": {"coefficient_m3_s_pa": null}},
                {"effect": "none", "parameters": {}}
            ]
        });
        let f = findings(&d).unwrap();
        assert_eq!(f.effects, ["accumulator_precharge"]);
        assert_eq!(
            f.released["accumulator_precharge.precharge_pa"],
            Estimate {
                value: 1.8e6,
                se: Some(2.0e4)
            }
        );
        assert_eq!(f.released["extra_leakage.coefficient_m3_s_pa"].se, None);
        assert!(!f.named.contains_key("extra_leakage"));
        let row = Row {
            path: "a.csv".into(),
            drive: Some("D1".into()),
            recorded_at: Some("2026-01-01T00:00:00Z".into()),
            t_days: Some(20454.0),
            sha256: Some("00".repeat(32)),
            result: Ok(f),
        };
        let h = header();
        let r = fields(&row);
        assert_eq!(h.len(), r.len());
        let at = |c: &str| r[h.iter().position(|x| x == c).unwrap()].clone();
        assert_eq!(at("status"), "ok");
        assert_eq!(at("effects"), "accumulator_precharge");
        assert_eq!(at("accumulator_precharge.precharge_pa"), "1800000");
        assert_eq!(at("accumulator_precharge.precharge_pa.se"), "20000");
        assert_eq!(at("extra_leakage.coefficient_m3_s_pa"), "");
        assert_eq!(at("noise_ratio.baseline.iq_a"), "1");
        assert_eq!(at("fit_points"), "12.5");
        let v = row_json(&row);
        assert_eq!(
            v["parameters"]["accumulator_precharge"]["precharge_pa"],
            1.8e6
        );
        assert_eq!(v["noise_ratio_by_signal"]["extended"]["p_pa"], 1.1);
        let failed = Row {
            result: Err("bench log `b.csv`, line 3: not a number".into()),
            ..row
        };
        assert!(fields(&failed)[3].starts_with("error: bench log"));
        assert_eq!(fields(&failed)[5], "");
    }
}
