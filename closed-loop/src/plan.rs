//! What a scenario is: a plant configuration, an initial state, the commands the bench PC
//! sends at given times and the setpoint [`Profile`] it streams, with what it exercises —
//! the type the named catalogue ([`crate::scenario`]) and the bench-test builders
//! ([`crate::bench_test`]) both make.

use crate::profile::Profile;
use firmware::Command;

/// Most commands a scenario sends.
pub const MAX_EVENTS: usize = 6;

/// What a scenario exercises (used to choose analysis windows).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScenarioKind {
    /// Steady pressure holding.
    PressureHold,
    /// A pressure setpoint step.
    PressureStep,
    /// A speed setpoint step.
    SpeedStep,
    /// The payload moved slowly under speed control.
    SlowStroke,
    /// The commissioning sequence (motor identification) on the free shaft.
    Commissioning,
    /// The torque feed-forward's bench sweep: constant speed both ways, payload free.
    CompensationSweep,
    /// Pressure levels held one after another on the blocked cylinder.
    Staircase,
    /// A sinusoidal pressure setpoint on the blocked cylinder.
    Sine,
    /// The payload moved out and back under speed control, reversing once.
    Stroke,
}

/// A named scenario.
#[derive(Clone, Copy, Debug)]
pub struct Scenario {
    /// Name used on the command line.
    pub name: &'static str,
    /// One line for `eha simulate --list`.
    pub description: &'static str,
    /// What it exercises.
    pub kind: ScenarioKind,
    /// Cylinder held at mid-stroke (pressure holding).
    pub blocked: bool,
    /// Port-A pressure at the start. [Pa]
    pub initial_pressure_pa: f64,
    /// Default length of the run. [s]
    pub duration_s: f64,
    /// When the steady state is reached (analysis starts here). [s]
    pub steady_from_s: f64,
    /// Commands and when they are sent. [s]
    pub events: [Option<(f64, Command)>; MAX_EVENTS],
    /// The setpoint the bench PC streams from the start, after the events due at the same
    /// instant (`None`: only the events).
    pub profile: Option<Profile>,
}
