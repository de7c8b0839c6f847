//! `eha tune`: from a bench log holding a setpoint step of one loop, identify that
//! loop's plant, propose gains meeting an overshoot/settling target, predict the step with
//! them on the identified plant, and print the CAN commands that apply them.
//!
//! - [`step`]: finding the step, its overshoot and 2 % settling time;
//! - [`speed`], [`pressure`]: each loop's identification (least squares on the integrated
//!   plant equation) and design;
//! - [`candidates`], [`predict`]: the closed-loop replays (the firmware's control core
//!   against the plant model) the proposal is chosen and predicted with;
//! - [`can`]: the `SetParameter` frames;
//! - [`report`]: the JSON document and the text printed;
//! - [`tuning`]: what tuning a loop gives; [`gains`]: a PI's two gains.
//!
//! The *current* gains are those of the controller configured from the rig (`--rig`, the
//! rig the engineer believes in): for the pressure loop, its schedule's gains at the step's
//! final setpoint.

pub mod can;
pub mod candidates;
pub mod fit;
pub mod gains;
pub mod glitch;
pub mod predict;
pub mod pressure;
pub mod report;
pub mod speed;
pub mod step;
pub mod tuning;

use crate::bench_log::BenchLog;
use crate::output::paths::Declared;
use crate::output::{is_stdout, CliError, Outputs};
use crate::values::{non_negative_f64, positive_f64, show};
use can::Setting;
use clap::Args;
use closed_loop::controller_config;
use firmware::config::Config;
use firmware::parameters::ParamId;
use plant_model::Rig;
use predict::StepSpec;
use std::path::PathBuf;
use step::{Signal, Step, StepError, StepMetrics, Target};

pub use gains::Gains;
pub use tuning::{Identified, LoopKind, Tuning};

/// `eha tune`.
#[derive(Debug, Args)]
pub struct TuneArgs {
    /// Bench log with a setpoint step.
    #[arg(value_name = "LOG.csv")]
    pub log: PathBuf,
    /// The loop to tune.
    #[arg(long = "loop", value_enum)]
    pub loop_kind: LoopKind,
    /// Overshoot target. [%]
    #[arg(long, value_name = "PCT", value_parser = non_negative_f64, allow_negative_numbers = true)]
    pub overshoot: Option<f64>,
    /// Settling-time target. [s]
    #[arg(long, value_name = "S", value_parser = positive_f64, allow_negative_numbers = true)]
    pub settling: Option<f64>,
    /// Write the results as JSON (`-`: standard output).
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// Also write the CAN commands as a `candump -l` log (`canplayer -I FILE` replays it).
    #[arg(long, value_name = "FILE")]
    pub can_log: Option<PathBuf>,
}

impl TuneArgs {
    /// The files it reads and writes.
    pub fn paths(&self) -> Declared<'_> {
        Declared::default()
            .input("LOG", Some(&self.log))
            .file("--json", self.json.as_ref())
            .file("--can-log", self.can_log.as_ref())
    }
}

/// Default target of the speed loop: what its documented design (Table 1 gains, poles at
/// −67 and −143 rad/s with the PI zero at −50 rad/s) achieves on the nominal rig with
/// margin — 10.5 % overshoot and 0.02 s settling for the 0 → 50 rad/s step.
pub const SPEED_TARGET: Target = Target {
    overshoot_percent: 15.0,
    settling_s: 0.1,
};

/// Default target of the pressure loop: what `firmware::pressure_loop` promises for steps
/// within the speed limit (overshoot ≤ 15 %, 2 % settling ≤ 0.8 s, the setpoint ramp
/// included).
pub const PRESSURE_TARGET: Target = Target {
    overshoot_percent: 15.0,
    settling_s: 0.8,
};

/// Why a log cannot be tuned from.
#[derive(Debug, thiserror::Error)]
pub enum TuneError {
    /// The log lacks what the identification needs (exit 2).
    #[error("{0}")]
    BadLog(String),
    /// A simulation or the identification's numerics failed.
    #[error("{0}")]
    Failed(String),
}

impl From<TuneError> for CliError {
    fn from(e: TuneError) -> CliError {
        match e {
            TuneError::BadLog(m) => CliError::BadInput(m),
            TuneError::Failed(m) => CliError::Failed(m),
        }
    }
}

/// The default target of a loop with the command line's overrides.
pub fn target_for(kind: LoopKind, overshoot: Option<f64>, settling: Option<f64>) -> Target {
    let d = match kind {
        LoopKind::Speed => SPEED_TARGET,
        LoopKind::Pressure => PRESSURE_TARGET,
    };
    Target {
        overshoot_percent: overshoot.unwrap_or(d.overshoot_percent),
        settling_s: settling.unwrap_or(d.settling_s),
    }
}

/// Tunes `kind` from `log`, the controller configured from `rig`.
pub fn tune(
    rig: &Rig,
    log: &BenchLog,
    kind: LoopKind,
    target: Target,
) -> Result<Tuning, TuneError> {
    let config = controller_config(rig);
    config.validate().map_err(|e| {
        TuneError::BadLog(format!(
            "the rig gives a controller configuration the firmware refuses: {e}"
        ))
    })?;
    let limit = config.speed.speed_limit_rad_s as f64;
    let (signal, response, step) = setpoint_step(kind, log, limit)?;
    check_followed(kind, log, response, &step)?;
    let measured = step::metrics(&log.t_s, response, &step, signal);
    let mut notes = Vec::new();
    let job = Job {
        rig,
        config: &config,
        log,
        step,
        target,
    };
    let t = match kind {
        LoopKind::Speed => {
            let rise = speed::rise_samples(log, &step);
            if rise < speed::MIN_RISE_SAMPLES {
                notes.push(format!(
                    "the speed rose from 10 % to 90 % of the step in {rise} log samples: too few \
                     to resolve the acceleration, so the identified inertia is uncertain (log \
                     faster, or step smaller)"
                ));
            }
            tune_speed(&job)?
        }
        LoopKind::Pressure => {
            let at_limit = pressure::longest_at_speed_limit(log, &step, limit);
            if at_limit > 0.25 * target.settling_s {
                notes.push(format!(
                    "the pump ran at the {limit:.0} rad/s speed limit for {at_limit:.2} s of the \
                     step: its settling is limited by the pump's flow, which no gains change"
                ));
            }
            tune_pressure(&job)?
        }
    };
    let (spec, identified, proposal, replayed_current) = t;
    notes.extend(proposal_notes(&identified, &proposal, &target));
    let cfg = &proposal.design.config;
    let settings = settings(kind, cfg);
    let current_gains = match kind {
        LoopKind::Speed => Gains {
            kp: config.speed.kp as f64,
            ki: config.speed.ki as f64,
        },
        LoopKind::Pressure => pressure::gains_at(&config, step.to),
    };
    Ok(Tuning {
        loop_kind: kind,
        step,
        step_time_s: log.t_s[step.start],
        spec,
        target,
        identified,
        current_config: config,
        current_gains,
        proposed_config: *cfg,
        proposed_gains: proposal.design.gains,
        settings,
        measured,
        predicted: proposal.metrics,
        replayed_current,
        notes,
    })
}

/// The loop's signal, its response column and the setpoint step found in `log`; refuses a
/// speed "step" at the speed `limit` [rad/s] (a saturated pressure loop) and a response
/// with a lone corrupted sample.
fn setpoint_step(
    kind: LoopKind,
    log: &BenchLog,
    limit: f64,
) -> Result<(Signal, &[f64], step::Step), TuneError> {
    let (signal, reference, response) = match kind {
        LoopKind::Speed => {
            let r = log.speed_ref_rad_s.as_deref().ok_or_else(|| {
                TuneError::BadLog(
                    "the log has no speed_ref_rad_s column: a speed step cannot be found".into(),
                )
            })?;
            (Signal::Speed, r, &log.speed_rad_s[..])
        }
        LoopKind::Pressure => (Signal::Pressure, &log.p_ref_pa[..], &log.p_pa[..]),
    };
    let step = step::find(&log.t_s, reference, signal).map_err(|e| no_step(kind, e))?;
    if signal == Signal::Speed && step.from.abs().max(step.to.abs()) >= 0.99 * limit {
        // The pressure loop's output pinned at the limit holds too, but is no setpoint.
        return Err(TuneError::BadLog(format!(
            "no speed setpoint step in the log: its speed_ref_rad_s steps between {:.0} and \
             {:.0} rad/s, at the {limit:.0} rad/s limit (a saturated pressure loop, not a \
             speed setpoint)",
            step.from, step.to
        )));
    }
    // A lone sample leaving both neighbours by half the step is no response of the loop.
    if let Some(k) = glitch::lone_spike(response, 0.5 * (step.to - step.from).abs()) {
        let (column, unit, scale) = match kind {
            LoopKind::Speed => ("speed_rad_s", "rad/s", 1.0),
            LoopKind::Pressure => ("p_pa", "MPa", 1e-6),
        };
        return Err(TuneError::BadLog(format!(
            "the log's {column} at t = {:.4} s (data row {}) reads {:.4} {unit} between {:.4} and \
             {:.4} {unit}: a dropped or corrupted sample, which would bias the identification; \
             repair or remove that row",
            log.t_s[k],
            k + 1,
            response[k] * scale,
            response[k - 1] * scale,
            response[k + 1] * scale
        )));
    }
    Ok((signal, response, step))
}

/// The notes the identified plant and the chosen proposal call for: an absorber that took
/// no oil, a target no candidate meets.
fn proposal_notes(
    identified: &Identified,
    proposal: &candidates::Candidate,
    target: &Target,
) -> Vec<String> {
    let mut notes = Vec::new();
    if let Identified::Pressure { high, .. } = identified {
        if high.precharge_is_lower_bound {
            notes.push(format!(
                "the absorber took no oil in this log: its precharge is above {:.2} MPa, the \
                 highest pressure reached; the proposal assumes it there (a step to higher \
                 pressure would locate it)",
                high.precharge_pa / 1e6
            ));
        }
    }
    if !proposal.metrics.meets(target) {
        notes.push(
            "no candidate design meets the target on the identified plant: the proposal \
             misses it least (the documented design where others gain under a tenth)"
                .into(),
        );
    }
    notes
}

/// The live parameters that carry the proposal `cfg` for a loop of `kind`.
fn settings(kind: LoopKind, cfg: &Config) -> Vec<Setting> {
    let ids: &[ParamId] = match kind {
        LoopKind::Speed => &[ParamId::SpeedKp, ParamId::SpeedKi],
        LoopKind::Pressure => &[
            ParamId::AbsorberPrechargePa,
            ParamId::PressureBandwidth,
            ParamId::PressureIntegralCornerRatio,
        ],
    };
    ids.iter()
        .map(|&id| Setting {
            id,
            value: id.get(cfg) as f64,
        })
        .collect()
}

/// Refuses a step the loop's response did not follow at least [`step::MIN_FOLLOWED`] of
/// the way: no plant of the loop is identified from a response that is not one (an open
/// loop, a saturated drive, a sensor that is not the column), and no gains proposed.
fn check_followed(
    kind: LoopKind,
    log: &BenchLog,
    response: &[f64],
    step: &Step,
) -> Result<(), TuneError> {
    let (signal, column, reference, unit, scale) = match kind {
        LoopKind::Speed => (
            Signal::Speed,
            "speed_rad_s",
            "speed_ref_rad_s",
            "rad/s",
            1.0,
        ),
        LoopKind::Pressure => (Signal::Pressure, "p_pa", "p_ref_pa", "MPa", 1e-6),
    };
    let part = step::followed(&log.t_s, response, step, signal);
    if part >= step::MIN_FOLLOWED {
        return Ok(());
    }
    let end = step.end.min(log.len()).saturating_sub(1);
    Err(TuneError::BadLog(format!(
        "the log's {column} does not follow its {reference} step from {:.3} to {:.3} {unit} at \
         t = {:.3} s: it comes {:.0} % of the way by t = {:.3} s (at least {:.0} % is a loop \
         following its setpoint); no plant can be identified from it, so no gains are \
         proposed (is the loop closed, the drive saturated, {column} the loop's sensor?)",
        step.from * scale,
        step.to * scale,
        log.t_s[step.start],
        100.0 * part.max(0.0),
        log.t_s[end],
        100.0 * step::MIN_FOLLOWED
    )))
}

/// What each loop's tuning starts from.
#[derive(Clone, Copy)]
struct Job<'a> {
    rig: &'a Rig,
    config: &'a Config,
    log: &'a BenchLog,
    step: Step,
    target: Target,
}

/// What each loop's tuning produces: the replay, the identification, the chosen design, and
/// the current gains replayed on the identified plant.
type LoopTuning = (StepSpec, Identified, candidates::Candidate, StepMetrics);

fn no_step(kind: LoopKind, e: StepError) -> TuneError {
    let (what, column, min) = match kind {
        LoopKind::Speed => ("speed", "speed_ref_rad_s", "5 rad/s"),
        LoopKind::Pressure => ("pressure", "p_ref_pa", "0.2 MPa"),
    };
    let why = match e {
        StepError::NoStep => format!("never changes by {min} or more"),
        StepError::NoHold => "never holds a value for 20 ms (a loop output, not a setpoint)".into(),
    };
    TuneError::BadLog(format!(
        "no {what} setpoint step in the log: its {column} {why}"
    ))
}

fn tune_speed(job: &Job) -> Result<LoopTuning, TuneError> {
    let (rig, config, log, step, target) = (job.rig, job.config, job.log, job.step, job.target);
    let shaft = speed::identify(rig, log, &step).map_err(TuneError::BadLog)?;
    simulatable(&speed::identified_rig(rig, &shaft), "speed response")?;
    let spec = replay_spec(Signal::Speed, log, &step, log.p_pa[0], &target);
    let proposal =
        speed::propose(rig, config, &shaft, &spec, &target).map_err(TuneError::Failed)?;
    let identified = Identified::Speed {
        shaft,
        assumed_inertia_kg_m2: rig.shaft.inertia_kg_m2(),
        assumed_viscous_nm_s: rig.shaft.viscous_nm_s,
    };
    let plant = speed::identified_rig(rig, &shaft);
    finish(spec, identified, proposal, &plant, config)
}

fn tune_pressure(job: &Job) -> Result<LoopTuning, TuneError> {
    let (rig, config, log, step, target) = (job.rig, job.config, job.log, job.step, job.target);
    let high = pressure::identify(rig, log).map_err(TuneError::BadLog)?;
    simulatable(&pressure::identified_rig(rig, &high), "pressure response")?;
    let p_start = log.p_pa[step.start.saturating_sub(1)];
    let spec = replay_spec(Signal::Pressure, log, &step, p_start, &target);
    let proposal =
        pressure::propose(rig, config, &high, &spec, &target).map_err(TuneError::Failed)?;
    let h = &config.hydraulics;
    let identified = Identified::Pressure {
        high,
        assumed_precharge_pa: h.absorber_precharge_pa as f64,
        assumed_oil_capacitance_m3_per_pa: (h.oil_volume_m3 / h.bulk_modulus_pa) as f64,
        capacitance_m3_per_pa: pressure::capacitance_at(
            &pressure::identified_hydraulics(h, &high),
            step.to,
        ),
        assumed_capacitance_m3_per_pa: pressure::capacitance_at(h, step.to),
    };
    let plant = pressure::identified_rig(rig, &high);
    finish(spec, identified, proposal, &plant, config)
}

/// Checks that the plant identified from the log's `what` can be simulated: a log whose
/// response no plant of this kind produces (a sensor scaled wrongly, data of another
/// machine) is bad input, said before any proposal is attempted.
fn simulatable(plant: &Rig, what: &str) -> Result<(), TuneError> {
    plant.validate().map_err(|e| {
        TuneError::BadLog(format!(
            "the log's {what} identifies a plant that cannot be simulated ({e}): is the log \
             of this rig, its units SI?"
        ))
    })
}

/// The replay of the log's step: the scenarios' lead time at the initial setpoint (0.1 s
/// speed, 0.5 s pressure), then as long after the step as the log shows, but at least twice
/// the settling target and at most 0.5 s (speed) or 3 s (pressure).
fn replay_spec(
    signal: Signal,
    log: &BenchLog,
    step: &Step,
    initial_pressure_pa: f64,
    target: &Target,
) -> StepSpec {
    let (lead, min_after, max_after): (f64, f64, f64) = match signal {
        Signal::Speed => (0.1, 2.0 * target.settling_s + 0.05, 0.5),
        Signal::Pressure => (0.5, 2.0 * target.settling_s, 3.0),
    };
    predict::spec_of(
        signal,
        &log.t_s,
        step,
        initial_pressure_pa,
        lead,
        (min_after, max_after.max(min_after)),
    )
}

/// Completes a loop's tuning with the current gains replayed on the identified `plant`.
fn finish(
    spec: StepSpec,
    identified: Identified,
    proposal: candidates::Candidate,
    plant: &Rig,
    config: &Config,
) -> Result<LoopTuning, TuneError> {
    let replayed = predict::simulate(plant, config, &spec, 1).map_err(TuneError::Failed)?;
    Ok((spec, identified, proposal, replayed.metrics))
}

/// The longest settling target per loop: the step is replayed for twice the target on
/// each candidate design, so the target bounds the run time (a few seconds at these
/// limits); no tuning of this drive asks for slower loops. [s]
pub const MAX_SETTLING_S: [(LoopKind, f64); 2] =
    [(LoopKind::Speed, 2.0), (LoopKind::Pressure, 10.0)];

/// The shortest settling target: a millisecond is ten periods of the fastest outer loop. [s]
pub const MIN_SETTLING_S: f64 = 1e-3;

/// Checks the command line's target before the log is read.
fn check_target(args: &TuneArgs) -> Result<(), CliError> {
    if let Some(o) = args.overshoot.filter(|o| *o > 100.0) {
        return Err(CliError::BadInput(format!(
            "--overshoot {} %: an overshoot target lies between 0 and 100 %",
            show(o)
        )));
    }
    let most = MAX_SETTLING_S
        .iter()
        .find(|(k, _)| *k == args.loop_kind)
        .map_or(10.0, |(_, s)| *s);
    if let Some(s) = args
        .settling
        .filter(|s| !(MIN_SETTLING_S..=most).contains(s))
    {
        return Err(CliError::BadInput(format!(
            "--settling {} s: the {} loop's settling target lies between {MIN_SETTLING_S} and \
             {most} s",
            show(s),
            report::loop_name(args.loop_kind)
        )));
    }
    Ok(())
}

/// `eha tune`.
pub fn run_tune(rig: &Rig, args: &TuneArgs) -> Result<(), CliError> {
    check_target(args)?;
    let log = crate::bench_log::read(&args.log)?;
    let target = target_for(args.loop_kind, args.overshoot, args.settling);
    let busy = crate::output::progress::spinner(format!(
        "tuning the {} loop from {}",
        report::loop_name(args.loop_kind),
        args.log.display()
    ));
    let t = tune(rig, &log, args.loop_kind, target);
    busy.finish_and_clear();
    let t = t?;
    let frames = can::parameter_commands(&t.settings).map_err(CliError::Failed)?;
    let commands = crate::can_commands::cansend_lines(&frames);
    let mut out = Outputs::new();
    if let Some(path) = &args.can_log {
        crate::can_commands::stage_candump_log(&mut out, path, &frames)?;
    }
    if let Some(path) = &args.json {
        out.json("--json", path, &t.to_json(&commands))?;
    }
    if !args.json.as_deref().is_some_and(is_stdout) {
        out.print(&t.to_text(&commands));
    }
    out.commit()
}
