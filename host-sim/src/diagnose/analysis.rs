//! The diagnosis: what the nominal model gets wrong on a log, which effect of the catalogue
//! explains it, with which parameters, and what that gains on data the fit never saw.
//!
//! 1. Segments: identification = the first half of the log (at most
//!    [`MAX_IDENTIFICATION_S`]; half-way into a final pressure hold the first half does not
//!    reach, see [`segments`]), validation = the rest.
//! 2. Baseline: every subsystem replay ([`super::predict`]) and the closed loop
//!    ([`super::closed_replay`]) on the nominal rig over the whole log; residuals.
//! 3. Evidence: the residuals' order spectra against the shaft angle
//!    ([`super::spectrum`]) point at angle-locked effects and fix the cogging order.
//! 4. Every candidate ([`super::candidates`]) is fitted on the identification rows
//!    ([`super::fit`], in parallel): its score is the fraction of the nominal model's error
//!    on its signals it removes there.
//! 5. The best candidate that is a fault (beyond the rig's tolerances, see
//!    [`Candidate::is_significant`]) is kept only if it also improves its signals on the
//!    validation segment; otherwise the answer is `none`.

use super::candidates::{candidates, tolerance_dims, Candidate, RIPPLE_PISTONS};
use super::closed_replay::{hold_scored_from, replay_closed_loop, scenario_of};
use super::diagnosis::{Cause, Diagnosis, Extended, Fit, Gain};
use super::fit::{fit, CandidateFit, Target};
use super::lock_in::refine_ripple_amplitude;
use super::predict::{piston_moves, predict, Predicted, Predictor};
use super::replay::{unwrap_angle, ReplayError, INITIAL_SAMPLES};
use super::signatures::{residual_signature, Regressors, ResidualSignature};
use super::spectrum::{order_spectrum, OrderSpectrum};
use super::{fit_percent, DiagnoseError};
use crate::bench_log::{BenchLog, Signal};
use closed_loop::ScenarioKind;
use plant_model::pump::ripple_order;
use plant_model::Rig;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;

/// Longest identification segment: the fit replays it once per evaluation, so this bounds
/// the diagnosis's time on long logs (a few seconds hold every effect's signature). [s]
pub const MAX_IDENTIFICATION_S: f64 = 2.5;

/// Fraction of the nominal model's identification error a candidate must remove to be
/// considered at all. [1]
pub const MIN_EXPLAINED: f64 = 0.2;

/// Validation-fit improvement, on the candidate's own signals, below which an extension is
/// not kept. [percentage points]
pub const MIN_VALIDATION_GAIN_POINTS: f64 = 1.0;

/// Rows of a settled final pressure hold below which the hold replay is not fitted (0.1 s
/// at 1 kHz: the pressure loop's integral, which carries the leakage speed, settles in
/// that time). [1]
const MIN_HOLD_ROWS: usize = 100;

/// Longest settled hold the hold replay is fitted on: its pump speed is a level, which half
/// a second of a hold fixes to the speed noise over √500 (each evaluation replays the whole
/// loop, the costliest of the replays). [s]
const MAX_HOLD_IDENTIFICATION_S: f64 = 0.5;

/// Everything the diagnosis computed, for the JSON and the report.
pub struct Analysis {
    /// The contract's result.
    pub diagnosis: Diagnosis,
    /// The log's time. [s]
    pub t_s: Vec<f64>,
    /// Measured signals by name.
    pub measured: BTreeMap<&'static str, Vec<f64>>,
    /// Baseline predictions by signal name, whole log.
    pub baseline: BTreeMap<&'static str, Vec<f64>>,
    /// Extended predictions by signal name, whole log (equal to the baseline when nothing
    /// was kept).
    pub extended: BTreeMap<&'static str, Vec<f64>>,
    /// Order spectra of the baseline residuals (pressure, speed), when the shaft turned.
    pub spectra: Vec<(&'static str, OrderSpectrum)>,
    /// Time-domain signatures of the baseline residuals, one per predicted signal.
    pub signatures: Vec<ResidualSignature>,
    /// Orders the candidates point at, for the plots: (order, effect).
    pub candidate_orders: Vec<(u32, &'static str)>,
    /// Every candidate's fit.
    pub fits: Vec<CandidateFit>,
}

/// Diagnoses `log` against the nominal model `rig`.
pub fn diagnose(log: &BenchLog, rig: &Rig) -> Result<Diagnosis, DiagnoseError> {
    analyse(log, rig).map(|a| a.diagnosis)
}

fn column<'a>(log: &'a BenchLog, name: &str) -> Option<&'a [f64]> {
    log.column(Signal::from_name(name)?)
}

/// The predictors the log supports.
pub fn predictors(log: &BenchLog) -> Vec<Predictor> {
    let mut p = vec![Predictor::Hydraulics, Predictor::Motor];
    if piston_moves(log) {
        p.push(Predictor::Cylinder);
    }
    if log.theta_m_rad.is_some() && log.ud_v.is_some() && log.uq_v.is_some() {
        p.push(Predictor::Electrical);
    }
    if log.theta_m_rad.is_some() && scenario_of(log).is_some() {
        p.push(Predictor::InnerLoops);
    }
    // A log that holds from the start has its leakage in the hydraulic replay's pressure
    // drift over the identification segment; one whose final hold begins after the
    // middle (a pressure step's fill) has it only in the hold's pump speed.
    if scenario_of(log).is_some_and(|s| s.kind == ScenarioKind::PressureStep)
        && hold_scored_from(log)
            .is_some_and(|k| k + MIN_HOLD_ROWS < log.len() && log.t_s[k] > default_split_time(log))
    {
        p.push(Predictor::PressureLoop);
    }
    p
}

/// Predictions by signal: the subsystem replays' (what the diagnosis decides on) and the
/// closed loop's.
#[derive(Clone, Debug, Default)]
pub struct Predictions {
    /// Hydraulic, motor and electrical replays by signal.
    pub subsystem: BTreeMap<&'static str, Vec<f64>>,
    /// Speed and current loops replayed on the logged speed reference
    /// ([`Predictor::InnerLoops`]) by signal; empty without the shaft angle.
    pub inner_loops: BTreeMap<&'static str, Vec<f64>>,
    /// The whole closed loop replayed from the logged setpoints, by signal (empty when the
    /// log has no usable setpoint).
    pub closed_loop: BTreeMap<&'static str, Vec<f64>>,
}

impl Predictions {
    /// The contract's per-signal predictions: pressure and voltages from the subsystem
    /// replays (driven by the logged angle and currents); speed and currents from the
    /// control loops, which predict them (the subsystem replays take them as inputs). The
    /// speed comes from the whole loop: in pressure control the logged speed reference is
    /// the pressure loop's output, and the inner loops replayed on it would predict the
    /// speed from itself. The q current comes from the inner loops where they ran (the
    /// torque the shaft needed, without the pressure loop's answer to its transducer's
    /// noise, which no noise-free replay reproduces), else from the whole loop. The motor
    /// replay's speed and needed current stand when neither loop could be replayed.
    pub fn contract(&self) -> BTreeMap<&'static str, Vec<f64>> {
        let mut out = self.subsystem.clone();
        for (k, v) in &self.closed_loop {
            if *k != "p_pa" {
                out.insert(k, v.clone());
            }
        }
        if let Some(iq) = self.inner_loops.get("iq_a") {
            out.insert("iq_a", iq.clone());
        }
        out
    }
}

/// Every prediction on `rig`, the pressure from `pressure` (the hydraulic replay with the
/// piston prescribed, or with it simulated when the extension is the cylinder's).
fn predict_all(
    log: &BenchLog,
    supported: &[Predictor],
    rig: &Rig,
    phase_a_offset_a: f64,
    pressure: Predictor,
) -> Result<Predictions, ReplayError> {
    // The whole loop's replay (every signal it predicts) beside the others.
    let (preds, whole): (Vec<Result<(Predictor, Predicted), ReplayError>>, _) = rayon::join(
        || {
            supported
                .par_iter()
                .copied()
                .filter(|p| match p {
                    Predictor::Hydraulics | Predictor::Cylinder => *p == pressure,
                    Predictor::PressureLoop => false,
                    _ => true,
                })
                .map(|p| Ok((p, predict(log, rig, p, usize::MAX, phase_a_offset_a)?)))
                .collect()
        },
        || replay_closed_loop(log, rig),
    );
    let mut out = Predictions::default();
    for p in preds {
        let (predictor, predicted) = p?;
        let map = match predictor {
            Predictor::InnerLoops => &mut out.inner_loops,
            _ => &mut out.subsystem,
        };
        map.extend(predicted);
    }
    if let Some(cl) = whole {
        out.closed_loop.insert("p_pa", cl.p_pa);
        out.closed_loop.insert("speed_rad_s", cl.speed_rad_s);
        out.closed_loop.insert("iq_a", cl.iq_a);
        out.closed_loop.insert("id_a", cl.id_a);
    }
    Ok(out)
}

/// Fit per signal over `rows`.
fn fits_over(
    log: &BenchLog,
    predicted: &BTreeMap<&'static str, Vec<f64>>,
    rows: std::ops::Range<usize>,
) -> BTreeMap<String, f64> {
    predicted
        .iter()
        .filter_map(|(name, y_hat)| {
            let y = column(log, name)?;
            let f = fit_percent(&y[rows.clone()], y_hat.get(rows.clone())?)?;
            Some((name.to_string(), f))
        })
        .collect()
}

fn rmse(y: &[f64], y_hat: &[f64]) -> f64 {
    let n = y.len().min(y_hat.len()).max(1);
    (y.iter()
        .zip(y_hat)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        / n as f64)
        .sqrt()
}

fn fit_of(
    log: &BenchLog,
    predicted: &BTreeMap<&'static str, Vec<f64>>,
    rows: std::ops::Range<usize>,
) -> Fit {
    let by = fits_over(log, predicted, rows.clone());
    Fit {
        fit_percent: by.get("p_pa").copied().unwrap_or(f64::NAN),
        rmse_pa: predicted
            .get("p_pa")
            .map_or(f64::NAN, |p| rmse(&log.p_pa[rows.clone()], &p[rows])),
        fit_percent_by_signal: by,
    }
}

/// The identification segment of a checked `log` (at least a few rows): its end row
/// `split` (the validation segment is `split..`) and the first row scored, `from` (the
/// replays' start-up rows are skipped).
///
/// The split is the log's middle (at most [`MAX_IDENTIFICATION_S`] in), unless the log
/// ends in a pressure hold the first half does not reach: a pressure step whose fill takes
/// most of the log. Then the identification segment runs half-way into that hold's settled
/// part ([`hold_scored_from`]), so the fit sees the regime the validation tests: the hold is
/// where the leakage shows, in the pump speed that replaces it, while in the fill it is a
/// few percent of the pump's flow, where the rig's tolerances would mimic it.
pub fn segments(log: &BenchLog) -> (usize, usize) {
    let n = log.len();
    let t = &log.t_s;
    let mut t_split = default_split_time(log);
    if let Some(t_hold) = hold_scored_from(log).and_then(|k| t.get(k)) {
        if *t_hold > t_split {
            t_split = t_hold + 0.5 * (t[n - 1] - t_hold);
        }
    }
    let split = t.partition_point(|x| *x < t_split).clamp(2, n - 1);
    (split, INITIAL_SAMPLES.min(split / 4))
}

/// The identification rows `predictor` is fitted on, as (first scored row, end row), for a
/// log whose identification segment is `from..split` ([`segments`]): those, except for the
/// hold replay, which predicts the settled final hold only and is fitted on at most
/// [`MAX_HOLD_IDENTIFICATION_S`] of it.
pub fn scored_rows(
    log: &BenchLog,
    predictor: Predictor,
    split: usize,
    from: usize,
) -> (usize, usize) {
    if predictor != Predictor::PressureLoop {
        return (from, split);
    }
    let t = &log.t_s;
    let first = hold_scored_from(log).map_or(from, |k| k.max(from));
    let end = t
        .partition_point(|x| *x < t[first.min(t.len() - 1)] + MAX_HOLD_IDENTIFICATION_S)
        .min(split);
    (first, end)
}

/// The identification segment's end without a late final hold: the log's middle, at most
/// [`MAX_IDENTIFICATION_S`] in. [s]
fn default_split_time(log: &BenchLog) -> f64 {
    let t = &log.t_s;
    let (first, last) = (t[0], t[t.len() - 1]);
    (first + 0.5 * (last - first)).min(first + MAX_IDENTIFICATION_S)
}

/// Runs the whole analysis.
pub fn analyse(log: &BenchLog, rig: &Rig) -> Result<Analysis, DiagnoseError> {
    log.check(Path::new("bench log being diagnosed"))
        .map_err(ReplayError::from)?;
    rig.validate().map_err(ReplayError::from)?;
    let n = log.len();
    let t = &log.t_s;
    // 1. Segments.
    let (split, from) = segments(log);
    // 2. Baseline.
    let supported = predictors(log);
    let mut base_pred = predict_all(log, &supported, rig, 0.0, Predictor::Hydraulics)?;
    let baseline = base_pred.subsystem.clone();
    let measured: BTreeMap<&'static str, Vec<f64>> = base_pred
        .contract()
        .keys()
        .filter_map(|k| Some((*k, column(log, k)?.to_vec())))
        .collect();
    // 3. Evidence: the residuals' time-domain signatures and order spectra (against the
    // logged angle, else against the angle the logged speed integrates to).
    let signatures = residual_signatures(log, &measured, &baseline, from);
    let has_angle = log.theta_m_rad.is_some();
    let theta = match log.theta_m_rad.as_deref() {
        Some(th) => Some(unwrap_angle(th)),
        None => integrated_angle(&log.t_s, &log.speed_rad_s),
    };
    let mut spectra = Vec::new();
    if let Some(th) = &theta {
        for name in ["p_pa", "speed_rad_s"] {
            if let (Some(y), Some(y_hat)) = (measured.get(name), baseline.get(name)) {
                let r = super::residual(y, y_hat);
                if let Some(s) = order_spectrum(&th[from..], &r[from..]) {
                    spectra.push((name, s));
                }
            }
        }
    }
    let pp = rig.motor.pole_pairs;
    let lcm = rig.motor.cogging_fundamental_order();
    let mut cogging_orders = vec![lcm];
    let mut ripple_pistons = Vec::new();
    if let Some((_, s)) = spectra.iter().find(|(n, _)| *n == "speed_rad_s") {
        // A strong line at a pump's ripple order is its torque ripple (in a stroke, its
        // flow ripple is fitted on the hydraulics whatever the spectrum); at an order no
        // other angle-locked effect makes, a cogging order the rig file does not predict.
        let floor = s.floor(2, 200);
        if let Some((k, a)) = s.strongest(2, 200) {
            if a > 6.0 * floor {
                match RIPPLE_PISTONS.iter().find(|z| ripple_order(**z) == k) {
                    Some(z) => ripple_pistons.push(*z),
                    None if k % pp != 0 && k != lcm => cogging_orders.push(k),
                    None => {}
                }
            }
        }
    }
    // 4. Candidates fitted on the identification rows.
    let cands = candidates(rig, &supported, has_angle, &cogging_orders, &ripple_pistons);
    // The free-payload pressure replay, only when the piston moves: the baseline of the
    // cylinder's candidates, and the contract's baseline pressure if one of them is kept.
    let cylinder_baseline: BTreeMap<&'static str, Vec<f64>> =
        if supported.contains(&Predictor::Cylinder) {
            predict(log, rig, Predictor::Cylinder, usize::MAX, 0.0)?
                .into_iter()
                .collect()
        } else {
            BTreeMap::new()
        };
    let targets: BTreeMap<Predictor, Target> = supported
        .iter()
        .copied()
        .map(|p| {
            let pred: Predicted = if p == Predictor::Cylinder {
                cylinder_baseline.clone().into_iter().collect()
            } else if p == Predictor::InnerLoops {
                p.signals()
                    .iter()
                    .filter_map(|s| Some((*s, base_pred.inner_loops.get(s)?.clone())))
                    .collect()
            } else if p == Predictor::PressureLoop {
                predict(log, rig, p, scored_rows(log, p, split, from).1, 0.0).unwrap_or_default()
            } else {
                p.signals()
                    .iter()
                    .filter_map(|s| Some((*s, baseline.get(s)?.clone())))
                    .collect()
            };
            let (from, rows) = scored_rows(log, p, split, from);
            (p, Target::new(log, rig, rows, from, &pred))
        })
        .filter(|(_, t)| !t.baseline_sse.is_empty())
        .collect();
    // The nominal model within its tolerances first, per predictor: its tolerance
    // coordinates are a second start of every other candidate of that predictor (the
    // simplex then has only the effect to find, not the rig's few percent as well; the
    // nominal start stays, for effects the tolerances had mimicked).
    let (nones, effects): (Vec<Candidate>, Vec<Candidate>) =
        cands.into_iter().partition(|c| c.name == "none");
    let calibrations: Vec<CandidateFit> = nones
        .par_iter()
        .filter_map(|c| Some(fit(targets.get(&c.predictor)?, c)))
        .collect();
    let effects: Vec<Candidate> = effects
        .into_iter()
        .map(|mut c| {
            if let Some(cal) = calibrations
                .iter()
                .find(|k| k.candidate.predictor == c.predictor)
            {
                let dims = tolerance_dims(c.predictor);
                let (n, m) = (c.start.len(), cal.u.len());
                // Only the hydraulic replays' two tolerances (displacement and absorber volume)
                // leave a simplex of 18 iterations short of an effect's minimum; the motor's one
                // coordinate does not, and the closed loop's replays are the costliest.
                if dims > 1 && dims <= n && dims <= m {
                    let mut alt = c.start.clone();
                    alt[n - dims..].copy_from_slice(&cal.u[m - dims..]);
                    c.alternative_start = alt;
                }
            }
            c
        })
        .collect();
    let mut fits: Vec<CandidateFit> = effects
        .par_iter()
        .filter_map(|c| {
            let t = targets.get(&c.predictor)?;
            Some(refine_ripple_amplitude(t, fit(t, c)))
        })
        .collect();
    // The nominal model within its tolerances, per predictor: the reference every
    // candidate of that predictor must beat (costs become relative to it).
    for f in &mut fits {
        if let Some(c) = calibrations
            .iter()
            .find(|c| c.candidate.predictor == f.candidate.predictor)
        {
            if c.cost > 0.0 && c.cost < 1.0 {
                f.cost /= c.cost;
            }
        }
    }
    fits.sort_by(|a, b| a.cost.total_cmp(&b.cost));
    // 5. Keep the best fault that validates against the calibrated nominal model.
    let val = split..n;
    // The calibrated nominal model's validation fits, per predictor, computed when a
    // candidate of that predictor first reaches validation (a whole-log replay each).
    let calibrated_fits = |p: Predictor| -> Option<BTreeMap<String, f64>> {
        let calibrated = calibrations
            .iter()
            .find(|c| c.candidate.predictor == p)
            .map_or_else(|| rig.clone(), |c| c.candidate.rig_at(&c.u, rig));
        let pred: BTreeMap<&'static str, Vec<f64>> = predict(log, &calibrated, p, usize::MAX, 0.0)
            .ok()?
            .into_iter()
            .collect();
        Some(fits_over(log, &pred, val.clone()))
    };
    let mut calibrated_val: BTreeMap<Predictor, Option<BTreeMap<String, f64>>> = BTreeMap::new();
    let mut kept: Option<(usize, Predictions)> = None;
    let mut notes: BTreeMap<usize, String> = BTreeMap::new();
    for (i, f) in fits.iter().enumerate() {
        if 1.0 - f.cost < MIN_EXPLAINED {
            break;
        }
        if !f.candidate.is_significant(&f.u, rig) {
            notes.insert(i, "within the rig's tolerances".into());
            continue;
        }
        if let Some(why) = missing_order_line(&f.candidate, &spectra, rig) {
            notes.insert(i, why);
            continue;
        }
        let ext_rig = f.candidate.rig_at(&f.u, rig);
        let offset = f.candidate.phase_a_offset_a(&f.u);
        // Only the candidate's own replay decides; the other predictors (and the closed
        // loop) run once an extension is kept.
        let own: BTreeMap<&'static str, Vec<f64>> =
            predict(log, &ext_rig, f.candidate.predictor, usize::MAX, offset)?
                .into_iter()
                .collect();
        let ext_val = fits_over(log, &own, val.clone());
        let base_val = calibrated_val
            .entry(f.candidate.predictor)
            .or_insert_with(|| calibrated_fits(f.candidate.predictor))
            .as_ref();
        let gain = f
            .candidate
            .predictor
            .signals()
            .iter()
            .filter_map(|s| Some(ext_val.get(*s)? - base_val?.get(*s)?))
            .fold(f64::NEG_INFINITY, f64::max);
        if gain >= MIN_VALIDATION_GAIN_POINTS {
            let pressure = match f.candidate.predictor {
                Predictor::Cylinder => Predictor::Cylinder,
                _ => Predictor::Hydraulics,
            };
            if pressure == Predictor::Cylinder {
                // Baseline and extension on the same replay, so the gain is the extension's.
                base_pred.subsystem.extend(cylinder_baseline.clone());
            }
            kept = Some((i, predict_all(log, &supported, &ext_rig, offset, pressure)?));
            break;
        }
        notes.insert(
            i,
            format!("does not improve the validation segment ({gain:+.1} points)"),
        );
    }
    // Causes, ranked.
    let best_explained = fits.first().map_or(0.0, |f| 1.0 - f.cost);
    let mut causes = Vec::new();
    let describe = |f: &CandidateFit| {
        let signals = f.candidate.predictor.signals().join(", ");
        let mut s = format!(
            "removes {:.0} % of the squared error the nominal model (within its tolerances) leaves in {} ({}) on the identification segment",
            100.0 * (1.0 - f.cost),
            signals,
            f.candidate.predictor.describe()
        );
        if let Some(line) = order_evidence(&f.candidate, &spectra, rig) {
            s.push_str("; ");
            s.push_str(&line);
        }
        let own = f.candidate.predictor.signals();
        if let Some(sig) = signatures.iter().find(|g| own.contains(&g.signal)) {
            s.push_str("; ");
            s.push_str(&sig.phrase_for(f.candidate.name));
        }
        s
    };
    let none_cause = |score: f64, why: String| Cause {
        effect: "none".into(),
        score,
        parameters: BTreeMap::new(),
        evidence: why,
    };
    if let Some((i, _)) = &kept {
        let f = &fits[*i];
        causes.push(cause_of(f, rig, describe(f)));
    } else {
        let mut why =
            "no effect of the catalogue beyond the rig's tolerances improves the validation segment"
                .to_string();
        for sig in &signatures {
            why.push_str("; ");
            why.push_str(&sig.whiteness_phrase());
        }
        causes.push(none_cause(1.0 - best_explained, why));
    }
    // The other candidates, best first, one entry per effect.
    for (i, f) in fits.iter().enumerate() {
        if kept.as_ref().is_some_and(|(k, _)| *k == i)
            || causes.iter().any(|c| c.effect == f.candidate.name)
        {
            continue;
        }
        let mut why = describe(f);
        if let Some(n) = notes.get(&i) {
            why.push_str("; ");
            why.push_str(n);
        }
        causes.push(cause_of(f, rig, why));
    }
    if kept.is_some() {
        causes.push(none_cause(
            0.0,
            "the kept extension improves the validation segment".into(),
        ));
    }
    let base_contract = base_pred.contract();
    let base_fit = fit_of(log, &base_contract, val.clone());
    let (ext_effects, ext_pred) = match kept {
        Some((i, ext)) => (vec![fits[i].candidate.name.to_string()], ext.contract()),
        None => (Vec::new(), base_contract.clone()),
    };
    let ext_fit = fit_of(log, &ext_pred, val.clone());
    let diagnosis = Diagnosis {
        samples: n,
        identification_segment_s: [t[0], t[split - 1]],
        validation_segment_s: [t[split], t[n - 1]],
        gain: Gain {
            fit_points: ext_fit.fit_percent - base_fit.fit_percent,
            rmse_reduction_percent: 100.0 * (1.0 - ext_fit.rmse_pa / base_fit.rmse_pa),
        },
        baseline: base_fit,
        causes,
        extended: Extended {
            effects: ext_effects,
            fit_percent: ext_fit.fit_percent,
            rmse_pa: ext_fit.rmse_pa,
            fit_percent_by_signal: ext_fit.fit_percent_by_signal,
        },
    };
    let candidate_orders = candidate_orders(rig, &cogging_orders);
    Ok(Analysis {
        diagnosis,
        t_s: t.clone(),
        measured,
        baseline: base_contract,
        extended: ext_pred,
        spectra,
        signatures,
        candidate_orders,
        fits,
    })
}

/// The time-domain signatures of every baseline residual, over the rows from `from`.
fn residual_signatures<'a>(
    log: &'a BenchLog,
    measured: &BTreeMap<&'static str, Vec<f64>>,
    baseline: &'a BTreeMap<&'static str, Vec<f64>>,
    from: usize,
) -> Vec<ResidualSignature> {
    let n = log.len();
    if n < from + 2 {
        return Vec::new();
    }
    let dt = (log.t_s[n - 1] - log.t_s[from]) / (n - 1 - from) as f64;
    // The model's operating point where it predicts it (a residual correlates with its own
    // measured signal through the noise alone), else the logged one.
    let point = |name: &str, logged: &'a [f64]| -> &'a [f64] {
        baseline.get(name).map_or(logged, Vec::as_slice)
    };
    let with = Regressors {
        speed_rad_s: &point("speed_rad_s", &log.speed_rad_s)[from..],
        p_pa: &point("p_pa", &log.p_pa)[from..],
        iq_a: &point("iq_a", &log.iq_a)[from..],
    };
    measured
        .iter()
        .filter_map(|(name, y)| {
            let y_hat = baseline.get(name)?;
            residual_signature(name, dt, y.get(from..)?, y_hat.get(from..)?, &with)
        })
        .collect()
}

/// The shaft angle the logged speed integrates to (trapezoids), for the order spectrum of
/// a log without the angle; `None` for fewer than two rows. [rad]
fn integrated_angle(t: &[f64], speed: &[f64]) -> Option<Vec<f64>> {
    if t.len() < 2 || speed.len() != t.len() {
        return None;
    }
    let mut theta = Vec::with_capacity(t.len());
    theta.push(0.0);
    for k in 1..t.len() {
        let step = 0.5 * (speed[k] + speed[k - 1]) * (t[k] - t[k - 1]);
        theta.push(theta[k - 1] + step);
    }
    Some(theta)
}

fn cause_of(f: &CandidateFit, rig: &Rig, evidence: String) -> Cause {
    Cause {
        effect: f.candidate.name.into(),
        score: (1.0 - f.cost).max(0.0),
        parameters: f
            .candidate
            .parameters(&f.u, rig)
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect(),
        evidence,
    }
}

/// The angle-locked orders each effect would show at.
fn candidate_orders(rig: &Rig, cogging: &[u32]) -> Vec<(u32, &'static str)> {
    let pp = rig.motor.pole_pairs;
    let mut v = vec![
        (pp, "current_sensor_offset"),
        (6 * pp, "flux_harmonics"),
        (2 * rig.pump.pistons, "piston_ripple"),
    ];
    v.extend(cogging.iter().map(|k| (*k, "cogging_torque")));
    v
}

/// How far above the residual spectrum's median line an angle-locked effect's order must
/// stand for the effect to be named, as (effect, factor). Measured on the blind suite's
/// logs: the motor replay's speed residual shows a first-electrical line (order 4) of up to
/// 82× its median without any offset (the replay's own angle tracking leaves it), and
/// 550–4000× with offsets of 0.23–0.75 A; the cogging order up to 5× without cogging and
/// 50× with 0.1 N·m; the sixth-electrical order up to 5× without flux harmonics and 14–16×
/// with 5.5 %. Without a spectrum (the shaft turned too little) an angle-locked effect is
/// not named: its fit would only be absorbing a slow model error.
pub const ORDER_LINE_FACTORS: [(&str, f64); 3] = [
    ("current_sensor_offset", 200.0),
    ("cogging_torque", 20.0),
    ("flux_harmonics", 10.0),
];

/// Why an angle-locked candidate lacks its line in the residual spectrum; `None` when it has
/// it or is not angle-locked.
fn missing_order_line(
    c: &Candidate,
    spectra: &[(&'static str, OrderSpectrum)],
    rig: &Rig,
) -> Option<String> {
    let factor = ORDER_LINE_FACTORS
        .iter()
        .find(|(name, _)| *name == c.name)?
        .1;
    let (signal, order) = angle_locked_order(c, rig)?;
    let Some((_, s)) = spectra.iter().find(|(n, _)| *n == signal) else {
        return Some("no residual order spectrum (the shaft turned too little)".into());
    };
    let ratio = s.at(order) / s.floor(1, 200).max(f64::MIN_POSITIVE);
    (ratio < factor).then(|| {
        format!(
            "residual speed line at order {order} only {ratio:.0}× the median, below {factor:.0}×"
        )
    })
}

/// The residual signal and the order per revolution at which an angle-locked candidate
/// shows; `None` for the others.
fn angle_locked_order(c: &Candidate, rig: &Rig) -> Option<(&'static str, u32)> {
    let pp = rig.motor.pole_pairs;
    Some(match (c.name, c.structure) {
        ("cogging_torque", super::candidates::Structure::Order(k)) => ("speed_rad_s", k),
        ("flux_harmonics", _) => ("speed_rad_s", 6 * pp),
        ("current_sensor_offset", _) => ("speed_rad_s", pp),
        // The flow ripple shows in the pressure, the torque ripple in the shaft speed.
        ("piston_ripple", super::candidates::Structure::Pistons(z)) => match c.predictor {
            Predictor::InnerLoops => ("speed_rad_s", ripple_order(z)),
            _ => ("p_pa", ripple_order(z)),
        },
        _ => return None,
    })
}

/// A line of evidence from the residual spectrum for an angle-locked candidate.
fn order_evidence(
    c: &Candidate,
    spectra: &[(&'static str, OrderSpectrum)],
    rig: &Rig,
) -> Option<String> {
    let (signal, order) = angle_locked_order(c, rig)?;
    let (_, s) = spectra.iter().find(|(n, _)| *n == signal)?;
    let floor = s.floor(1, 200);
    Some(format!(
        "residual {signal} line at order {order}: {:.3e} ({:.1}× the spectrum's median line)",
        s.at(order),
        s.at(order) / floor.max(f64::MIN_POSITIVE)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_speed_integrates_to_the_angle_turned() {
        // 1000 rows over 1 s: a ramp 0 → 20 rad/s turns ½·20·1 = 10 rad (trapezoids are
        // exact on a ramp), then 5 rad/s for another second turns 5 more.
        let t: Vec<f64> = (0..2001).map(|k| k as f64 * 1e-3).collect();
        let w: Vec<f64> = t
            .iter()
            .map(|&t| if t <= 1.0 { 20.0 * t } else { 5.0 })
            .collect();
        let th = integrated_angle(&t, &w).expect("rows");
        assert!((th[1000] - 10.0).abs() < 1e-9, "{}", th[1000]);
        // The one step from 20 to 5 rad/s is averaged: (20 + 5)/2·1 ms, then 999 ms at 5.
        let expected = 10.0 + 12.5e-3 + 5.0 * 0.999;
        assert!((th[2000] - expected).abs() < 1e-9, "{}", th[2000]);
        assert!(integrated_angle(&t[..1], &w[..1]).is_none());
    }
}
