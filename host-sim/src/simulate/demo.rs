//! `eha demo`: the paper's low-speed pressure holding in closed loop with and without the
//! absorber, each again with the torque feed-forward learned by the bench procedure
//! (`crate::compensate`), a pressure step and a speed step — a summary table, the runs' bench logs and
//! SVG plots in an output folder.

use super::holding::{pulsation, Pulsation};
use super::{converged, effects_text, plant_rig, rig_name};
use crate::bench_log::write_into;
use crate::feedforward::Feedforward;
use crate::output::paths::Declared;
use crate::output::{CliError, Outputs, StagedFolder};
use crate::plots::{line_chart, stacked_chart, Figure, Marker, Panel, Series};
use crate::pulsation::sources;
use crate::run::{run, Run, RunOptions, LOG_RATE_HZ};
use clap::Args;
use closed_loop::{by_name, Scenario};
use plant_model::effects::paper_low_speed_effects;
use plant_model::{Effect, Rig};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// `eha demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Output folder for plots and the bench log.
    #[arg(long, value_name = "DIR", default_value = "eha-out")]
    pub out: PathBuf,
}

impl DemoArgs {
    /// The files it writes.
    pub fn paths(&self) -> Declared<'_> {
        Declared::default().dir("--out", Some(&self.out), FILES)
    }
}

/// The files the demo writes into its folder (each figure an SVG and a PNG).
pub const FILES: &[&str] = &[
    "pressure-hold.csv",
    "pressure-hold-no-absorber.csv",
    "pressure-step.csv",
    "speed-step.csv",
    "compensation-sweep.csv",
    "compensation.table",
    "pressure_trace.svg",
    "pulsation_spectrum.svg",
    "pressure_step.svg",
    "speed_step.svg",
    "pressure_trace.png",
    "pulsation_spectrum.png",
    "pressure_step.png",
    "speed_step.png",
];

/// A demo run: plant rig, controller rig, scenario, duration [s], log metadata, the torque
/// feed-forward table loaded (if any).
type Job<'a> = (
    &'a Rig,
    &'a Rig,
    &'a Scenario,
    f64,
    Vec<(String, String)>,
    Option<&'a Feedforward>,
);

/// `eha demo`.
pub fn run_demo(rig: &Rig, args: &DemoArgs) -> Result<(), CliError> {
    let out = &args.out;
    let effects: Vec<Effect> = paper_low_speed_effects().to_vec();
    let plant = plant_rig(rig, &effects)?;
    let hold =
        by_name("pressure-hold").ok_or_else(|| CliError::Failed("scenario missing".into()))?;
    // The torque feed-forward and the speed modulation learned as a bench would: the
    // drive's sweep and a 12 s hold at 5 MPa, `eha compensate`'s model method.
    let (ff_table, ff_logs) = crate::compensate::study::bench_learning(rig, &plant, 12.0)?;
    let [with, without, with_ff, without_ff, stepped, sped] =
        demo_runs(rig, &plant, &effects, &ff_table)?;
    let pw = pulsation(&with, hold, &plant);
    let po = pulsation(&without, hold, &plant);
    let pwf = pulsation(&with_ff, hold, &plant);
    let pof = pulsation(&without_ff, hold, &plant);
    let table = summary(rig, out, &with, [&pw, &po, &pwf, &pof]);
    let mut outputs = Outputs::new();
    outputs.folder("--out", out, FILES, |d| {
        d.file("compensation.table", &ff_table.file_bytes())?;
        write_into(d, "compensation-sweep.csv", &ff_logs[0])?;
        write_into(d, "pressure-hold.csv", &with.log)?;
        write_into(d, "pressure-hold-no-absorber.csv", &without.log)?;
        write_into(d, "pressure-step.csv", &stepped.log)?;
        write_into(d, "speed-step.csv", &sped.log)?;
        let runs = Runs {
            with: &with,
            without: &without,
            without_ff: &without_ff,
            stepped: &stepped,
            sped: &sped,
        };
        figures(d, &runs, (&pw, &po), &plant, hold.steady_from_s)
    })?;
    outputs.print(&table);
    outputs.commit()
}

/// The demo's six closed-loop runs, in parallel: holding with and without the absorber,
/// each without and with the feed-forward `ff_table`, then a pressure step and a speed
/// step, all on `plant` (the rig with `effects`).
fn demo_runs(
    rig: &Rig,
    plant: &Rig,
    effects: &[Effect],
    ff_table: &Feedforward,
) -> Result<[Run; 6], CliError> {
    // The reference is the rig without absorber, its controller configured for that rig
    // (the pressure loop's schedule then sees only the oil's capacitance).
    let mut bare = plant.clone();
    bare.absorber.enabled = false;
    let mut bare_controller = rig.clone();
    bare_controller.absorber.enabled = false;
    let scenario =
        |name: &str| by_name(name).ok_or_else(|| CliError::Failed("scenario missing".into()));
    let (hold, step, speed_step) = (
        scenario("pressure-hold")?,
        scenario("pressure-step")?,
        scenario("speed-step")?,
    );
    let meta = |scenario: &str, absorber: &str| {
        vec![
            ("source".to_string(), "simulation".to_string()),
            ("rig".into(), rig_name(rig).into()),
            ("scenario".into(), scenario.into()),
            ("effects".into(), effects_text(rig, effects)),
            ("absorber".into(), absorber.into()),
        ]
    };
    let held = |p, c, absorber, table| (p, c, hold, 4.0, meta("pressure-hold", absorber), table);
    let jobs: Vec<Job> = vec![
        held(plant, rig, "fitted", None),
        held(&bare, &bare_controller, "none", None),
        held(plant, rig, "fitted, feed-forward", Some(ff_table)),
        held(
            &bare,
            &bare_controller,
            "none, feed-forward",
            Some(ff_table),
        ),
        (
            plant,
            rig,
            step,
            step.duration_s,
            meta("pressure-step", "fitted"),
            None,
        ),
        (
            plant,
            rig,
            speed_step,
            0.4,
            meta("speed-step", "fitted"),
            None,
        ),
    ];
    let runs: Vec<Result<Run, String>> = jobs
        .par_iter()
        .map(|(p, c, sc, d, m, table)| {
            run(
                p,
                c,
                sc,
                &RunOptions {
                    duration_s: *d,
                    log_rate_hz: LOG_RATE_HZ,
                    seed: 1,
                    progress: false,
                    metadata: m.clone(),
                    compensation: table.cloned(),
                    integrator: Default::default(),
                },
            )
        })
        .collect();
    let runs: Vec<Run> = runs
        .into_iter()
        .map(|r| r.map_err(CliError::Failed).and_then(|r| converged(r, None)))
        .collect::<Result<_, _>>()?;
    runs.try_into()
        .map_err(|_| CliError::Failed("run missing".into()))
}

/// The demo's summary table: the holding's pulsation with the absorber, without it, and
/// each with the feed-forward (`[with, without, with_ff, without_ff]`), the absorption and
/// the feed-forward's reduction, and what was written to `out`.
fn summary(rig: &Rig, out: &Path, with: &Run, p: [&Pulsation; 4]) -> String {
    let [pw, po, pwf, pof] = p;
    let mut table = String::new();
    let _ = writeln!(
        table,
        "EHA low-speed pressure holding (closed loop, firmware control core vs plant model; cogging, flux harmonics, piston ripple on)\n"
    );
    let _ = writeln!(
        table,
        "{:<24} {:>9} {:>11} {:>13} {:>11} {:>34} {:>11}",
        "absorber",
        "setpoint",
        "mean p",
        "pulsation pp",
        "dominant",
        "cause (order per rev)",
        "shaft"
    );
    let fitted = format!("fitted, p0 {:.1} MPa", rig.absorber.precharge_pa / 1e6);
    for (label, p) in [
        (fitted.clone(), pw),
        ("none".to_string(), po),
        ("none + feed-forward".to_string(), pof),
        (format!("{fitted} + ff"), pwf),
    ] {
        let cause = match p.cause {
            Some(s) => format!("{} ({:.0})", s.cause, s.order),
            None => {
                let order = p.dominant_hz / (p.speed_rad_s / (2.0 * std::f64::consts::PI));
                format!("unattributed ({order:.1})")
            }
        };
        let _ = writeln!(
            table,
            "{:<24} {:>5.2} MPa {:>7.4} MPa {:>9.0} Pa {:>8.1} Hz {:>34} {:>5.1} rpm",
            label,
            5.0,
            p.mean_pa / 1e6,
            p.pp_pa,
            p.dominant_hz,
            cause,
            p.speed_rad_s * 60.0 / (2.0 * std::f64::consts::PI)
        );
    }
    let absorption = if po.pp_pa > 0.0 {
        100.0 * (1.0 - pw.pp_pa / po.pp_pa)
    } else {
        0.0
    };
    let _ = writeln!(
        table,
        "\nabsorption {absorption:.0} %; absorber natural frequency {:.1} Hz, damping ratio {:.2} at the holding pressure; {:.0}× real time",
        with.absorber_fn_hz, with.absorber_zeta, with.real_time_factor
    );
    let cut =
        |without: f64, with: f64| crate::compensate::predict::reduction_percent(without, with);
    let _ = writeln!(
        table,
        "torque feed-forward and speed modulation against the pump's flow ripple (learned by the bench sweep and a 12 s hold, compensation.table): pulsation {:.0} % less without the absorber, {:.0} % less with it; what is left: docs/compensation.md",
        cut(po.pp_pa, pof.pp_pa),
        cut(pw.pp_pa, pwf.pp_pa)
    );

    let _ = writeln!(
        table,
        "\nwritten to {}/: pressure-hold.csv (bench log), pressure-hold-no-absorber.csv, pressure-step.csv, speed-step.csv, compensation-sweep.csv (the feed-forward's bench sweep), compensation.table, pressure_trace, pulsation_spectrum, pressure_step, speed_step (each .svg and .png)",
        out.display()
    );
    table
}

/// The demo's runs the figures show.
struct Runs<'a> {
    with: &'a Run,
    without: &'a Run,
    without_ff: &'a Run,
    stepped: &'a Run,
    sped: &'a Run,
}

/// Renders the demo's figures into `d`: the pressure trace, the pulsation spectrum with the
/// physical orders (`pw`, `po`: the holding's pulsation with and without the absorber),
/// the pressure step and the speed step.
fn figures(
    d: &StagedFolder,
    r: &Runs,
    (pw, po): (&Pulsation, &Pulsation),
    plant: &Rig,
    steady_from_s: f64,
) -> Result<(), CliError> {
    let plot = |name: &str, fig: Result<Figure, String>| {
        fig.map_err(|e| CliError::Failed(format!("plot `{name}`: {e}")))?
            .write_into(d, name)
    };
    plot(
        "pressure_trace.svg",
        pressure_figure(r.with, r.without, r.without_ff, steady_from_s),
    )?;
    let rev_s = pw.speed_rad_s / (2.0 * std::f64::consts::PI);
    let srcs = sources(plant);
    let markers: Vec<Marker> = srcs
        .iter()
        .map(|s| Marker {
            x: s.order * rev_s,
            label: s.cause,
        })
        .collect();
    let below_150_hz = |p: &super::holding::Pulsation| -> Vec<(f64, f64)> {
        p.spectrum
            .iter()
            .copied()
            .filter(|(f, _)| *f <= 150.0)
            .collect()
    };
    plot(
        "pulsation_spectrum.svg",
        line_chart(
            "Pressure pulsation spectrum (true p_A, steady state) with the physical orders",
            "f [Hz]",
            "amplitude [Pa]",
            &[
                Series {
                    name: "no absorber",
                    points: below_150_hz(po),
                },
                Series {
                    name: "absorber fitted",
                    points: below_150_hz(pw),
                },
            ],
            &markers,
            true,
        ),
    )?;
    let stepped = r.stepped;
    let mpa = |y: &[f64]| -> Vec<(f64, f64)> {
        stepped
            .log
            .t_s
            .iter()
            .zip(y)
            .map(|(t, p)| (*t, p / 1e6))
            .collect()
    };
    plot(
        "pressure_step.svg",
        line_chart(
            "Pressure step 3 → 5 MPa (blocked cylinder)",
            "t [s]",
            "p [MPa]",
            &[
                Series {
                    name: "setpoint",
                    points: mpa(&stepped.log.p_ref_pa),
                },
                Series {
                    name: "true p_A",
                    points: mpa(&stepped.p_true_pa),
                },
            ],
            &[],
            false,
        ),
    )?;
    plot("speed_step.svg", speed_figure(r.sped))
}

/// Seconds of the steady hold the pressure figure shows: enough for the slowest line
/// (the shaft's once per revolution at the demo's ~0.9 rev/s), few enough that each cycle
/// of the pump's and the motor's lines stays distinct.
const PRESSURE_FIGURE_S: f64 = 1.2;

/// The demo's point in one figure: the true port-A pressure with and without the absorber
/// about the 5 MPa setpoint, on a scale the pulsation fills; beneath it, on its own scale,
/// what the transducer reads with the absorber fitted (its noise and quantisation are
/// larger than the absorbed pulsation).
fn pressure_figure(
    with: &Run,
    without: &Run,
    without_ff: &Run,
    steady_from_s: f64,
) -> Result<Figure, String> {
    let t_end = with.log.t_s.last().copied().unwrap_or(0.0);
    let t_from = steady_from_s.max(t_end - PRESSURE_FIGURE_S);
    let kpa_about_5mpa = |t: &[f64], p: &[f64]| -> Vec<(f64, f64)> {
        t.iter()
            .zip(p)
            .filter(|(t, _)| **t >= t_from)
            .map(|(t, p)| (*t, (p - 5e6) / 1e3))
            .collect()
    };
    let truth = [
        Series {
            name: "true, no absorber",
            points: kpa_about_5mpa(&without.log.t_s, &without.p_true_pa),
        },
        // In the spectrum's order and colours: no absorber, absorber fitted, then the
        // feed-forward's run.
        Series {
            name: "true, absorber fitted",
            points: kpa_about_5mpa(&with.log.t_s, &with.p_true_pa),
        },
        Series {
            name: "true, no absorber, torque feed-forward",
            points: kpa_about_5mpa(&without_ff.log.t_s, &without_ff.p_true_pa),
        },
    ];
    let measured = [Series {
        name: "measured (transducer), absorber fitted",
        points: kpa_about_5mpa(&with.log.t_s, &with.log.p_pa),
    }];
    stacked_chart(
        "Port-A pressure holding 5 MPa: the pulsation with and without the absorber",
        "t [s]",
        &[
            Panel::new("true p - 5 MPa [kPa]", &truth).weight(3),
            Panel::new("measured p - 5 MPa [kPa]", &measured).weight(2),
        ],
    )
}

/// The speed step: reference and true speed above, the q current that drives it beneath,
/// each on its own scale.
fn speed_figure(sped: &Run) -> Result<Figure, String> {
    let t = &sped.log.t_s;
    let pairs = |y: &[f64]| -> Vec<(f64, f64)> { t.iter().zip(y).map(|(t, y)| (*t, *y)).collect() };
    let speed_ref = sped.log.speed_ref_rad_s.clone().unwrap_or_default();
    let speed = [
        Series {
            name: "speed reference",
            points: pairs(&speed_ref),
        },
        Series {
            name: "true shaft speed",
            points: pairs(&sped.speed_true_rad_s),
        },
    ];
    let current = [Series {
        name: "measured q current",
        points: pairs(&sped.log.iq_a),
    }];
    stacked_chart(
        "Speed step 0 → 50 rad/s (payload free)",
        "t [s]",
        &[
            Panel::new("speed [rad/s]", &speed).weight(3),
            Panel::new("q current [A]", &current).weight(2),
        ],
    )
}
