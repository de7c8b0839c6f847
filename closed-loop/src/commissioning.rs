//! Commissioning in closed loop: the firmware's sequence ([`firmware::commissioning`]) run
//! on the plant's motor from a drive configured with the nameplate only, the way a new
//! drive meets its motor on the bench: payload free at the fill pressure, sensor noise and
//! quantisation on, the encoder's mounting offset unknown to the controller.

use crate::{BuildError, ClosedLoop, Scenario, ScenarioKind};
use firmware::commissioning::CommissioningResult;
use firmware::config::Config;
use firmware::io::Measurements;
use firmware::{Command, FaultCode, Mode};
use plant_model::Rig;

/// The plant's set-up for commissioning: no scenario commands (the sequence drives).
pub const COMMISSIONING: Scenario = Scenario {
    name: "commissioning",
    description: "the commissioning sequence on the free shaft at the fill pressure",
    kind: ScenarioKind::Commissioning,
    blocked: false,
    initial_pressure_pa: 0.5e6,
    duration_s: LONGEST_S,
    steady_from_s: 0.0,
    events: [None; crate::scenario::MAX_EVENTS],
    profile: None,
};

/// The longest a sequence may take in simulation before the run gives up. [s]
pub const LONGEST_S: f64 = 20.0;

/// How a commissioning run ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome {
    /// The identified motor and derived gains, on success.
    pub result: Option<CommissioningResult>,
    /// The fault the drive latched, on failure.
    pub fault: Option<FaultCode>,
    /// Simulated time from the command to the drive's return to Disabled. [s]
    pub duration_s: f64,
}

/// The controller configuration before commissioning: the rig's sensor scalings and
/// hydraulics (as [`crate::controller_config`]) but the motor of the nameplate
/// ([`Config::nominal`]), its Table 1 gains, and encoder offset 0.
pub fn nameplate_config(rig: &Rig) -> Config {
    let mut c = crate::controller_config(rig);
    let nominal = Config::nominal();
    c.motor = firmware::config::Motor {
        pole_pairs: rig.motor.pole_pairs,
        dc_link_nominal_v: c.motor.dc_link_nominal_v,
        ..nominal.motor
    };
    c.current = nominal.current;
    c.sensors.encoder_offset_rad = 0.0;
    c
}

/// Runs the sequence on `rig` with controller `config`, noise seeded by `seed`.
pub fn commission(rig: &Rig, config: &Config, seed: u64) -> Result<Outcome, BuildError> {
    commission_with(rig, config, seed, |m| m)
}

/// As [`commission`], with every period's measurements passed through `tamper` (fault
/// injection: a dead current sensor, a reversed encoder).
pub fn commission_with(
    rig: &Rig,
    config: &Config,
    seed: u64,
    mut tamper: impl FnMut(Measurements) -> Measurements,
) -> Result<Outcome, BuildError> {
    let mut cl = ClosedLoop::new(rig, config, &COMMISSIONING, seed)?;
    // Accepted: nothing is latched and no condition is present before the first sample.
    let _ = cl.command(Command::Commission);
    let start = cl.time_s();
    while cl.time_s() - start < LONGEST_S {
        cl.step_with(&mut tamper);
        let c = cl.controller_mut();
        if c.mode() == Mode::Disabled {
            break;
        }
    }
    let c = cl.controller_mut();
    let fault = c.fault();
    Ok(Outcome {
        result: if fault.is_none() {
            c.commissioning_result()
        } else {
            None
        },
        fault,
        duration_s: cl.time_s() - start,
    })
}
