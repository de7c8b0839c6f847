//! The contract's per-signal predictions of a model (calibrated nominal, or extended by the
//! named effect), each from the parity relation that predicts the signal from the others:
//!
//! - `p_pa`: the hydraulic relation over its shooting windows (or, when the named effect is
//!   the cylinder's, the cylinder's force balance, so baseline and extension are compared
//!   on the same relation);
//! - `speed_rad_s`: the mechanical relation integrated over its shooting windows;
//! - `iq_a`: the q current the mechanical relation needs;
//! - `ud_v`, `uq_v`: the electrical relation, when the voltages are logged.
//!
//! Scores on a segment: the contract's fit (MATLAB `compare`) and the residual's RMS over
//! the signal's own noise RMS from the log (1.0: explained down to the noise).

use crate::bench_log::{BenchLog, Signal};
use crate::diagnose::cylinder::CylinderRelation;
use crate::diagnose::electrical::ElectricalRelation;
use crate::diagnose::facts::LogFacts;
use crate::diagnose::fit_score::fit_percent;
use crate::diagnose::hydraulic::{HydraulicInputs, Hydraulics};
use crate::diagnose::hydraulic_relation::{hydraulic_params, HYDRAULIC_WINDOW_S};
use crate::diagnose::mechanical::{Mechanics, ShaftMotion, TorqueLine};
use crate::diagnose::mechanical_relation::{mechanical_params, SPEED_WINDOW_S};
use plant_model::Rig;
use std::collections::BTreeMap;
use std::ops::Range;

/// One model's parameters on every relation the log supports.
#[derive(Clone, Debug)]
pub struct ModelValues {
    /// Hydraulic relation's search values.
    pub hydraulic: Vec<f64>,
    /// Mechanical relation's search values.
    pub mechanical: Vec<f64>,
    /// Torque lines added to the mechanical relation.
    pub lines: Vec<TorqueLine>,
    /// Electrical relation's values, when it exists.
    pub electrical: Option<Vec<f64>>,
    /// Cylinder relation's values, when it exists.
    pub cylinder: Option<Vec<f64>>,
    /// Whether the pressure is predicted by the cylinder relation.
    pub pressure_from_cylinder: bool,
}

/// Everything the predictions read.
pub struct Context<'a> {
    /// The log.
    pub log: &'a BenchLog,
    /// Its facts.
    pub facts: &'a LogFacts,
    /// The shaft's motion.
    pub motion: &'a ShaftMotion,
    /// The rig file.
    pub rig: &'a Rig,
    /// The electrical relation, when the voltages are logged.
    pub electrical: Option<&'a ElectricalRelation<'a>>,
    /// The cylinder relation, when the piston moves.
    pub cylinder: Option<&'a CylinderRelation<'a>>,
}

/// Predicts every signal over the whole log.
pub fn predict(c: &Context<'_>, m: &ModelValues) -> BTreeMap<&'static str, Vec<f64>> {
    let mut out = BTreeMap::new();
    predict_each(c, m, &mut |name, v| {
        out.insert(name, v);
    });
    out
}

/// Predicts every signal over the whole log, handing each to `sink` as soon as it is
/// made: a caller that only scores them holds one whole-log signal at a time.
pub fn predict_each(
    c: &Context<'_>,
    m: &ModelValues,
    sink: &mut dyn FnMut(&'static str, Vec<f64>),
) {
    let n = c.facts.rows;
    let all = 0..n;
    let mut p = vec![0.0; n];
    match (m.pressure_from_cylinder, c.cylinder, &m.cylinder) {
        (true, Some(rel), Some(v)) => rel.predict(v, all.clone(), &mut p),
        _ => {
            let hyd = Hydraulics::new(hydraulic_params(c.rig, &m.hydraulic), c.rig);
            let w = c.facts.windows(all.clone(), HYDRAULIC_WINDOW_S);
            hyd.predict(&HydraulicInputs::of(c.log, c.facts), &w, &mut p);
        }
    }
    sink("p_pa", p);
    let mut params = mechanical_params(c.rig, &m.mechanical);
    params.lines = m.lines.clone();
    let mech = Mechanics::new(params);
    let mut speed = vec![0.0; n];
    let w = c.facts.windows(all.clone(), SPEED_WINDOW_S);
    mech.speed(c.log, c.facts, c.motion, &w, &mut speed);
    sink("speed_rad_s", speed);
    let mut iq = vec![0.0; n];
    mech.needed_current(c.log, c.facts, c.motion, all.clone(), &mut iq);
    sink("iq_a", iq);
    if let (Some(rel), Some(v)) = (c.electrical, &m.electrical) {
        let (mut ud, mut uq) = (vec![0.0; n], vec![0.0; n]);
        rel.predict(v, all, &mut ud, &mut uq);
        sink("ud_v", ud);
        sink("uq_v", uq);
    }
}

/// Fit (%) and noise ratio of each predicted signal over `rows`.
pub fn scores(
    log: &BenchLog,
    facts: &LogFacts,
    predicted: &BTreeMap<&'static str, Vec<f64>>,
    rows: Range<usize>,
) -> (BTreeMap<String, f64>, BTreeMap<String, f64>) {
    let mut fits = BTreeMap::new();
    let mut ratios = BTreeMap::new();
    for (name, y_hat) in predicted {
        let Some(signal) = Signal::from_name(name) else {
            continue;
        };
        let Some(y) = log.column(signal) else {
            continue;
        };
        let (y, y_hat) = (&y[rows.clone()], &y_hat[rows.clone()]);
        if let Some(f) = fit_percent(y, y_hat) {
            fits.insert(name.to_string(), f);
        }
        let rms = (y
            .iter()
            .zip(y_hat)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            / y.len().max(1) as f64)
            .sqrt();
        if let Some(noise) = facts.noise(signal).filter(|s| *s > 0.0) {
            if rms.is_finite() {
                ratios.insert(name.to_string(), rms / noise);
            }
        }
    }
    (fits, ratios)
}
