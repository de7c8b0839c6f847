//! What tuning one loop from one log gives ([`Tuning`]): the step found, the plant
//! identified ([`Identified`]: the shaft of [`super::speed`], the high-pressure side of
//! [`super::pressure`]), the current and proposed gains and configurations, the step
//! measured, predicted and replayed, the parameters to send.

use super::can::Setting;
use super::gains::Gains;
use super::predict::StepSpec;
use super::step::{Step, StepMetrics, Target};
use super::{pressure, speed};
use clap::ValueEnum;
use firmware::config::Config;

/// Which loop `eha tune` identifies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LoopKind {
    /// Speed loop (speed reference step).
    Speed,
    /// Pressure loop (pressure setpoint step).
    Pressure,
}

/// What was identified, per loop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Identified {
    /// The shaft, and what the rig assumed.
    Speed {
        /// Identified.
        shaft: speed::Shaft,
        /// The rig's inertia. [kg·m²]
        assumed_inertia_kg_m2: f64,
        /// The rig's viscous friction. [N·m·s]
        assumed_viscous_nm_s: f64,
    },
    /// The high-pressure side, and what the controller's schedule assumed.
    Pressure {
        /// Identified.
        high: pressure::HighSide,
        /// The schedule's precharge. [Pa]
        assumed_precharge_pa: f64,
        /// The schedule's oil capacitance `V_oil/β`. [m³/Pa]
        assumed_oil_capacitance_m3_per_pa: f64,
        /// Identified capacitance at the step's final setpoint. [m³/Pa]
        capacitance_m3_per_pa: f64,
        /// The schedule's capacitance there. [m³/Pa]
        assumed_capacitance_m3_per_pa: f64,
    },
}

/// The result of tuning one loop from one log.
#[derive(Clone, Debug)]
pub struct Tuning {
    /// The loop.
    pub loop_kind: LoopKind,
    /// The step found in the log.
    pub step: Step,
    /// When the step's reference left its initial value in the log. [s]
    pub step_time_s: f64,
    /// Its replay (setpoints and windows) used for the predictions.
    pub spec: StepSpec,
    /// The target.
    pub target: Target,
    /// The identified plant.
    pub identified: Identified,
    /// The controller's configuration from the rig.
    pub current_config: Config,
    /// Its gains (the schedule's at the final setpoint for pressure).
    pub current_gains: Gains,
    /// The proposed configuration.
    pub proposed_config: Config,
    /// Its gains.
    pub proposed_gains: Gains,
    /// The parameters to send.
    pub settings: Vec<Setting>,
    /// The logged step's overshoot and settling.
    pub measured: StepMetrics,
    /// The proposal's, replayed on the identified plant.
    pub predicted: StepMetrics,
    /// The current gains replayed on the identified plant: how well the model reproduces
    /// the log.
    pub replayed_current: StepMetrics,
    /// Remarks for the engineer.
    pub notes: Vec<String>,
}
