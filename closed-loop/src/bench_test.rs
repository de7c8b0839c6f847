//! The bench tests a diagnosis is run on, as scenarios built from their parameters: a
//! pressure step, a pressure staircase and a sinusoidal pressure on the blocked cylinder,
//! and a stroke of the free payload out and back under speed control. Each starts at rest
//! at the boost pressure, as a bench run does, and streams its setpoint ([`Profile`]).
//!
//! A test generator draws the parameters and builds its scenario with these functions; the
//! named defaults in [`crate::SCENARIOS`] are the same functions at fixed values.

use crate::plan::{Scenario, ScenarioKind, MAX_EVENTS};
use crate::profile::{Profile, ProfileError, Setpoint, Sine};
use firmware::{Command, Mode};

/// Where every test starts: chamber A at the boost pressure, at rest. [Pa]
pub const START_PRESSURE_PA: f64 = 0.5e6;

/// How long a test holds its start before the setpoint moves (the drive enters its mode
/// and settles). [s]
pub const SETTLE_S: f64 = 0.5;

/// Most levels of a staircase.
pub const MAX_LEVELS: usize = 5;

/// The events that put the drive in pressure control at the start pressure.
const PRESSURE_START: [Option<(f64, Command)>; MAX_EVENTS] = [
    Some((
        0.0,
        Command::SetPressure {
            pa: START_PRESSURE_PA as f32,
        },
    )),
    Some((0.0, Command::SetMode(Mode::Pressure))),
    None,
    None,
    None,
    None,
];

/// The events that put the drive in speed control at standstill.
const SPEED_START: [Option<(f64, Command)>; MAX_EVENTS] = [
    Some((0.0, Command::SetSpeed { rad_s: 0.0 })),
    Some((0.0, Command::SetMode(Mode::Speed))),
    None,
    None,
    None,
    None,
];

/// The start of a pressure profile: held at the start pressure for [`SETTLE_S`], then
/// ramped over `ramp_s` [s] to `level_pa` [Pa].
const fn ramp_to(level_pa: f64, ramp_s: f64) -> Result<Profile, ProfileError> {
    let p = Profile::new(Setpoint::Pressure);
    let p = match p.with_knot(0.0, START_PRESSURE_PA) {
        Ok(p) => p,
        Err(e) => return Err(e),
    };
    let p = match p.with_knot(SETTLE_S, START_PRESSURE_PA) {
        Ok(p) => p,
        Err(e) => return Err(e),
    };
    p.with_knot(SETTLE_S + ramp_s, level_pa)
}

/// A blocked-cylinder pressure test with `profile`.
const fn pressure_test(
    name: &'static str,
    description: &'static str,
    kind: ScenarioKind,
    profile: Profile,
    steady_from_s: f64,
    duration_s: f64,
) -> Scenario {
    Scenario {
        name,
        description,
        kind,
        blocked: true,
        initial_pressure_pa: START_PRESSURE_PA,
        duration_s,
        steady_from_s,
        events: PRESSURE_START,
        profile: Some(profile),
    }
}

/// The pressure step: a ramp over `ramp_s` [s] to `level_pa` [Pa], held, a step of
/// `step_pa` [Pa] at `step_at_s` [s], held to `duration_s` [s].
pub const fn step_test(
    level_pa: f64,
    ramp_s: f64,
    step_at_s: f64,
    step_pa: f64,
    duration_s: f64,
) -> Result<Scenario, ProfileError> {
    let p = match ramp_to(level_pa, ramp_s) {
        Ok(p) => p,
        Err(e) => return Err(e),
    };
    let p = match p.with_knot(step_at_s, level_pa) {
        Ok(p) => p,
        Err(e) => return Err(e),
    };
    match p.with_knot(step_at_s, level_pa + step_pa) {
        Ok(p) => Ok(pressure_test(
            "pressure-step-test",
            "bench pressure step: ramp from 0.5 MPa to a level, hold, a step near mid-log, hold; blocked cylinder",
            ScenarioKind::PressureStep,
            p,
            SETTLE_S + ramp_s,
            duration_s,
        )),
        Err(e) => Err(e),
    }
}

/// The staircase: a ramp over `ramp_s` [s] to the first of `levels` (pressure [Pa], hold
/// [s]), then each level in turn, stepped to and held its time; the test ends with the
/// last hold.
pub const fn staircase_test(levels: &[(f64, f64)], ramp_s: f64) -> Result<Scenario, ProfileError> {
    if levels.is_empty() || levels.len() > MAX_LEVELS {
        return Err(ProfileError::TooManyKnots);
    }
    let mut p = match ramp_to(levels[0].0, ramp_s) {
        Ok(p) => p,
        Err(e) => return Err(e),
    };
    let mut t = SETTLE_S + ramp_s + levels[0].1;
    let mut k = 1;
    while k < levels.len() {
        p = match p.with_knot(t, levels[k - 1].0) {
            Ok(p) => p,
            Err(e) => return Err(e),
        };
        p = match p.with_knot(t, levels[k].0) {
            Ok(p) => p,
            Err(e) => return Err(e),
        };
        t += levels[k].1;
        k += 1;
    }
    Ok(pressure_test(
        "staircase",
        "pressure staircase: ramp from 0.5 MPa, then levels between 2 and 9 MPa held a few seconds each; blocked cylinder",
        ScenarioKind::Staircase,
        p,
        SETTLE_S + ramp_s,
        t,
    ))
}

/// The sine: a ramp over `ramp_s` [s] to `level_pa` [Pa], a hold of `hold_s` [s], then a
/// sinusoidal setpoint of `amplitude_pa` [Pa] at `frequency_hz` [Hz] to `duration_s` [s].
pub const fn sine_test(
    level_pa: f64,
    ramp_s: f64,
    hold_s: f64,
    amplitude_pa: f64,
    frequency_hz: f64,
    duration_s: f64,
) -> Result<Scenario, ProfileError> {
    let p = match ramp_to(level_pa, ramp_s) {
        Ok(p) => p,
        Err(e) => return Err(e),
    };
    let sine = Sine {
        from_s: SETTLE_S + ramp_s + hold_s,
        amplitude: amplitude_pa,
        frequency_hz,
    };
    match p.with_sine(sine) {
        Ok(p) => Ok(pressure_test(
            "sine",
            "sinusoidal pressure: ramp from 0.5 MPa to a level, a short hold, then a sine of a fraction of a MPa; blocked cylinder",
            ScenarioKind::Sine,
            p,
            SETTLE_S + ramp_s,
            duration_s,
        )),
        Err(e) => Err(e),
    }
}

/// The stroke: payload free, speed control; the speed ramps over `accel_s` [s] to
/// `speed_rad_s` [rad/s], runs, reverses through a ramp of `2·accel_s` centred on
/// `reverse_at_s` [s] and runs back to `duration_s` [s]. `p_ref_pa` stays 0: no pressure
/// loop runs.
pub const fn stroke_test(
    speed_rad_s: f64,
    accel_s: f64,
    reverse_at_s: f64,
    duration_s: f64,
) -> Result<Scenario, ProfileError> {
    let knots = [
        (0.0, 0.0),
        (SETTLE_S, 0.0),
        (SETTLE_S + accel_s, speed_rad_s),
        (reverse_at_s - accel_s, speed_rad_s),
        (reverse_at_s + accel_s, -speed_rad_s),
    ];
    let mut p = Profile::new(Setpoint::Speed);
    let mut k = 0;
    while k < knots.len() {
        p = match p.with_knot(knots[k].0, knots[k].1) {
            Ok(p) => p,
            Err(e) => return Err(e),
        };
        k += 1;
    }
    Ok(Scenario {
        name: "stroke",
        description: "stroke of the free payload under speed control: a constant speed out, reversed once near mid-log, and back",
        kind: ScenarioKind::Stroke,
        blocked: false,
        initial_pressure_pa: START_PRESSURE_PA,
        duration_s,
        steady_from_s: SETTLE_S + accel_s,
        events: SPEED_START,
        profile: Some(p),
    })
}

/// A named default: `built`, which is valid by construction (checked at compile time).
pub(crate) const fn named(built: Result<Scenario, ProfileError>) -> Scenario {
    match built {
        Ok(s) => s,
        Err(_) => panic!("a named test's parameters make a valid profile"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_staircase_holds_each_level_its_time() {
        let s = staircase_test(&[(4e6, 3.0), (7e6, 4.0), (2.5e6, 5.0)], 2.0).expect("valid");
        let p = s.profile.expect("a profile");
        // Ramp ends at 0.5 + 2 = 2.5 s; 4 MPa to 5.5 s, 7 MPa to 9.5 s, 2.5 MPa to 14.5 s.
        assert_eq!(p.value_at(1.5), 0.5e6 + 3.5e6 / 2.0);
        assert_eq!(p.value_at(5.4), 4e6);
        assert_eq!(p.value_at(5.5), 7e6);
        assert_eq!(p.value_at(9.6), 2.5e6);
        assert_eq!(s.duration_s, 14.5);
        assert!(staircase_test(&[(4e6, 3.0); MAX_LEVELS + 1], 2.0).is_err());
    }

    #[test]
    fn the_stroke_comes_back_where_it_started() {
        // Out at full speed for the equivalent of (r − 0.5 − 0.25) s, back for (20 − r) s:
        // equal at r = 10.375 s.
        let s = stroke_test(20.0, 0.5, 10.375, 20.0).expect("valid");
        let p = s.profile.expect("a profile");
        let dt = 1e-3;
        let travel: f64 = (0..20_000).map(|k| p.value_at(k as f64 * dt) * dt).sum();
        assert!(travel.abs() < 0.05, "{travel} rad left");
        assert_eq!(p.value_at(10.375), 0.0);
        assert!(!s.blocked);
    }
}
