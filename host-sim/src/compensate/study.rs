//! The feed-forward's closed-loop study (`docs/compensation.md`): the paper's holding at
//! 5 MPa with cogging, flux harmonics and piston ripple at the nominal rig's values and at
//! three times them, the pulsation of the true pressure and shaft speed without and with
//! tables learned by the bench procedure, with and without the absorber; the same table
//! on a rig whose effects differ (±10 % amplitude, 10° phase), a table learned from a log
//! in the foreign-logs simulator's style (pressure control against the end stop, no
//! voltages), the histogram method beside the model-based one, and the ideal table from
//! the rig's own equations.
//!
//! Every run is the firmware's control core against the plant through `closed_loop`. The
//! learning logs use other noise seeds than the evaluation.

use super::learn::find;
use super::method::{feedforward_of, Method};
use super::predict::{self, Pulsation};
use super::{model, table};
use crate::bench_log::BenchLog;
use crate::feedforward::flow::{self, FlowParams};
use crate::feedforward::Feedforward;
use crate::output::CliError;
use crate::run::{run, RunOptions};
use closed_loop::scenario::HOLD_PRESSURE_PA;
use closed_loop::{by_name, Scenario, ScenarioKind};
use firmware::{Command, Mode};
use plant_model::pump::kinematic_ripple_ratio;
use plant_model::{Effect, Rig};
use rayon::prelude::*;
use std::fmt::Write as _;

/// A log in the style of the foreign-logs data set: blocked cylinder, pressure control
/// from the fill pressure, a ramp to 5 MPa, a hold, a step of +1 MPa, a hold; 20 s.
pub const FOREIGN_STYLE: Scenario = Scenario {
    name: "foreign-style",
    description: "pressure control from 0.5 MPa: ramp to 5 MPa, hold, step to 6 MPa, hold",
    kind: ScenarioKind::PressureStep,
    blocked: true,
    initial_pressure_pa: 0.5e6,
    duration_s: 20.0,
    steady_from_s: 1.0,
    events: [
        Some((0.0, Command::SetPressure { pa: 0.5e6 })),
        Some((0.0, Command::SetMode(Mode::Pressure))),
        Some((
            0.5,
            Command::SetPressure {
                pa: HOLD_PRESSURE_PA as f32,
            },
        )),
        Some((10.0, Command::SetPressure { pa: 6e6 })),
        None,
        None,
    ],
    profile: None,
};

/// Length of the learning hold at 5 MPa. [s]
pub const LEARNING_HOLD_S: f64 = 20.0;

/// The paper's three low-speed effects at `level` times the nominal rig's values, their
/// amplitudes further scaled by `amplitude` and their phases moved by `phase_rad` (the
/// pump's ripple has no phase in the plant: amplitude only).
pub fn effects(level: f64, amplitude: f64, phase_rad: f64) -> Vec<Effect> {
    vec![
        Effect::CoggingTorque {
            amplitude_nm: 0.05 * level * amplitude,
            order: 0,
            phase_rad,
        },
        Effect::FluxHarmonics {
            t6_ratio: 0.02 * level * amplitude,
            phase_rad,
        },
        Effect::PistonRipple {
            pistons: 9,
            amplitude_ratio: kinematic_ripple_ratio(9) * level * amplitude,
        },
    ]
}

/// `rig` with `effects` on.
pub fn with_effects(rig: &Rig, effects: &[Effect]) -> Rig {
    let mut r = rig.clone();
    for e in effects {
        e.apply(&mut r);
    }
    r
}

/// A run of `scenario` for `duration_s` logged at 1 kHz (a bench's rate) with noise seed
/// `seed`; `voltages` false drops the stator-voltage columns, as a foreign bench logs.
fn learning_log(
    plant: &Rig,
    controller: &Rig,
    scenario: &Scenario,
    duration_s: f64,
    seed: u64,
    voltages: bool,
) -> Result<BenchLog, CliError> {
    let r = run(
        plant,
        controller,
        scenario,
        &RunOptions {
            duration_s,
            log_rate_hz: 1000.0,
            seed,
            progress: false,
            metadata: vec![("source".into(), "compensation study".into())],
            compensation: None,
            integrator: Default::default(),
        },
    )
    .map_err(CliError::Failed)?;
    let mut log = r.log;
    if !voltages {
        (log.ud_v, log.uq_v, log.udc_v) = (None, None, None);
    }
    Ok(log)
}

/// The bench procedure's learning on `plant` (controller configured from `rig`): the
/// drive's sweep and a hold at 5 MPa of `hold_s`, logged at 1 kHz, and the model-based
/// feed-forward learned from them (table and speed modulation).
pub fn bench_learning(
    rig: &Rig,
    plant: &Rig,
    hold_s: f64,
) -> Result<(Feedforward, Vec<BenchLog>), CliError> {
    let scenario =
        |name| by_name(name).ok_or_else(|| CliError::Failed(format!("scenario {name} missing")));
    let jobs = [
        (scenario("compensation-sweep")?, 12.8, 2),
        (scenario("pressure-hold")?, hold_s, 3),
    ];
    let logs = jobs
        .par_iter()
        .map(|(sc, d, seed)| learning_log(plant, rig, sc, *d, *seed, true))
        .collect::<Result<Vec<_>, _>>()?;
    let found = find(&logs, rig)?;
    let ff = feedforward_of(&found, &logs, rig, Method::Model, &[])?;
    Ok((ff, logs))
}

/// The feed-forwards one effect level learns.
pub struct Tables {
    /// Model-based, from the bench sweep and a hold at 5 MPa: table and speed modulation.
    pub model: Feedforward,
    /// The same table without the speed modulation.
    pub model_torque_only: Feedforward,
    /// The same without the pump's ripple (which evens out the pump's flow): no
    /// modulation either.
    pub model_without_pump: Feedforward,
    /// The histogram method on the same logs.
    pub histogram: Feedforward,
    /// Model-based from the bench sweep alone (low pressure only).
    pub sweep_only: Feedforward,
    /// Model-based from a foreign-style log alone (no voltages).
    pub foreign: Feedforward,
    /// The rig's own equations (the ideal): table and modulation.
    pub ideal: Feedforward,
    /// The ideal table without the modulation.
    pub ideal_torque_only: Feedforward,
}

/// Learns every table of one effect level on `plant` (controller configured from `rig`).
pub fn learn_tables(rig: &Rig, plant: &Rig) -> Result<Tables, CliError> {
    let scenario =
        |name| by_name(name).ok_or_else(|| CliError::Failed(format!("scenario {name} missing")));
    let sweep_sc = scenario("compensation-sweep")?;
    let hold_sc = scenario("pressure-hold")?;
    let jobs: Vec<(&Scenario, f64, u64, bool)> = vec![
        (sweep_sc, sweep_sc.duration_s, 2, true),
        (hold_sc, LEARNING_HOLD_S, 3, true),
        (&FOREIGN_STYLE, FOREIGN_STYLE.duration_s, 4, false),
    ];
    let logs = jobs
        .par_iter()
        .map(|(sc, d, seed, v)| learning_log(plant, rig, sc, *d, *seed, *v))
        .collect::<Result<Vec<_>, _>>()?;
    let (sweep, hold, foreign) = (&logs[0], &logs[1], &logs[2]);
    let bench = [sweep.clone(), hold.clone()];
    let found = find(&bench, rig)?;
    let none: [String; 0] = [];
    let sweep_found = find(std::slice::from_ref(sweep), rig)?;
    let foreign_found = find(std::slice::from_ref(foreign), rig)?;
    let ideal = table::build(&model::channels_from_rig(plant, rig.fill.pressure_pa, &[]))
        .ok_or_else(|| CliError::Failed("the ideal table does not fit".into()))?;
    let ideal_flow = FlowParams::of_rig(plant).map(|f| FlowParams {
        inertia_kg_m2: plant.shaft.inertia_kg_m2(),
        ..f
    });
    Ok(Tables {
        model: feedforward_of(&found, &bench, rig, Method::Model, &none)?,
        model_torque_only: feedforward_of(
            &found,
            &bench,
            rig,
            Method::Model,
            &[flow::EXCLUDE_NAME.to_string()],
        )?,
        model_without_pump: feedforward_of(
            &found,
            &bench,
            rig,
            Method::Model,
            &["piston_ripple".to_string()],
        )?,
        histogram: feedforward_of(&found, &bench, rig, Method::Histogram, &none)?,
        sweep_only: feedforward_of(
            &sweep_found,
            std::slice::from_ref(sweep),
            rig,
            Method::Model,
            &none,
        )?,
        foreign: feedforward_of(
            &foreign_found,
            std::slice::from_ref(foreign),
            rig,
            Method::Model,
            &none,
        )?,
        ideal: Feedforward {
            table: ideal.clone(),
            flow: ideal_flow,
        },
        ideal_torque_only: Feedforward::table_only(ideal),
    })
}

/// `ff` with its speed modulation's phase moved by `cycle_deg` [°] of the ripple's cycle
/// (the phase error a pump mounted off the encoder's reference would leave).
pub fn with_flow_phase(ff: &Feedforward, cycle_deg: f64) -> Feedforward {
    let mut out = ff.clone();
    if let Some(f) = &mut out.flow {
        let order = plant_model::pump::ripple_order(f.pistons) as f64;
        f.phase_rad =
            (f.phase_rad + cycle_deg.to_radians() / order).rem_euclid(std::f64::consts::TAU);
    }
    out
}

/// One row of the study: a table (or none) on a plant.
#[derive(Clone, Debug)]
pub struct Row {
    /// Effect level (× the nominal rig's values).
    pub level: f64,
    /// Absorber fitted.
    pub absorber: bool,
    /// What was applied, in words.
    pub label: String,
    /// The holding's pulsation.
    pub pulsation: Pulsation,
    /// The same plant without a table (the reference of the reductions).
    pub reference: Pulsation,
}

/// The rows of one effect level.
pub fn rows_for(rig: &Rig, level: f64) -> Result<Vec<Row>, CliError> {
    let plant = with_effects(rig, &effects(level, 1.0, 0.0));
    let t = learn_tables(rig, &plant)?;
    let ten = 10f64.to_radians();
    let plus = with_effects(rig, &effects(level, 1.1, ten));
    let minus = with_effects(rig, &effects(level, 0.9, -ten));
    let mut out = Vec::new();
    for absorber in [true, false] {
        let fit = |r: &Rig| {
            let mut r = r.clone();
            r.absorber.enabled = absorber;
            r
        };
        let controller = fit(rig);
        let late = with_flow_phase(&t.model, 10.0);
        let cases: Vec<(&str, Rig, Option<&Feedforward>)> = vec![
            ("none", fit(&plant), None),
            (
                "model + speed modulation (bench sweep + 5 MPa hold)",
                fit(&plant),
                Some(&t.model),
            ),
            (
                "model, torque table only",
                fit(&plant),
                Some(&t.model_torque_only),
            ),
            (
                "model + modulation 10° (of the ripple cycle) late",
                fit(&plant),
                Some(&late),
            ),
            (
                "model without the pump's ripple",
                fit(&plant),
                Some(&t.model_without_pump),
            ),
            (
                "histogram (bench sweep + 5 MPa hold)",
                fit(&plant),
                Some(&t.histogram),
            ),
            ("model (bench sweep only)", fit(&plant), Some(&t.sweep_only)),
            (
                "model (foreign-style log, no voltages)",
                fit(&plant),
                Some(&t.foreign),
            ),
            (
                "ideal (the rig's own equations) + modulation",
                fit(&plant),
                Some(&t.ideal),
            ),
            (
                "ideal torque table only",
                fit(&plant),
                Some(&t.ideal_torque_only),
            ),
            ("none, effects +10 %, +10°", fit(&plus), None),
            ("model on effects +10 %, +10°", fit(&plus), Some(&t.model)),
            ("none, effects −10 %, −10°", fit(&minus), None),
            ("model on effects −10 %, −10°", fit(&minus), Some(&t.model)),
        ];
        let results = cases
            .par_iter()
            .map(|(_, p, table)| predict::holding(p, &controller, *table, 1))
            .collect::<Result<Vec<_>, _>>()?;
        let mut reference = results[0];
        for ((label, _, table), p) in cases.iter().zip(results) {
            if table.is_none() {
                reference = p;
            }
            out.push(Row {
                level,
                absorber,
                label: label.to_string(),
                pulsation: p,
                reference,
            });
        }
    }
    Ok(out)
}

/// The study's rows as markdown tables, one per effect level and absorber.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::new();
    let mut keys: Vec<(u64, bool)> = rows
        .iter()
        .map(|r| (r.level.to_bits(), r.absorber))
        .collect();
    keys.dedup();
    for (level, absorber) in keys {
        let level = f64::from_bits(level);
        let _ = writeln!(
            s,
            "\nHolding at 5 MPa, effects at {level}× the nominal rig, absorber {}:\n",
            if absorber { "fitted (3 MPa)" } else { "none" }
        );
        let _ = writeln!(
            s,
            "| table | p pp [Pa] | p angle-locked pp [Pa] | ω pp [rad/s] | ω angle-locked pp [rad/s] |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|");
        for r in rows
            .iter()
            .filter(|r| r.level == level && r.absorber == absorber)
        {
            let (p, q) = (&r.pulsation, &r.reference);
            let cell = |v: f64, without: f64, digits: usize| {
                if std::ptr::eq(p, q) || r.label.starts_with("none") {
                    format!("{v:.digits$}")
                } else {
                    format!(
                        "{v:.digits$} ({:+.0} %)",
                        -predict::reduction_percent(without, v)
                    )
                }
            };
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} |",
                r.label,
                cell(p.pressure_pp_pa, q.pressure_pp_pa, 0),
                cell(p.pressure_locked_pp_pa, q.pressure_locked_pp_pa, 1),
                cell(p.speed_pp_rad_s, q.speed_pp_rad_s, 3),
                cell(p.speed_locked_pp_rad_s, q.speed_locked_pp_rad_s, 3),
            );
        }
    }
    s
}
