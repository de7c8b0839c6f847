//! `eha sweep-precharge`: the paper's precharge study (Section 5.2, Figure 12) — the
//! low-speed pressure holding run without absorber and once per absorber precharge, the
//! steady pulsation of each against the reference, with the absorber's natural frequency
//! and damping at the run's mean pressure; optionally the runs' bench logs and plots.

use crate::bench_log::write_into;
use crate::output::paths::Declared;
use crate::output::{is_stdout, CliError, Outputs, StagedFolder};
use crate::plots::{line_chart, Series};
use crate::run::Run;
use crate::simulate::holding::{holding_run, pulsation, Pulsation};
use crate::simulate::{effects_text, plant_rig};
use crate::values::{positive_f64, show};
use clap::Args;
use closed_loop::{by_name, Scenario};
use plant_model::effects::paper_low_speed_effects;
use plant_model::{Effect, Rig};
use rayon::prelude::*;
use serde_json::json;
use std::fmt::Write as _;
use std::path::PathBuf;

/// `eha sweep-precharge`.
#[derive(Debug, Args)]
pub struct SweepPrechargeArgs {
    /// Precharges (gauge) to run. [Pa]
    #[arg(
        long,
        value_name = "PA,PA,…",
        value_delimiter = ',',
        default_value = "2e6,4e6,5e6,10e6,13e6",
        value_parser = positive_f64, allow_negative_numbers = true
    )]
    pub values: Vec<f64>,
    /// Write the results as JSON (`-`: standard output).
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// Folder for plots and the runs' bench logs.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

impl SweepPrechargeArgs {
    /// The files it writes.
    pub fn paths(&self) -> Declared<'_> {
        Declared::default().file("--json", self.json.as_ref()).dir(
            "--out",
            self.out.as_ref(),
            FILES,
        )
    }
}

/// The files the sweep writes into its folder: a bench log per precharge and the reference
/// without absorber, the figures as SVG and PNG.
pub const FILES: &[&str] = &[
    "precharge-*MPa.csv",
    "no-absorber.csv",
    "pressure_traces.svg",
    "pressure_traces.png",
    "sweep.svg",
    "sweep.png",
];

/// Most precharges one sweep runs.
pub const MAX_POINTS: usize = 32;

/// Decimals of the MPa in the runs' file names: one, or as many as keep every name apart
/// (5.00 and 5.04 MPa would both be `precharge-5.0MPa.csv`).
fn file_decimals(values: impl Iterator<Item = f64> + Clone) -> usize {
    (1..=12)
        .find(|&d| {
            let names: Vec<String> = values
                .clone()
                .map(|v| format!("{:.*}", d, v / 1e6))
                .collect();
            names
                .iter()
                .enumerate()
                .all(|(i, n)| !names[..i].contains(n))
        })
        .unwrap_or(12)
}

/// The bench log of the run at precharge `p0` [Pa], its MPa with `decimals`.
fn log_name(p0: f64, decimals: usize) -> String {
    format!("precharge-{:.*}MPa.csv", decimals, p0 / 1e6)
}

/// A sweep result: precharge (None for the reference without absorber), run, figures.
type SweepPoint = (Option<f64>, Run, Pulsation);

/// The sweep's runs: the reference's without the absorber with its pulsation, and each
/// precharge [Pa] with its run and pulsation.
type Swept = ((Run, Pulsation), Vec<(f64, Run, Pulsation)>);

/// `eha sweep-precharge`.
pub fn run_sweep_precharge(rig: &Rig, args: &SweepPrechargeArgs) -> Result<(), CliError> {
    check_values(&args.values)?;
    let hold =
        by_name("pressure-hold").ok_or_else(|| CliError::Failed("scenario missing".into()))?;
    let duration = 4.0;
    let ((ref_run, ref_p), points) = sweep_runs(rig, &args.values, hold, duration)?;
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
    let mut out = Outputs::new();
    if let Some(dir) = &args.out {
        out.folder("--out", dir, FILES, |d| {
            write_sweep_outputs(d, &ref_run, &points)
        })?;
        let _ = writeln!(table, "bench logs and plots written to {}/", dir.display());
    }
    if let Some(path) = &args.json {
        out.json(
            "--json",
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
    }
    if !args.json.as_deref().is_some_and(is_stdout) {
        out.print(&table);
    }
    out.commit()
}

/// Refuses an empty list of precharges, one longer than [`MAX_POINTS`], and a precharge
/// named twice.
fn check_values(values: &[f64]) -> Result<(), CliError> {
    if values.is_empty() {
        return Err(CliError::BadInput(
            "--values needs at least one precharge".into(),
        ));
    }
    if values.len() > MAX_POINTS {
        return Err(CliError::BadInput(format!(
            "--values names {} precharges; a sweep runs at most {MAX_POINTS} (each is a 4 s \
             closed-loop run)",
            values.len()
        )));
    }
    for (i, v) in values.iter().enumerate() {
        if values[..i].contains(v) {
            return Err(CliError::BadInput(format!(
                "--values names the precharge {} Pa twice",
                show(*v)
            )));
        }
    }
    Ok(())
}

/// The sweep's holding runs of `duration` [s], in parallel: the reference without the
/// absorber, and one per precharge of `values` [Pa] (each validated on the rig). Returns
/// the reference's run and pulsation, and each precharge's.
fn sweep_runs(
    rig: &Rig,
    values: &[f64],
    hold: &Scenario,
    duration: f64,
) -> Result<Swept, CliError> {
    let effects: Vec<Effect> = paper_low_speed_effects().to_vec();
    let mut jobs: Vec<(Option<f64>, Rig, Rig)> = Vec::new();
    let mut bare = plant_rig(rig, &effects)?;
    bare.absorber.enabled = false;
    let mut bare_controller = rig.clone();
    bare_controller.absorber.enabled = false;
    jobs.push((None, bare, bare_controller));
    for &p0 in values {
        let mut controller = rig.clone();
        controller.absorber.precharge_pa = p0;
        controller
            .validate()
            .map_err(|e| CliError::BadInput(format!("--values: precharge {} Pa: {e}", show(p0))))?;
        let plant = plant_rig(&controller, &effects)?;
        jobs.push((Some(p0), plant, controller));
    }
    let results: Vec<Result<SweepPoint, CliError>> = jobs
        .par_iter()
        .map(|(p0, plant, controller)| {
            let meta = vec![
                ("source".to_string(), "simulation".to_string()),
                ("scenario".into(), "pressure-hold".into()),
                ("effects".into(), effects_text(rig, &effects)),
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
    let reference = reference.ok_or_else(|| CliError::Failed("reference run missing".into()))?;
    Ok((reference, points))
}

/// Writes the runs' bench logs and the two figures into the sweep's folder.
fn write_sweep_outputs(
    d: &StagedFolder,
    reference: &Run,
    points: &[(f64, Run, Pulsation)],
) -> Result<(), CliError> {
    write_into(d, "no-absorber.csv", &reference.log)?;
    let mut traces = vec![Series {
        name: "no absorber",
        points: window(reference),
    }];
    let decimals = file_decimals(points.iter().map(|(p0, _, _)| *p0));
    let names: Vec<String> = points
        .iter()
        .map(|(p0, _, _)| format!("p0 = {:.1} MPa", p0 / 1e6))
        .collect();
    for ((p0, run, _), name) in points.iter().zip(&names) {
        write_into(d, &log_name(*p0, decimals), &run.log)?;
        traces.push(Series {
            name,
            points: window(run),
        });
    }
    let plot = |name: &str, fig: Result<crate::plots::Figure, String>| {
        fig.map_err(|e| CliError::Failed(format!("plot `{name}`: {e}")))?
            .write_into(d, name)
    };
    plot(
        "pressure_traces.svg",
        line_chart(
            "Steady holding pressure per absorber precharge (true p_A)",
            "t [s]",
            "p [MPa]",
            &traces,
            &[],
            false,
        ),
    )?;
    plot(
        "sweep.svg",
        line_chart(
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
        ),
    )
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
