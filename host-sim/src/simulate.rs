//! The closed-loop commands: `eha simulate` (a named scenario to a bench log), `eha demo`
//! (the paper's low-speed pressure holding with its summary, plots and log) and
//! `eha sweep-precharge` (Section 5.2 / Figure 12: pulsation against absorber precharge).
//!
//! Pulsation is measured on the plant's true port pressure over the steady window (the
//! measured pressure adds the transducer's noise and 477 Pa quantisation, which would
//! dominate the peak-to-peak at these amplitudes; both are in the bench log).

use crate::bench_log::{self, BenchLog};
use crate::cli::{print_stdout, write_json, CliError, DemoArgs, SimulateArgs, SweepPrechargeArgs};
use crate::plots::{line_chart, Marker, Series};
use crate::pulsation::{amplitude_spectrum, dominant_line, peak_to_peak, sources, Source};
use crate::rig_file;
use crate::run::{run, Run, RunOptions};
use closed_loop::{by_name, Scenario, SCENARIOS};
use plant_model::effects::paper_low_speed_effects;
use plant_model::{Effect, Rig};
use rayon::prelude::*;
use serde_json::json;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A demo run: plant rig, controller rig, scenario, duration [s], log metadata.
type Job<'a> = (&'a Rig, &'a Rig, &'a Scenario, f64, Vec<(String, String)>);
/// A sweep result: precharge (None for the reference without absorber), run, figures.
type SweepPoint = (Option<f64>, Run, Pulsation);

/// Log rate of the simulated bench logs. [Hz]
pub const LOG_RATE_HZ: f64 = 2000.0;

fn rig_name(rig: &Rig) -> &'static str {
    if *rig == Rig::nominal() {
        "nominal"
    } else {
        "file"
    }
}

fn effects_text(effects: &[Effect]) -> String {
    if effects.is_empty() {
        return "none".into();
    }
    effects
        .iter()
        .map(|e| {
            let params: Vec<String> = e
                .parameters()
                .iter()
                .flatten()
                .map(|(k, v)| format!("{k}={v}"))
                .collect();
            if params.is_empty() {
                e.name().to_string()
            } else {
                format!("{}:{}", e.name(), params.join(","))
            }
        })
        .collect::<Vec<_>>()
        .join(";")
}

/// The plant rig: `rig` with `effects` switched on, validated.
fn plant_rig(rig: &Rig, effects: &[Effect]) -> Result<Rig, CliError> {
    let mut r = rig.clone();
    for e in effects {
        e.apply(&mut r);
    }
    r.validate()
        .map_err(|e| CliError::BadInput(format!("with the requested effects, {e}")))?;
    Ok(r)
}

fn steady<'a>(run: &'a Run, scenario: &Scenario) -> (Vec<f64>, &'a [f64]) {
    let t0 = scenario.steady_from_s;
    let first = run.log.t_s.iter().position(|t| *t >= t0).unwrap_or(0);
    (
        run.p_true_pa[first..].to_vec(),
        &run.speed_true_rad_s[first..],
    )
}

/// Steady-state pulsation figures of a holding run.
struct Pulsation {
    mean_pa: f64,
    pp_pa: f64,
    speed_rad_s: f64,
    dominant_hz: f64,
    dominant_amp_pa: f64,
    cause: Option<Source>,
    spectrum: Vec<(f64, f64)>,
}

fn pulsation(run: &Run, scenario: &Scenario, rig: &Rig) -> Pulsation {
    let (p, w) = steady(run, scenario);
    let mean = p.iter().sum::<f64>() / p.len().max(1) as f64;
    let speed = w.iter().sum::<f64>() / w.len().max(1) as f64;
    let spectrum = amplitude_spectrum(&p, 1.0 / LOG_RATE_HZ);
    let rev_s = speed / (2.0 * std::f64::consts::PI);
    let (f, a, cause) =
        dominant_line(&spectrum, 0.5, rev_s, &sources(rig)).unwrap_or((0.0, 0.0, None));
    Pulsation {
        mean_pa: mean,
        pp_pa: peak_to_peak(&p),
        speed_rad_s: speed,
        dominant_hz: f,
        dominant_amp_pa: a,
        cause,
        spectrum,
    }
}

fn holding_run(
    plant: &Rig,
    controller: &Rig,
    duration_s: f64,
    metadata: Vec<(String, String)>,
) -> Result<Run, CliError> {
    let scenario = by_name("pressure-hold")
        .ok_or_else(|| CliError::Failed("pressure-hold scenario missing".into()))?;
    run(
        plant,
        controller,
        scenario,
        &RunOptions {
            duration_s,
            log_rate_hz: LOG_RATE_HZ,
            seed: 1,
            progress: true,
            metadata,
        },
    )
    .map_err(CliError::Failed)
}

fn write_log(path: &Path, log: &BenchLog) -> Result<(), CliError> {
    bench_log::write(path, log)?;
    Ok(())
}

/// `eha simulate`.
pub fn run_simulate(rig: &Rig, args: &SimulateArgs) -> Result<(), CliError> {
    if args.list {
        let mut s = String::new();
        for sc in &SCENARIOS {
            let _ = writeln!(
                s,
                "{:<15} {:>4.1} s  {}",
                sc.name, sc.duration_s, sc.description
            );
        }
        return print_stdout(&s);
    }
    let name = args.scenario.as_deref().unwrap_or_default();
    let scenario = by_name(name).ok_or_else(|| {
        let names: Vec<&str> = SCENARIOS.iter().map(|s| s.name).collect();
        CliError::BadInput(format!(
            "unknown scenario `{name}`: the scenarios are {} (see `eha simulate --list`)",
            names.join(", ")
        ))
    })?;
    let out = args
        .out
        .as_ref()
        .ok_or_else(|| CliError::BadInput("--out LOG.csv is required".into()))?;
    let mut controller = rig.clone();
    if let Some(p0) = args.precharge {
        controller.absorber.precharge_pa = p0;
    }
    controller
        .validate()
        .map_err(|e| CliError::BadInput(format!("{e}")))?;
    let effects = args
        .effects
        .as_ref()
        .map(|e| e.0.clone())
        .unwrap_or_default();
    // The plant is the controller's rig unless the bench's actuator is given apart.
    let plant = match &args.plant_rig {
        Some(path) => plant_rig(&rig_file::load(path)?, &effects)?,
        None => plant_rig(&controller, &effects)?,
    };
    let duration = args.duration.unwrap_or(scenario.duration_s);
    let seed = args.seed.unwrap_or(1);
    let mut metadata = vec![
        ("source".into(), "simulation".into()),
        ("rig".into(), rig_name(rig).into()),
        ("scenario".into(), scenario.name.into()),
        ("effects".into(), effects_text(&effects)),
        (
            "precharge_pa".into(),
            format!("{}", controller.absorber.precharge_pa),
        ),
        ("seed".into(), format!("{seed}")),
    ];
    if let Some(path) = &args.plant_rig {
        metadata.push(("plant_rig".into(), path.display().to_string()));
    }
    let r = run(
        &plant,
        &controller,
        scenario,
        &RunOptions {
            duration_s: duration,
            log_rate_hz: args.log_rate,
            seed,
            progress: true,
            metadata,
        },
    )
    .map_err(CliError::Failed)?;
    write_log(out, &r.log)?;
    eprintln!(
        "{}: {} rows over {duration} s written to {} ({:.0}× real time)",
        scenario.name,
        r.log.len(),
        out.display(),
        r.real_time_factor
    );
    if let Some(json_path) = &args.json {
        write_json(
            json_path,
            &json!({
                "scenario": scenario.name,
                "duration_s": duration,
                "rows": r.log.len(),
                "out": out.display().to_string(),
                "real_time_factor": r.real_time_factor,
            }),
        )?;
    }
    Ok(())
}

/// `eha demo`.
pub fn run_demo(rig: &Rig, args: &DemoArgs) -> Result<(), CliError> {
    let out = &args.out;
    std::fs::create_dir_all(out).map_err(|source| CliError::Write {
        file: out.clone(),
        source,
    })?;
    let effects: Vec<Effect> = paper_low_speed_effects().to_vec();
    let plant = plant_rig(rig, &effects)?;
    // The reference is the rig without absorber, its controller configured for that rig
    // (the pressure loop's schedule then sees only the oil's capacitance).
    let mut bare = plant.clone();
    bare.absorber.enabled = false;
    let mut bare_controller = rig.clone();
    bare_controller.absorber.enabled = false;
    let hold =
        by_name("pressure-hold").ok_or_else(|| CliError::Failed("scenario missing".into()))?;
    let step =
        by_name("pressure-step").ok_or_else(|| CliError::Failed("scenario missing".into()))?;
    let speed_step =
        by_name("speed-step").ok_or_else(|| CliError::Failed("scenario missing".into()))?;
    let meta = |scenario: &str, absorber: &str| {
        vec![
            ("source".to_string(), "simulation".to_string()),
            ("rig".into(), rig_name(rig).into()),
            ("scenario".into(), scenario.into()),
            ("effects".into(), effects_text(&effects)),
            ("absorber".into(), absorber.into()),
        ]
    };
    // Three runs in parallel: holding with and without the absorber, and a pressure step.
    let jobs: Vec<Job> = vec![
        (&plant, rig, hold, 4.0, meta("pressure-hold", "fitted")),
        (
            &bare,
            &bare_controller,
            hold,
            4.0,
            meta("pressure-hold", "none"),
        ),
        (
            &plant,
            rig,
            step,
            step.duration_s,
            meta("pressure-step", "fitted"),
        ),
        (&plant, rig, speed_step, 0.4, meta("speed-step", "fitted")),
    ];
    let runs: Vec<Result<Run, String>> = jobs
        .par_iter()
        .map(|(p, c, sc, d, m)| {
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
                },
            )
        })
        .collect();
    let mut runs = runs.into_iter();
    let mut next = || {
        runs.next()
            .unwrap_or_else(|| Err("run missing".into()))
            .map_err(CliError::Failed)
    };
    let (with, without, stepped, sped) = (next()?, next()?, next()?, next()?);
    let pw = pulsation(&with, hold, &plant);
    let po = pulsation(&without, hold, &plant);

    let log_path = out.join("pressure-hold.csv");
    write_log(&log_path, &with.log)?;
    write_log(&out.join("pressure-hold-no-absorber.csv"), &without.log)?;
    write_log(&out.join("pressure-step.csv"), &stepped.log)?;
    write_log(&out.join("speed-step.csv"), &sped.log)?;

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
    for (label, p) in [
        (
            format!("fitted, p0 {:.1} MPa", rig.absorber.precharge_pa / 1e6),
            &pw,
        ),
        ("none".to_string(), &po),
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

    // Plots.
    let t_from = hold.steady_from_s;
    let trace = |r: &Run, measured: bool| -> Vec<(f64, f64)> {
        r.log
            .t_s
            .iter()
            .enumerate()
            .filter(|(_, t)| **t >= t_from)
            .map(|(i, t)| {
                (
                    *t,
                    if measured {
                        r.log.p_pa[i]
                    } else {
                        r.p_true_pa[i]
                    } / 1e6,
                )
            })
            .collect()
    };
    let plot = |name: &str, res: Result<(), String>| {
        res.map_err(|e| CliError::Failed(format!("{name}: {e}")))
    };
    plot(
        "pressure trace",
        line_chart(
            &out.join("pressure_trace.svg"),
            "Port-A pressure, holding at 5 MPa",
            "t [s]",
            "p [MPa]",
            &[
                Series {
                    name: "true, absorber fitted",
                    points: trace(&with, false),
                },
                Series {
                    name: "true, no absorber",
                    points: trace(&without, false),
                },
                Series {
                    name: "measured (transducer), absorber fitted",
                    points: trace(&with, true),
                },
            ],
            &[],
            false,
        ),
    )?;
    let rev_s = pw.speed_rad_s / (2.0 * std::f64::consts::PI);
    let srcs = sources(&plant);
    let markers: Vec<Marker> = srcs
        .iter()
        .map(|s| Marker {
            x: s.order * rev_s,
            label: s.cause,
        })
        .collect();
    plot(
        "spectrum",
        line_chart(
            &out.join("pulsation_spectrum.svg"),
            "Pressure pulsation spectrum (true p_A, steady state) with the physical orders",
            "f [Hz]",
            "amplitude [Pa]",
            &[
                Series {
                    name: "absorber fitted",
                    points: pw
                        .spectrum
                        .iter()
                        .copied()
                        .filter(|(f, _)| *f <= 150.0)
                        .collect(),
                },
                Series {
                    name: "no absorber",
                    points: po
                        .spectrum
                        .iter()
                        .copied()
                        .filter(|(f, _)| *f <= 150.0)
                        .collect(),
                },
            ],
            &markers,
            true,
        ),
    )?;
    plot(
        "step response",
        line_chart(
            &out.join("pressure_step.svg"),
            "Pressure step 3 → 5 MPa (blocked cylinder)",
            "t [s]",
            "p [MPa]",
            &[
                Series {
                    name: "setpoint",
                    points: stepped
                        .log
                        .t_s
                        .iter()
                        .zip(&stepped.log.p_ref_pa)
                        .map(|(t, p)| (*t, p / 1e6))
                        .collect(),
                },
                Series {
                    name: "true p_A",
                    points: stepped
                        .log
                        .t_s
                        .iter()
                        .zip(&stepped.p_true_pa)
                        .map(|(t, p)| (*t, p / 1e6))
                        .collect(),
                },
            ],
            &[],
            false,
        ),
    )?;
    let speed_ref = sped.log.speed_ref_rad_s.clone().unwrap_or_default();
    plot(
        "speed step",
        line_chart(
            &out.join("speed_step.svg"),
            "Speed step 0 → 50 rad/s (payload free)",
            "t [s]",
            "speed [rad/s], q-current [A]",
            &[
                Series {
                    name: "speed reference",
                    points: sped
                        .log
                        .t_s
                        .iter()
                        .zip(&speed_ref)
                        .map(|(t, w)| (*t, *w))
                        .collect(),
                },
                Series {
                    name: "true shaft speed",
                    points: sped
                        .log
                        .t_s
                        .iter()
                        .zip(&sped.speed_true_rad_s)
                        .map(|(t, w)| (*t, *w))
                        .collect(),
                },
                Series {
                    name: "measured q-current",
                    points: sped
                        .log
                        .t_s
                        .iter()
                        .zip(&sped.log.iq_a)
                        .map(|(t, i)| (*t, *i))
                        .collect(),
                },
            ],
            &[],
            false,
        ),
    )?;
    let _ = writeln!(
        table,
        "\nwritten to {}/: pressure-hold.csv (bench log), pressure-hold-no-absorber.csv, pressure-step.csv, speed-step.csv, pressure_trace.svg, pulsation_spectrum.svg, pressure_step.svg, speed_step.svg",
        out.display()
    );
    print_stdout(&table)
}

/// `eha sweep-precharge`.
pub fn run_sweep_precharge(rig: &Rig, args: &SweepPrechargeArgs) -> Result<(), CliError> {
    if args.values.is_empty() {
        return Err(CliError::BadInput(
            "--values needs at least one precharge".into(),
        ));
    }
    let effects: Vec<Effect> = paper_low_speed_effects().to_vec();
    let hold =
        by_name("pressure-hold").ok_or_else(|| CliError::Failed("scenario missing".into()))?;
    let duration = 4.0;
    // Reference: the same run without the absorber; then one run per precharge, all in parallel.
    let mut jobs: Vec<(Option<f64>, Rig, Rig)> = Vec::new();
    let mut bare = plant_rig(rig, &effects)?;
    bare.absorber.enabled = false;
    let mut bare_controller = rig.clone();
    bare_controller.absorber.enabled = false;
    jobs.push((None, bare, bare_controller));
    for &p0 in &args.values {
        let mut controller = rig.clone();
        controller.absorber.precharge_pa = p0;
        controller
            .validate()
            .map_err(|e| CliError::BadInput(format!("precharge {p0} Pa: {e}")))?;
        let plant = plant_rig(&controller, &effects)?;
        jobs.push((Some(p0), plant, controller));
    }
    let results: Vec<Result<SweepPoint, CliError>> = jobs
        .par_iter()
        .map(|(p0, plant, controller)| {
            let meta = vec![
                ("source".to_string(), "simulation".to_string()),
                ("scenario".into(), "pressure-hold".into()),
                ("effects".into(), effects_text(&effects)),
                (
                    "precharge_pa".into(),
                    p0.map(|p| format!("{p}"))
                        .unwrap_or_else(|| "no absorber".into()),
                ),
            ];
            let r = holding_run(plant, controller, duration, meta)?;
            let p = pulsation(&r, hold, plant);
            Ok((*p0, r, p))
        })
        .collect();
    let mut reference = None;
    let mut points = Vec::new();
    for r in results {
        let (p0, run, p) = r?;
        match p0 {
            None => reference = Some((run, p)),
            Some(v) => points.push((v, run, p)),
        }
    }
    let (ref_run, ref_p) =
        reference.ok_or_else(|| CliError::Failed("reference run missing".into()))?;
    let mut table = format!(
        "Precharge sweep, low-speed holding at 5 MPa (Section 5.2); without absorber: {:.0} Pa peak-to-peak\n\n{:>10} {:>14} {:>11} {:>16} {:>9} {:>28}\n",
        ref_p.pp_pa, "precharge", "pulsation pp", "absorption", "natural freq.", "damping", "dominant line"
    );
    let mut json_points = Vec::new();
    for (p0, run, p) in &points {
        let absorption = 100.0 * (1.0 - p.pp_pa / ref_p.pp_pa);
        let cause = p.cause.map(|s| s.cause).unwrap_or("unattributed");
        let _ = writeln!(
            table,
            "{:>6.1} MPa {:>11.0} Pa {:>9.0} % {:>13.1} Hz {:>9.2} {:>10.1} Hz {}",
            p0 / 1e6,
            p.pp_pa,
            absorption,
            run.absorber_fn_hz,
            run.absorber_zeta,
            p.dominant_hz,
            cause
        );
        json_points.push(json!({
            "precharge_pa": p0,
            "pulsation_pp_pa": p.pp_pa,
            "absorption_percent": absorption,
            "natural_frequency_hz": run.absorber_fn_hz,
            "damping_ratio": run.absorber_zeta,
            "mean_pressure_pa": p.mean_pa,
            "absorber_holds_oil": run.absorber_fn_hz > 0.0,
            "dominant_frequency_hz": p.dominant_hz,
            "dominant_amplitude_pa": p.dominant_amp_pa,
            "dominant_cause": cause,
            "real_time_factor": run.real_time_factor,
        }));
    }
    table.push_str(
        "\nNatural frequency and damping are the absorber's (inlet inertance against the gas) at the run's mean pressure; 0 where the precharge is at or above it and the absorber holds no oil.\n",
    );
    if let Some(dir) = &args.out {
        write_sweep_outputs(dir, &ref_run, &points)?;
        let _ = writeln!(table, "bench logs and plots written to {}/", dir.display());
    }
    if let Some(path) = &args.json {
        write_json(
            path,
            &json!({
                "points": json_points,
                "reference_pulsation_pp_pa": ref_p.pp_pa,
                "holding_pressure_pa": 5e6,
                "duration_s": duration,
                "steady_from_s": hold.steady_from_s,
                "pulsation_signal": "true port-A pressure of the plant",
            }),
        )?;
        if crate::cli::is_stdout(path) {
            return Ok(());
        }
    }
    print_stdout(&table)
}

fn write_sweep_outputs(
    dir: &PathBuf,
    reference: &Run,
    points: &[(f64, Run, Pulsation)],
) -> Result<(), CliError> {
    std::fs::create_dir_all(dir).map_err(|source| CliError::Write {
        file: dir.clone(),
        source,
    })?;
    write_log(&dir.join("no-absorber.csv"), &reference.log)?;
    let mut traces = vec![Series {
        name: "no absorber",
        points: window(reference),
    }];
    let names: Vec<String> = points
        .iter()
        .map(|(p0, _, _)| format!("p0 = {:.1} MPa", p0 / 1e6))
        .collect();
    for ((p0, run, _), name) in points.iter().zip(&names) {
        write_log(
            &dir.join(format!("precharge-{:.1}MPa.csv", p0 / 1e6)),
            &run.log,
        )?;
        traces.push(Series {
            name,
            points: window(run),
        });
    }
    line_chart(
        &dir.join("pressure_traces.svg"),
        "Steady holding pressure per absorber precharge (true p_A)",
        "t [s]",
        "p [MPa]",
        &traces,
        &[],
        false,
    )
    .map_err(CliError::Failed)?;
    line_chart(
        &dir.join("sweep.svg"),
        "Pulsation peak-to-peak against precharge (holding at 5 MPa)",
        "precharge [MPa]",
        "pulsation pp [Pa]",
        &[Series {
            name: "with absorber",
            points: points
                .iter()
                .map(|(p0, _, p)| (p0 / 1e6, p.pp_pa))
                .collect(),
        }],
        &[],
        true,
    )
    .map_err(CliError::Failed)
}

fn window(r: &Run) -> Vec<(f64, f64)> {
    r.log
        .t_s
        .iter()
        .zip(&r.p_true_pa)
        .filter(|(t, _)| **t >= 2.0 && **t <= 2.5)
        .map(|(t, p)| (*t, p / 1e6))
        .collect()
}
