//! The closed loop: the firmware's control core against the plant model, across the one
//! seam of the design.
//!
//! Each PWM period: the plant's sensors are sampled at the PWM centre (ADC counts, encoder
//! count — exactly what the MCU's peripherals give), the control core's ISR body turns them
//! into three duties and the bridge enable, and the plant integrates one period with those
//! duties held (zero-order hold). Nothing of the plant's state reaches the controller except
//! through [`plant_model::SensorReadings`] → [`firmware::io::Measurements`].
//!
//! The plant's hardware over-current break ([`plant_model::Plant::set_hardware_break`], off
//! unless armed) is reported to the control core as the board's break interrupt does, before
//! the next current-loop call.
//!
//! `no_std`: the same harness runs in `eha`, in the cross-crate tests, and in the PIL binary
//! on a Cortex-M4F.
#![no_std]
#![deny(missing_docs)]

pub mod bench_test;
pub mod commissioning;
pub mod config;
pub mod plan;
pub mod profile;
pub mod scenario;

pub use config::controller_config;
pub use plan::{Scenario, ScenarioKind};
pub use profile::{Profile, Setpoint};
pub use scenario::{by_name, PROCEDURES, SCENARIOS};

use firmware::io::{Measurements, Outputs};
use firmware::{Command, Controller};
use plant_model::{InitialConditions, Inputs, Observables, Plant, Rig, RigError};

/// One PWM period of a run: what the controller reported and what the plant really did.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    /// The controller's telemetry (its measured and commanded quantities).
    pub telemetry: firmware::TelemetryFrame,
    /// The plant's true state at the same instant.
    pub truth: Observables,
    /// The controller's outputs for the next period.
    pub outputs: Outputs,
}

/// A logged period: the telemetry after the ISR, the plant's truth at the sampling instant.
fn record(plant: &Plant, controller: &Controller, outputs: Outputs) -> Sample {
    Sample {
        telemetry: controller.telemetry(),
        truth: plant.observe(),
        outputs,
    }
}

/// The control core in closed loop with the plant.
#[derive(Clone)]
pub struct ClosedLoop {
    plant: Plant,
    controller: Controller,
    period_s: f64,
    scenario: Scenario,
    next_event: usize,
    profile_sent: u64,
    heartbeat_every: u32,
    steps: u64,
    external_torque_nm: f64,
    bench_pc: bool,
}

/// Why a closed loop could not be built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BuildError {
    /// The rig failed validation.
    Rig(RigError),
    /// The controller configuration derived from the rig failed validation.
    Config(firmware::config::ConfigError),
}

impl core::fmt::Display for BuildError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            BuildError::Rig(e) => write!(f, "{e}"),
            BuildError::Config(e) => write!(f, "controller configuration: {e:?}"),
        }
    }
}

impl ClosedLoop {
    /// The loop for `scenario` on the plant `rig` (effects already applied), controlled by
    /// `config` (normally [`controller_config`] of the rig the engineer believes in), with
    /// sensor noise seeded by `seed`.
    pub fn new(
        rig: &Rig,
        config: &firmware::config::Config,
        scenario: &Scenario,
        seed: u64,
    ) -> Result<ClosedLoop, BuildError> {
        config.validate().map_err(BuildError::Config)?;
        let mut rig = rig.clone();
        rig.cylinder.blocked = scenario.blocked;
        let init = InitialConditions {
            p_a_pa: scenario.initial_pressure_pa,
            ..InitialConditions::at_rest(&rig)
        };
        let plant = Plant::new(&rig, &init, seed).map_err(BuildError::Rig)?;
        let period_s = 1.0 / config.rates.pwm_hz as f64;
        // A heartbeat well inside the command timeout, as the bench PC sends over CAN.
        let heartbeat_every =
            ((0.25 * config.limits.command_timeout_s as f64 / period_s) as u32).max(1);
        Ok(ClosedLoop {
            plant,
            controller: Controller::new(config),
            period_s,
            scenario: *scenario,
            next_event: 0,
            profile_sent: 0,
            heartbeat_every,
            steps: 0,
            external_torque_nm: 0.0,
            bench_pc: true,
        })
    }

    /// Time since the start. [s]
    pub fn time_s(&self) -> f64 {
        self.steps as f64 * self.period_s
    }

    /// The PWM period. [s]
    pub fn period_s(&self) -> f64 {
        self.period_s
    }

    /// The plant (for its energy books and true state).
    pub fn plant(&self) -> &Plant {
        &self.plant
    }

    /// The plant (for fault injection: [`Plant::set_faults`], [`Plant::set_sensor_faults`]).
    pub fn plant_mut(&mut self) -> &mut Plant {
        &mut self.plant
    }

    /// The controller (for commands outside the scenario, fault injection, telemetry).
    pub fn controller_mut(&mut self) -> &mut Controller {
        &mut self.controller
    }

    /// Switches the harness's own bench PC (the scenario's commands and the heartbeats) on
    /// or off; off, every command comes from the caller (a CAN bus model, say).
    pub fn set_bench_pc(&mut self, on: bool) {
        self.bench_pc = on;
    }

    /// The scenario this loop runs.
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// Sends a command as the bench PC would; refused commands are returned.
    pub fn command(&mut self, c: Command) -> Result<(), firmware::CommandError> {
        self.controller.command(c)
    }

    /// An external torque on the shaft from the next period on (a replay's tracking
    /// correction; 0 by default, as on a real rig). [N·m]
    pub fn set_external_torque_nm(&mut self, torque_nm: f64) {
        self.external_torque_nm = torque_nm;
    }

    /// Turns the plant's shaft by `delta_rad` now, leaving its speed and every other state
    /// alone (a replay's kinematic phase lock, see [`Plant::shift_shaft_angle`]). [rad]
    pub fn shift_shaft_angle(&mut self, delta_rad: f64) {
        self.plant.shift_shaft_angle(delta_rad);
    }

    /// One PWM period: scenario commands due now, sample, control, integrate.
    pub fn step(&mut self) -> Sample {
        self.step_with(|m| m)
    }

    /// One PWM period with the measurements passed through `tamper` first (fault injection:
    /// an open pressure wire, an encoder jump, an over-current reading).
    pub fn step_with(&mut self, tamper: impl FnOnce(Measurements) -> Measurements) -> Sample {
        self.period(tamper, record)
    }

    /// One PWM period: scenario commands due now, sample, control, then `record` (given the
    /// plant still at the sampling instant, the controller after its ISR and the outputs),
    /// then integrate. Recording is a closure so that unlogged periods pay nothing for the
    /// plant's observables or the telemetry frame.
    fn period<R>(
        &mut self,
        tamper: impl FnOnce(Measurements) -> Measurements,
        record: impl FnOnce(&Plant, &Controller, Outputs) -> R,
    ) -> R {
        let t = self.time_s();
        while let Some(ev) = self
            .scenario
            .events
            .get(self.next_event)
            .filter(|_| self.bench_pc)
        {
            match ev {
                Some((at, cmd)) if *at <= t => {
                    // Scenario commands are within range by construction; a refusal shows in
                    // the telemetry's status like on the bench.
                    let _ = self.controller.command(*cmd);
                    self.next_event += 1;
                }
                Some(_) => break,
                None => {
                    self.next_event += 1;
                }
            }
        }
        if let Some(p) = self.scenario.profile.filter(|_| self.bench_pc) {
            // The k-th setpoint is due at k·period (within half a PWM period of rounding).
            if t + 0.5 * self.period_s >= self.profile_sent as f64 * p.period_s {
                let _ = self.controller.command(p.command_at(t));
                self.profile_sent += 1;
            }
        }
        if self.bench_pc && self.steps % self.heartbeat_every as u64 == 0 {
            let _ = self.controller.command(Command::Heartbeat);
        }
        let r = self.plant.sample();
        let m = tamper(Measurements {
            adc_phase_current: r.adc_phase_current,
            adc_dc_link: r.adc_dc_link,
            adc_pressure: r.adc_pressure,
            encoder_count: r.encoder_count,
            encoder_index: r.encoder_index,
            // The simulated counter reads 0 at its index (`controller_config` says so).
            encoder_index_count: 0,
        });
        let out = self.controller.on_current_sample(&m);
        let recorded = record(&self.plant, &self.controller, out);
        let d = out.duties;
        let mut inputs = Inputs::duties([d[0] as f64, d[1] as f64, d[2] as f64], out.pwm_enabled);
        inputs.external_torque_nm = self.external_torque_nm;
        self.plant.advance(self.period_s, &inputs);
        if self.plant.take_break_event() {
            self.controller.report_hardware_break();
        }
        self.steps += 1;
        recorded
    }

    /// Runs until `t_end` seconds, calling `each` every `every` periods.
    pub fn run(&mut self, t_end_s: f64, every: u32, mut each: impl FnMut(&Sample)) {
        let n = libm::ceil((t_end_s - self.time_s()) / self.period_s).max(0.0) as u64;
        for k in 0..n {
            if k % every.max(1) as u64 == 0 {
                let s = self.period(|m| m, record);
                each(&s);
            } else {
                self.period(|m| m, |_, _, _| ());
            }
        }
    }
}
