//! The bench a fault is injected on: the closed loop (the firmware's control core against
//! the plant) in one of the campaign's scenarios, the CAN bus, and the bench PC that sends
//! the scenario's commands and a heartbeat over it.
//!
//! The plant carries the hardware over-current break the board arms
//! ([`BREAK_THRESHOLD_A`]) and a watch on its bridge currents at the drive's over-current
//! trip level.

use super::bus::Bus;
use super::spec::{Fired, PeriodView, Spec};
use closed_loop::commissioning::{nameplate_config, COMMISSIONING};
use closed_loop::{by_name, controller_config, ClosedLoop, Sample, Scenario};
use firmware::can_protocol::Request;
use firmware::{Command, Config, Measurements, Mode};
use plant_model::{CurrentWatch, Rig};

/// The hardware break's threshold: above the software trip (45 A) so that slow rises are
/// the software's, below the current ADC's ±50 A full scale. [A]
pub const BREAK_THRESHOLD_A: f64 = 48.0;
/// The bench PC's heartbeat period (a quarter of the drive's command timeout). [s]
pub const HEARTBEAT_S: f64 = 0.025;

/// A scenario of the campaign.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ScenarioId {
    /// `pressure-hold`.
    Hold,
    /// `pressure-step`.
    PressureStep,
    /// `speed-step`.
    SpeedStep,
    /// `slow-stroke`.
    SlowStroke,
    /// The commissioning sequence.
    Commissioning,
}

impl ScenarioId {
    /// Every scenario.
    pub const ALL: [ScenarioId; 5] = [
        ScenarioId::Hold,
        ScenarioId::PressureStep,
        ScenarioId::SpeedStep,
        ScenarioId::SlowStroke,
        ScenarioId::Commissioning,
    ];

    /// Its name.
    pub fn name(self) -> &'static str {
        self.scenario().name
    }

    /// The closed loop's scenario.
    pub fn scenario(self) -> Scenario {
        let named = |n| *by_name(n).unwrap_or_else(|| unreachable!("scenario {n} exists"));
        match self {
            ScenarioId::Hold => named("pressure-hold"),
            ScenarioId::PressureStep => named("pressure-step"),
            ScenarioId::SpeedStep => named("speed-step"),
            ScenarioId::SlowStroke => named("slow-stroke"),
            ScenarioId::Commissioning => COMMISSIONING,
        }
    }

    /// When a fault may be injected: from the scenario's start of activity to well before
    /// its end. [s]
    pub fn window_s(self) -> (f64, f64) {
        match self {
            ScenarioId::Hold => (0.1, 2.0),
            ScenarioId::PressureStep => (0.3, 2.5),
            ScenarioId::SpeedStep => (0.05, 0.8),
            ScenarioId::SlowStroke => (0.3, 3.0),
            // Offsets, resistance and inductance pulses, the spin: the sequence's first
            // 1.5 s (it runs about 2 s on the nominal rig).
            ScenarioId::Commissioning => (0.02, 1.5),
        }
    }

    /// The controller configuration: the rig's, or the nameplate's for commissioning.
    pub fn config(self, rig: &Rig) -> Config {
        match self {
            ScenarioId::Commissioning => nameplate_config(rig),
            _ => controller_config(rig),
        }
    }
}

/// The closed loop with its bus and bench PC.
#[derive(Clone)]
pub struct Bench {
    /// The closed loop.
    pub cl: ClosedLoop,
    /// The bus.
    pub bus: Bus,
    /// The controller's configuration.
    pub config: Config,
    /// The scenario.
    pub scenario: ScenarioId,
    events_sent: usize,
    next_heartbeat_s: f64,
    /// The bench PC sends nothing before this time. [s]
    pub silent_until_s: f64,
    started: bool,
    /// The campaign's rules, run from the start (the encoder's history).
    pub spec: Spec,
    /// Calls so far.
    pub calls: u64,
}

/// One period on the bench.
#[derive(Clone, Debug)]
pub struct Step {
    /// The closed loop's record.
    pub sample: Sample,
    /// The rules that fired (periods counted from the start).
    pub fired: Vec<Fired>,
    /// The bridge currents during the period against the trip level.
    pub watch: CurrentWatch,
    /// What the controller was given.
    pub m: Measurements,
}

impl Bench {
    /// The nominal rig in `scenario`, sensor noise seeded by `seed`.
    pub fn new(scenario: ScenarioId, seed: u64) -> Bench {
        let rig = Rig::nominal();
        let config = scenario.config(&rig);
        let mut cl = ClosedLoop::new(&rig, &config, &scenario.scenario(), seed)
            .unwrap_or_else(|e| panic!("closed loop for {}: {e}", scenario.name()));
        cl.set_bench_pc(false);
        cl.plant_mut().set_hardware_break(Some(BREAK_THRESHOLD_A));
        cl.plant_mut()
            .set_current_watch(Some(f64::from(config.limits.over_current_a)));
        Bench {
            cl,
            bus: Bus::new(),
            config,
            scenario,
            events_sent: 0,
            next_heartbeat_s: 0.0,
            silent_until_s: 0.0,
            started: false,
            spec: Spec::new(&config),
            calls: 0,
        }
    }

    /// Simulated time. [s]
    pub fn time_s(&self) -> f64 {
        self.cl.time_s()
    }

    /// The bench PC's commands due now: the scenario's, and the heartbeat.
    fn bench_pc(&mut self) {
        let t = self.time_s();
        if t < self.silent_until_s {
            return;
        }
        if !self.started {
            self.started = true;
            if self.scenario == ScenarioId::Commissioning {
                self.bus.pc_send(&Request::Commission);
            }
        }
        let events = self.cl.scenario().events;
        while let Some(Some((at, cmd))) = events.get(self.events_sent) {
            if *at > t {
                break;
            }
            if let Some(r) = request_of(cmd) {
                self.bus.pc_send(&r);
            }
            self.events_sent += 1;
        }
        if t >= self.next_heartbeat_s {
            self.bus.pc_send(&Request::Heartbeat);
            self.next_heartbeat_s = t + HEARTBEAT_S;
        }
    }

    /// One PWM period: the bench PC, the bus up to the sampling instant, the closed loop,
    /// the rules on what the controller was given and on the plant.
    pub fn period(&mut self) -> Step {
        self.bench_pc();
        let t = self.time_s();
        self.bus.run_until(t, self.cl.controller_mut());
        let mode = self.cl.controller_mut().mode();
        let calibrated = self.cl.controller_mut().offsets_measured();
        let offsets_lsb = self.cl.controller_mut().current_offsets();
        let latched_before = self.cl.plant().break_latched();
        let mut seen = Measurements::default();
        let sample = self.cl.step_with(|m| {
            seen = m;
            m
        });
        let broke = !latched_before && self.cl.plant().break_latched();
        let watch = self.cl.plant_mut().take_current_watch();
        let fired = self.spec.evaluate(&PeriodView {
            period: self.calls,
            m: &seen,
            i_bridge_a: sample.truth.i_bridge_abc_a,
            omega_rad_s: sample.truth.omega_m_rad_s,
            broke,
            silent_s: t - self.bus.last_command_s,
            mode,
            i_dq_a: (sample.truth.i_d_a, sample.truth.i_q_a),
            calibrated,
            offsets_lsb,
        });
        self.calls += 1;
        Step {
            sample,
            fired,
            watch,
            m: seen,
        }
    }

    /// Runs until `t_s`; the rules that fired on the way.
    pub fn run_to(&mut self, t_s: f64) -> Vec<Fired> {
        let mut fired = Vec::new();
        while self.time_s() < t_s - 1e-12 {
            fired.extend(self.period().fired);
        }
        fired
    }

    /// The mode the scenario runs the drive in, and the requests that bring it back there
    /// after a fault was cleared.
    pub fn restart_requests(&self) -> Vec<Request> {
        let events = self.cl.scenario().events;
        let mut out: Vec<Request> = events
            .iter()
            .take(self.events_sent)
            .flatten()
            .filter_map(|(_, c)| request_of(c))
            .filter(|r| !matches!(r, Request::SetMode(_)))
            .collect();
        let mode = match self.scenario {
            ScenarioId::Hold | ScenarioId::PressureStep => Mode::Pressure,
            ScenarioId::SpeedStep | ScenarioId::SlowStroke | ScenarioId::Commissioning => {
                Mode::Speed
            }
        };
        if self.scenario == ScenarioId::Commissioning {
            out.push(Request::SetSpeed { mrad_s: 0 });
        }
        out.push(Request::SetMode(mode));
        out
    }
}

/// The wire request of a scenario command.
fn request_of(c: &Command) -> Option<Request> {
    match *c {
        Command::SetMode(m) => Some(Request::SetMode(m)),
        Command::SetPressure { pa } => Request::pressure_from_pa(pa).ok(),
        Command::SetSpeed { rad_s } => Request::speed_from_rad_s(rad_s).ok(),
        Command::ClearFaults => Some(Request::ClearFaults),
        Command::Heartbeat => Some(Request::Heartbeat),
        Command::Commission => Some(Request::Commission),
        Command::SetParameter { id, value } => Some(Request::SetParameter { id, value }),
        Command::StepTest { .. } => None,
        Command::CompensationHeader { exponents, bins } => {
            Some(Request::CompensationHeader { exponents, bins })
        }
        Command::CompensationBin { bin, raw } => Some(Request::CompensationBin { bin, raw }),
        Command::CompensationCommit { crc } => Some(Request::CompensationCommit { crc }),
        Command::CompensationSweep { speed_rad_s, leg_s } => {
            let ms = (leg_s * 1e3).round();
            (0.0..=f32::from(u16::MAX))
                .contains(&ms)
                .then_some(Request::CompensationSweep {
                    speed_rad_s,
                    leg_ms: ms as u16,
                })
        }
    }
}
