//! Named scenarios: the paper's low-speed pressure holding, pressure and speed steps, and a
//! slow stroke of the payload — each a plant configuration, an initial state and the
//! commands the bench PC sends at given times.

use firmware::{Command, Mode};

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
}

/// The paper's holding pressure. [Pa]
pub const HOLD_PRESSURE_PA: f64 = 5e6;

/// Every scenario.
pub const SCENARIOS: [Scenario; 4] = [
    Scenario {
        name: "pressure-hold",
        description: "the paper's low-speed pressure holding: blocked cylinder at 5 MPa, the pump turning only to replace leakage (about 60 rpm)",
        kind: ScenarioKind::PressureHold,
        blocked: true,
        initial_pressure_pa: HOLD_PRESSURE_PA,
        duration_s: 3.0,
        steady_from_s: 1.0,
        events: [
            Some((0.0, Command::SetPressure { pa: HOLD_PRESSURE_PA as f32 })),
            Some((0.0, Command::SetMode(Mode::Pressure))),
            None,
            None,
            None,
            None,
        ],
    },
    Scenario {
        name: "pressure-step",
        description: "pressure step 3 → 5 MPa at 0.5 s, blocked cylinder",
        kind: ScenarioKind::PressureStep,
        blocked: true,
        initial_pressure_pa: 3e6,
        // Long enough for the speed-limited fill of a low-precharge absorber (≈ 2.3 s at
        // 2 MPa: ~130 pump revolutions at the 200 rad/s limit).
        duration_s: 4.0,
        steady_from_s: 0.5,
        events: [
            Some((0.0, Command::SetPressure { pa: 3e6 })),
            Some((0.0, Command::SetMode(Mode::Pressure))),
            Some((0.5, Command::SetPressure { pa: 5e6 })),
            None,
            None,
            None,
        ],
    },
    Scenario {
        name: "speed-step",
        description: "speed step 0 → 50 rad/s at 0.1 s, payload free",
        kind: ScenarioKind::SpeedStep,
        blocked: false,
        initial_pressure_pa: 0.5e6,
        duration_s: 1.0,
        steady_from_s: 0.1,
        events: [
            Some((0.0, Command::SetSpeed { rad_s: 0.0 })),
            Some((0.0, Command::SetMode(Mode::Speed))),
            Some((0.1, Command::SetSpeed { rad_s: 50.0 })),
            None,
            None,
            None,
        ],
    },
    Scenario {
        name: "slow-stroke",
        description: "slow stroke of the 2000 kg payload: pump at 30 rad/s (≈1 mm/s) under speed control",
        kind: ScenarioKind::SlowStroke,
        blocked: false,
        initial_pressure_pa: 0.5e6,
        duration_s: 4.0,
        steady_from_s: 1.0,
        events: [
            Some((0.0, Command::SetSpeed { rad_s: 0.0 })),
            Some((0.0, Command::SetMode(Mode::Speed))),
            Some((0.2, Command::SetSpeed { rad_s: 30.0 })),
            None,
            None,
            None,
        ],
    },
];

/// Speed of the torque feed-forward's bench sweep: 1.6 revolutions per second, so a
/// steady window of a few seconds holds several revolutions and the cogging's 72nd order
/// (115 Hz) stays below a third of a 1 kHz log's rate. [rad/s]
pub const SWEEP_SPEED_RAD_S: f32 = 10.0;
/// Duration of each of the sweep's two legs. [s]
pub const SWEEP_LEG_S: f32 = 6.0;

/// The bench procedures the firmware runs itself, beside the [`SCENARIOS`] (kept apart so
/// the studies over every scenario stay as they were).
pub const PROCEDURES: [Scenario; 1] = [Scenario {
    name: "compensation-sweep",
    description: "the torque feed-forward's bench procedure: the drive's own sweep at 10 rad/s, 6 s each way, payload free at the fill pressure",
    kind: ScenarioKind::CompensationSweep,
    blocked: false,
    initial_pressure_pa: 0.5e6,
    duration_s: 12.8,
    steady_from_s: 0.3,
    events: [
        Some((0.0, Command::SetSpeed { rad_s: 0.0 })),
        Some((0.0, Command::SetMode(Mode::Speed))),
        Some((
            0.3,
            Command::CompensationSweep {
                speed_rad_s: SWEEP_SPEED_RAD_S,
                leg_s: SWEEP_LEG_S,
            },
        )),
        None,
        None,
        None,
    ],
}];

/// The scenario or procedure called `name`.
pub fn by_name(name: &str) -> Option<&'static Scenario> {
    SCENARIOS
        .iter()
        .chain(PROCEDURES.iter())
        .find(|s| s.name == name)
}
