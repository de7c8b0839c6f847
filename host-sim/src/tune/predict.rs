//! The step of a log replayed in closed loop: the firmware's control core, configured with
//! the gains under test, against the plant model of a rig (the identified plant for a
//! prediction, the true one in a test), measured exactly as the log was
//! ([`super::step::metrics`] on the controller's own telemetry).

use super::step::{self, Signal, Step, StepMetrics};
use closed_loop::scenario::MAX_EVENTS;
use closed_loop::{ClosedLoop, Scenario, ScenarioKind};
use firmware::config::Config;
use firmware::{Command, Mode};
use plant_model::Rig;

/// Rate the simulated response is sampled at (the bench logs' telemetry rate). [Hz]
const SAMPLE_RATE_HZ: f64 = 2000.0;

/// A setpoint step to replay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepSpec {
    /// Which loop's setpoint steps.
    pub signal: Signal,
    /// Setpoint before the step. [Pa] or [rad/s]
    pub from: f64,
    /// Setpoint after the step. [Pa] or [rad/s]
    pub to: f64,
    /// Time at the initial setpoint before the step (lets the loop settle there). [s]
    pub lead_s: f64,
    /// Time simulated after the step. [s]
    pub after_s: f64,
    /// Pressure on the pump's port at the start. [Pa]
    pub initial_pressure_pa: f64,
}

impl StepSpec {
    /// The closed-loop scenario of this step: the cylinder blocked for a pressure step (as
    /// the pressure identification requires), free for a speed step.
    pub fn scenario(&self) -> Scenario {
        let (set, mode, kind) = match self.signal {
            Signal::Pressure => (
                (|v: f64| Command::SetPressure { pa: v as f32 }) as fn(f64) -> Command,
                Mode::Pressure,
                ScenarioKind::PressureStep,
            ),
            Signal::Speed => (
                (|v: f64| Command::SetSpeed { rad_s: v as f32 }) as fn(f64) -> Command,
                Mode::Speed,
                ScenarioKind::SpeedStep,
            ),
        };
        let mut events: [Option<(f64, Command)>; MAX_EVENTS] = [None; MAX_EVENTS];
        events[0] = Some((0.0, set(self.from)));
        events[1] = Some((0.0, Command::SetMode(mode)));
        events[2] = Some((self.lead_s, set(self.to)));
        Scenario {
            name: "tune-step",
            description: "the setpoint step of the log being tuned",
            kind,
            blocked: self.signal == Signal::Pressure,
            initial_pressure_pa: self.initial_pressure_pa,
            duration_s: self.lead_s + self.after_s,
            steady_from_s: self.lead_s,
            events,
            profile: None,
        }
    }
}

/// A simulated step: its samples and its metrics.
#[derive(Clone, Debug)]
pub struct Response {
    /// Sample instants. [s]
    pub t_s: Vec<f64>,
    /// The controller's reference (ramped pressure setpoint [Pa], or speed reference
    /// [rad/s]).
    pub reference: Vec<f64>,
    /// The controller's measurement (pressure [Pa] or speed [rad/s]).
    pub measured: Vec<f64>,
    /// Overshoot and settling.
    pub metrics: StepMetrics,
}

/// Runs `spec` on the plant `plant` with the controller configured by `config`.
pub fn simulate(
    plant: &Rig,
    config: &Config,
    spec: &StepSpec,
    seed: u64,
) -> Result<Response, String> {
    let scenario = spec.scenario();
    let mut cl = ClosedLoop::new(plant, config, &scenario, seed).map_err(|e| e.to_string())?;
    let every = ((1.0 / SAMPLE_RATE_HZ) / cl.period_s()).round().max(1.0) as u32;
    let (mut t, mut r, mut y) = (Vec::new(), Vec::new(), Vec::new());
    cl.run(scenario.duration_s, every, |s| {
        let f = &s.telemetry;
        t.push(s.truth.t_s);
        match spec.signal {
            Signal::Pressure => {
                r.push(f.p_ref_pa as f64);
                y.push(f.p_pa as f64);
            }
            Signal::Speed => {
                r.push(f.speed_ref_rad_s as f64);
                y.push(f.speed_rad_s as f64);
            }
        }
    });
    let found = step::find(&t, &r, spec.signal)
        .map_err(|e| format!("the simulated step was not seen in the reference ({e:?})"))?;
    let metrics = step::metrics(&t, &y, &found, spec.signal);
    Ok(Response {
        t_s: t,
        reference: r,
        measured: y,
        metrics,
    })
}

/// The replay of `step` found in a log: same setpoints, at least `lead_s` before, and after
/// it as long as the log showed (at least `min_after_s`, at most `max_after_s`). [s]
pub fn spec_of(
    signal: Signal,
    t: &[f64],
    step: &Step,
    initial_pressure_pa: f64,
    lead_s: f64,
    (min_after_s, max_after_s): (f64, f64),
) -> StepSpec {
    let shown = t[step.end - 1] - t[step.start];
    StepSpec {
        signal,
        from: step.from,
        to: step.to,
        lead_s,
        after_s: shown.clamp(min_after_s, max_after_s),
        initial_pressure_pa,
    }
}
