//! Named scenarios: the paper's low-speed pressure holding, pressure and speed steps, a
//! slow stroke of the payload, and the bench tests a diagnosis is run on (a pressure
//! staircase, a sinusoidal pressure, a stroke out and back under speed control) — each a
//! plant configuration, an initial state, the commands the bench PC sends at given times
//! and, for a test whose setpoint moves, the [`crate::profile::Profile`] it streams.

use crate::bench_test::{named, sine_test, staircase_test, stroke_test};
pub use crate::plan::{Scenario, ScenarioKind, MAX_EVENTS};
use firmware::{Command, Mode};

/// The paper's holding pressure. [Pa]
pub const HOLD_PRESSURE_PA: f64 = 5e6;

/// The named staircase: 0.5 → 4 MPa in 2.5 s, then 4, 7, 2.5 and 5.5 MPa for 4 s each.
const STAIRCASE: Scenario = named(staircase_test(
    &[(4e6, 4.0), (7e6, 4.0), (2.5e6, 4.0), (5.5e6, 4.0)],
    2.5,
));

/// The named sine: 0.5 → 5 MPa in 3 s, 2 s held, then ±0.6 MPa at 0.2 Hz to 20 s.
const SINE: Scenario = named(sine_test(5e6, 3.0, 2.0, 0.6e6, 0.2, 20.0));

/// The named stroke: 20 rad/s (≈0.7 mm/s) out, reversed at 10.4 s, back to 20 s.
const STROKE: Scenario = named(stroke_test(20.0, 0.5, 10.375, 20.0));

/// Every scenario.
pub const SCENARIOS: [Scenario; 7] = [
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
        profile: None,
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
        profile: None,
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
        profile: None,
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
        profile: None,
    },
    STAIRCASE,
    SINE,
    STROKE,
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
    profile: None,
}];

/// The scenario or procedure called `name`.
pub fn by_name(name: &str) -> Option<&'static Scenario> {
    SCENARIOS
        .iter()
        .chain(PROCEDURES.iter())
        .find(|s| s.name == name)
}
