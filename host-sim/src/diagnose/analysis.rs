//! The diagnosis as a list of stages, each a module of its own, data passed forward:
//!
//! 1. [`super::facts`]: the log's sampling, shaft angle, low-side pressure, noise levels,
//!    segments (identification = first half, validation = second) and steady windows.
//! 2. [`super::calibration`]: each parity relation the log supports (hydraulic, mechanical,
//!    electrical, cylinder) fitted within the rig's tolerance bands: the baseline.
//! 3. [`super::lines`]: the angle-locked lines of the steady windows, read with the
//!    calibrated shaft constants.
//! 4. [`super::candidates`]: every effect of the catalogue tested on its relation or lines.
//! 5. [`super::decision`]: significance, band, validation and vetoes; the named effect.
//! 6. [`super::predictions`]: the contract's per-signal predictions of the baseline and the
//!    extended model, scored on the validation segment.
//! 7. [`super::result`]: the scores, the evidence for the report (residual signatures and
//!    order spectra of the baseline) and the contract's result.

use super::angle_locked::{EmfLines, LineReading, ShaftConstants};
use super::calibration::{calibrate, polished, test_release_at_nominal, Release};
use super::candidates::{test_lines, Extension, Tested};
use super::contributions::contributions;
use super::cylinder::{self};
use super::diagnosis::Diagnosis;
use super::displacement;
use super::error::DiagnoseError;
use super::facts::LogFacts;
use super::findings::{trace_step, traced_all, Analysis};
use super::lines::window_lines;
use super::mechanical::ShaftMotion;
use super::mechanical_relation::mech;
use super::predictions::{predict, Context, ModelValues};
pub use super::relations::Precision;
use super::relations::{Calibrations, Relations};
use super::release_verdict::{from_release, test_relation};
use super::result::{assemble, calibration_values, extended_values, fit_each, fit_of, Scored};
use super::selection::select;
use crate::bench_log::{BenchLog, Signal};
use plant_model::Rig;
use std::path::Path;

/// Shortest interval between the rows the diagnosis reads (≈2 kHz, with room for a
/// 2 kHz logger's jitter): a faster log is read at about this interval, every k-th row as
/// logged, unfiltered, so the replays meet the measurement at the very instants it was
/// sampled. What a faster log adds is sensor noise the likelihood would count as evidence
/// against a model that is never exact (a pressure-sensor lag accused at 10 kHz), and rows
/// that cost time and memory; every effect of the catalogue shows below the 1 kHz this
/// keeps. [s]
pub const MIN_ANALYSED_INTERVAL_S: f64 = 0.45e-3;

/// Diagnoses `log` against the rig file `rig`.
pub fn diagnose(log: &BenchLog, rig: &Rig) -> Result<Diagnosis, DiagnoseError> {
    analyse(log, rig).map(|a| a.diagnosis)
}

/// Diagnoses `log` against `rig` with the fits driven to `precision`.
pub fn diagnose_to(
    log: &BenchLog,
    rig: &Rig,
    precision: Precision,
) -> Result<Diagnosis, DiagnoseError> {
    analyse_reporting(log, rig, precision, &|_: &'static str| {}).map(|a| a.diagnosis)
}

/// What the pipeline reports as it goes: one call per finished step, naming the step
/// that follows, [`STEPS`] calls in all.
pub trait Progress: Sync {
    /// A step finished; `next` is the one under way.
    fn step(&self, next: &'static str);
}

impl<F: Fn(&'static str) + Sync> Progress for F {
    fn step(&self, next: &'static str) {
        self(next)
    }
}

/// `value`, once `progress` has been told the step that made it finished.
fn reported<T>(progress: &dyn Progress, value: T, next: &'static str) -> T {
    progress.step(next);
    value
}

/// Steps [`analyse_reporting`] reports: the facts, four calibrations, the lines, four
/// relations' tests, the lines' tests, the predictions and the evidence.
pub const STEPS: u64 = 13;

/// Runs the whole diagnosis.
pub fn analyse(log: &BenchLog, rig: &Rig) -> Result<Analysis, DiagnoseError> {
    analyse_reporting(log, rig, Precision::Diagnosis, &|_: &'static str| {})
}

/// Stage 2: every relation calibrated, in parallel.
fn calibrate_all(r: &Relations<'_>, progress: &dyn Progress) -> Calibrations {
    let done = |c, next| reported(progress, c, next);
    let ((hydraulic, mechanical), (electrical, cylinder)) = rayon::join(
        || {
            rayon::join(
                || done(calibrate(&r.screened(&r.hydraulic), &r.h_id), "calibration"),
                || done(calibrate(&r.patient(&r.mechanical), &r.m_id), "calibration"),
            )
        },
        || {
            rayon::join(
                || {
                    let c = r
                        .electrical
                        .as_ref()
                        .map(|e| calibrate(&r.patient(e), &r.m_id));
                    reported(progress, c, "calibration")
                },
                || {
                    let c = r
                        .cylinder
                        .as_ref()
                        .map(|c| calibrate(&r.patient(c), &r.m_id));
                    reported(progress, c, "calibration")
                },
            )
        },
    );
    Calibrations {
        hydraulic,
        mechanical,
        electrical,
        cylinder,
    }
}

/// Stage 4: every effect tested on its relation, in parallel, each with its released
/// parameters.
fn test_relations(
    r: &Relations<'_>,
    cal: &Calibrations,
    facts: &LogFacts,
    rig: &Rig,
    progress: &dyn Progress,
) -> Vec<Tested> {
    let mut hyd_releases = vec![Release::Leakage, Release::BulkModulus, Release::SensorLag];
    if rig.absorber.enabled {
        hyd_releases.push(Release::Precharge);
    }
    // A piston that moves without its position logged: the volume balance lacks its
    // largest flow, and no hydraulic effect can be told from it. With it logged, the
    // balance is read for the position (`hydraulic::stroke`): the oil's compliance and the
    // absorber show there, but not the transducer's lag, and a leakage at a stroke's
    // steady port pressure is a flow in proportion to the speed, which the displacement's
    // tolerance band takes up as well.
    if facts.piston_unseen {
        hyd_releases.clear();
    } else if r.hydraulic.moving_piston() {
        hyd_releases.retain(|r| matches!(r, Release::BulkModulus | Release::Precharge));
    }
    let (h, m) = (&cal.hydraulic, &cal.mechanical);
    let ((mut tested, mech_tests), (elec_tests, cyl_tests)) = rayon::join(
        || {
            rayon::join(
                || {
                    let t = test_relation(
                        &r.screened(&r.hydraulic),
                        h,
                        &r.h_id,
                        &r.h_val,
                        &hyd_releases,
                        rig,
                    );
                    reported(progress, t, "testing effects")
                },
                || {
                    let rel = [Release::ShaftFriction];
                    let t =
                        test_relation(&r.patient(&r.mechanical), m, &r.m_id, &r.m_val, &rel, rig);
                    reported(progress, t, "testing effects")
                },
            )
        },
        || {
            rayon::join(
                || {
                    let t = match (&r.electrical, &cal.electrical) {
                        (Some(e), Some(c)) => test_relation(
                            &r.patient(e),
                            c,
                            &r.m_id,
                            &r.m_val,
                            &[Release::DeadTime],
                            rig,
                        ),
                        _ => Vec::new(),
                    };
                    reported(progress, t, "testing effects")
                },
                || {
                    let t = match (&r.cylinder, &cal.cylinder) {
                        (Some(y), Some(c)) => {
                            let y = r.patient(y);
                            // Along a one-way stroke the transducer's zero is the Coulomb
                            // force's pressure step: the friction at the rig file's zero.
                            let (t, at_zero) = test_release_at_nominal(
                                &y,
                                &r.m_id,
                                Release::CylinderFriction,
                                c,
                                cylinder::ix::ZERO,
                                y.relation.strokes_both_ways(),
                            );
                            let mut tested = from_release(&y, &t, &r.m_id, &r.m_val, rig);
                            if at_zero {
                                tested.evidence.push_str(&y.relation.zero_caveat());
                            }
                            vec![tested]
                        }
                        _ => Vec::new(),
                    };
                    reported(progress, t, "testing effects")
                },
            )
        },
    );
    tested.extend(mech_tests);
    tested.extend(elec_tests);
    tested.extend(cyl_tests);
    tested
}

/// Runs the whole diagnosis, reporting each finished step to `progress`. The diagnosis
/// explains what the loop did, never what it was asked: `log` may leave the pressure
/// setpoint's column empty ([`BenchLog::check_holding`]).
pub fn analyse_reporting(
    log: &BenchLog,
    rig: &Rig,
    precision: Precision,
    progress: &dyn Progress,
) -> Result<Analysis, DiagnoseError> {
    log.check_holding(
        Path::new("bench log being diagnosed"),
        &[Signal::PressureRef],
    )?;
    rig.validate()?;
    let thinned = log.thinned(MIN_ANALYSED_INTERVAL_S);
    let log = thinned.as_ref().unwrap_or(log);
    // Rows stamped off the even grid they were sampled on are read on it.
    let retimed = super::retime::on_even_grid(log);
    let log = retimed.as_ref().unwrap_or(log);
    // 1. Facts.
    let facts = LogFacts::of(log, rig);
    let motion = ShaftMotion::of(log, &facts, rig.motor.pole_pairs);
    let rel = Relations::of(log, &facts, &motion, rig, precision);
    progress.step("calibration");
    // The fits' vectors reused from the heap, until the predictions.
    let fit_stage = crate::memory::FitStage::begin();
    // 2. Calibration.
    let mut cal = calibrate_all(&rel, progress);
    // 3. Lines, read with the calibrated shaft.
    let shaft = shaft_constants(&cal, rig);
    let orders = &rel.orders;
    let lines = window_lines(log, &facts, rig, orders, shaft.kt, shaft.j, shaft.d_per_rad);
    let (line_id, line_val): (Vec<_>, Vec<_>) = lines
        .iter()
        .partition(|w| w.window.rows.start < facts.lines_split);
    progress.step("testing effects");
    // 4. Every effect tested; beside the tests, the baseline the report predicts with,
    // driven on from the screening's calibration (it depends on nothing they find).
    let (mut tested, base) = rayon::join(
        || test_relations(&rel, &cal, &facts, rig, progress),
        || {
            rel.reported_effort()
                .map(|effort| polished(&rel.hydraulic, &rel.h_id, &cal.hydraulic, effort))
        },
    );
    let line_tests = test_lines(
        &line_id,
        &line_val,
        rig,
        shaft,
        orders,
        LineReading {
            angle: facts.angle,
            emf: match &cal.electrical {
                Some(c) => EmfLines::Voltages(super::electrical::stator(&c.fitted.values)),
                None => EmfLines::Currents,
            },
        },
        cal.electrical.as_ref().map(|c| c.fitted.values.as_slice()),
    );
    tested.extend(line_tests);
    progress.step("predictions");
    // 5. Selection: every effect the log convicts.
    // A blocked cylinder's volume balance is read at the displacement the shaft fixes.
    let displacement = displacement::from_shaft(&cal.mechanical, cal.electrical.as_ref(), rig)
        .filter(|_| !facts.piston_moves);
    let (named, hydraulic_values) = select(&rel, &mut tested, rig, displacement);
    if let Some(base) = base {
        cal.hydraulic = base;
    }
    // The line bases served the fits; the predictions do not read them.
    rel.mechanical.forget_bases();
    drop(fit_stage);
    // 6. Predictions and scores.
    let ctx = Context {
        log,
        facts: &facts,
        motion: &motion,
        rig,
        electrical: rel.electrical.as_ref(),
        cylinder: rel.cylinder.as_ref(),
    };
    let (base_values, ext_values) =
        model_values(&cal, (&tested, &named), hydraulic_values, rig, shaft);
    // Beside the baseline's whole-log predictions (the evidence reads them), every other
    // model's signals are predicted and scored one at a time.
    let baseline = predict(&ctx, &base_values);
    let step = trace_step(facts.rows);
    let val = facts.validation();
    let base_fit = fit_of(log, &facts, &baseline, val.clone());
    let (ext_fit, ext_trace) = if named.is_empty() {
        (base_fit.clone(), traced_all(&baseline, step))
    } else {
        fit_each(&ctx, &ext_values, val, step)
    };
    let contributions = contributions(
        &ctx,
        (&facts, rig, shaft),
        (&tested, &named),
        &base_values,
        (&base_fit, &ext_fit),
    );
    progress.step("evidence");
    // The evidence reads the log, its facts and the baseline's predictions only.
    let calibration = calibration_values(&rel, &cal);
    drop(rel);
    drop(motion);
    let scored = Scored {
        baseline,
        base_fit,
        ext_fit,
        ext_trace,
        calibration,
    };
    let mut a = assemble(log, &facts, rig, &cal, tested, named, scored);
    a.contributions = contributions;
    progress.step("done");
    Ok(a)
}

/// The shaft's constants as the calibration fitted them: torque constant, inertia and the
/// pump's displacement per radian.
fn shaft_constants(cal: &Calibrations, rig: &Rig) -> ShaftConstants {
    let mv = &cal.mechanical.fitted.values;
    ShaftConstants {
        kt: 1.5 * rig.motor.pole_pairs as f64 * mv[mech::PSI],
        j: mv[mech::INERTIA],
        d_per_rad: mv[mech::DISPLACEMENT] / (2.0 * std::f64::consts::PI),
    }
}

/// The baseline's values (the calibration's) and the extended model's: the baseline with
/// every `named` effect's extension, and the hydraulic values the selection refitted
/// together (`hydraulic_values`) in place of the calibration's.
fn model_values(
    cal: &Calibrations,
    (tested, named): (&[Tested], &[usize]),
    hydraulic_values: Option<Vec<f64>>,
    rig: &Rig,
    shaft: ShaftConstants,
) -> (ModelValues, ModelValues) {
    let base_values = ModelValues {
        hydraulic: cal.hydraulic.fitted.values.clone(),
        mechanical: cal.mechanical.fitted.values.clone(),
        lines: Vec::new(),
        electrical: cal.electrical.as_ref().map(|c| c.fitted.values.clone()),
        cylinder: cal.cylinder.as_ref().map(|c| c.fitted.values.clone()),
        pressure_from_cylinder: named
            .iter()
            .any(|&i| matches!(tested[i].extension, Extension::Cylinder(_))),
    };
    let mut ext_values = base_values.clone();
    for &i in named {
        ext_values = extended_values(&ext_values, &tested[i].extension, rig, shaft);
    }
    if let Some(v) = hydraulic_values {
        ext_values.hydraulic = v;
    }
    (base_values, ext_values)
}
