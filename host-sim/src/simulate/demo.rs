//! `eha demo`: the paper's low-speed pressure holding in closed loop with and without the
//! absorber, a pressure step and a speed step — a summary table, the runs' bench logs and
//! SVG plots in an output folder.

use super::holding::pulsation;
use super::{converged, effects_text, plant_rig, rig_name, write_log, LOG_RATE_HZ};
use crate::output::paths::Declared;
use crate::output::{print_stdout, CliError};
use crate::plots::{line_chart, Marker, Series};
use crate::pulsation::sources;
use crate::run::{run, Run, RunOptions};
use clap::Args;
use closed_loop::{by_name, Scenario};
use plant_model::effects::paper_low_speed_effects;
use plant_model::{Effect, Rig};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::PathBuf;

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
        Declared::default().dir("--out", Some(&self.out))
    }
}

/// A demo run: plant rig, controller rig, scenario, duration [s], log metadata.
type Job<'a> = (&'a Rig, &'a Rig, &'a Scenario, f64, Vec<(String, String)>);

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
                    compensation: None,
                },
            )
        })
        .collect();
    let mut runs = runs.into_iter();
    let mut next = || {
        runs.next()
            .unwrap_or_else(|| Err("run missing".into()))
            .map_err(CliError::Failed)
            .and_then(converged)
    };
    let (with, without, stepped, sped) = (next()?, next()?, next()?, next()?);
    let pw = pulsation(&with, hold, &plant);
    let po = pulsation(&without, hold, &plant);
    // The torque feed-forward learned by the bench procedure (the drive's sweep and a
    // 12 s hold), then the holding again with it, with and without the absorber.
    let (ff_table, ff_logs) = crate::compensate::study::bench_learning(rig, &plant, 12.0)?;
    let ff_runs: Vec<Result<Run, String>> = [(&plant, rig), (&bare, &bare_controller)]
        .par_iter()
        .map(|(p, c)| {
            run(
                p,
                c,
                hold,
                &RunOptions {
                    duration_s: 4.0,
                    log_rate_hz: LOG_RATE_HZ,
                    seed: 1,
                    progress: false,
                    metadata: meta("pressure-hold", "feed-forward"),
                    compensation: Some(ff_table.clone()),
                },
            )
        })
        .collect();
    let mut ff_runs = ff_runs.into_iter();
    let mut next_ff = || {
        ff_runs
            .next()
            .unwrap_or_else(|| Err("run missing".into()))
            .map_err(CliError::Failed)
            .and_then(converged)
    };
    let (with_ff, without_ff) = (next_ff()?, next_ff()?);
    let pwf = pulsation(&with_ff, hold, &plant);
    let pof = pulsation(&without_ff, hold, &plant);
    let mut record = [0u8; firmware::compensation::record::RECORD_LEN];
    firmware::compensation::record::Encoder::write_all(&ff_table, &mut record);
    crate::output::atomic::write(&out.join("compensation.table"), &record).map_err(|source| {
        CliError::Write {
            file: out.join("compensation.table"),
            source,
        }
    })?;
    write_log(&out.join("compensation-sweep.csv"), &ff_logs[0])?;

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
    let fitted = format!("fitted, p0 {:.1} MPa", rig.absorber.precharge_pa / 1e6);
    for (label, p) in [
        (fitted.clone(), &pw),
        ("none".to_string(), &po),
        ("none + feed-forward".to_string(), &pof),
        (format!("{fitted} + ff"), &pwf),
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
        "torque feed-forward (learned by the bench sweep and a 12 s hold, compensation.table): pulsation {:.0} % less without the absorber, {:.0} % less with it; the rest is the pump's flow ripple and the loop's wander (docs/compensation.md)",
        cut(po.pp_pa, pof.pp_pa),
        cut(pw.pp_pa, pwf.pp_pa)
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
                    name: "measured (transducer), absorber fitted",
                    points: trace(&with, true),
                },
                Series {
                    name: "true, absorber fitted",
                    points: trace(&with, false),
                },
                Series {
                    name: "true, no absorber",
                    points: trace(&without, false),
                },
                Series {
                    name: "true, no absorber, torque feed-forward",
                    points: trace(&without_ff, false),
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
        "\nwritten to {}/: pressure-hold.csv (bench log), pressure-hold-no-absorber.csv, pressure-step.csv, speed-step.csv, compensation-sweep.csv, compensation.table, pressure_trace.svg, pulsation_spectrum.svg, pressure_step.svg, speed_step.svg",
        out.display()
    );
    print_stdout(&table)
}
