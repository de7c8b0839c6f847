//! The step-test command: a programmed step of one loop's reference (q current, speed or
//! pressure) for a set duration, with telemetry at full rate (one frame per PWM period)
//! while it runs, then the previous reference and decimation back.
//!
//! The step is added to the reference in use when the test starts, so a test at an
//! operating point measures the small-signal step response there (the method of the
//! bench: a step of known amplitude, the response read from the full-rate log). The
//! stepped reference must stay within the loop's limits (`speed.iq_limit_a`,
//! `speed.speed_limit_rad_s`, `pressure.setpoint_min_pa..=setpoint_max_pa`); a current
//! step runs in Speed mode with the speed loop suspended, a speed step in Speed mode and a
//! pressure step in Pressure mode (through the configured setpoint ramp). A mode change,
//! a fault or a new setpoint command ends the test early.

use crate::supervisor::Mode;

/// Longest step test. [s]
pub const MAX_DURATION_S: f32 = 10.0;
/// Shortest step test. [s]
pub const MIN_DURATION_S: f32 = 1e-3;

/// Which loop's reference is stepped; the code is the wire code of the step-test frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum StepLoop {
    /// q-current reference [A], in Speed mode (speed loop suspended). Code 1.
    Current = 1,
    /// Speed setpoint [rad/s], in Speed mode. Code 2.
    Speed = 2,
    /// Pressure setpoint [Pa], in Pressure mode. Code 3.
    Pressure = 3,
}

impl StepLoop {
    /// Every loop, in code order.
    pub const ALL: [StepLoop; 3] = [StepLoop::Current, StepLoop::Speed, StepLoop::Pressure];

    /// Wire code.
    pub fn code(self) -> u8 {
        self as u8
    }

    /// From the wire code.
    pub fn from_code(code: u8) -> Option<StepLoop> {
        match code {
            1 => Some(StepLoop::Current),
            2 => Some(StepLoop::Speed),
            3 => Some(StepLoop::Pressure),
            _ => None,
        }
    }

    /// The mode the step needs.
    pub fn mode(self) -> Mode {
        match self {
            StepLoop::Current | StepLoop::Speed => Mode::Speed,
            StepLoop::Pressure => Mode::Pressure,
        }
    }
}

/// Why a step test was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StepTestError {
    /// The drive is not in the mode the loop needs.
    WrongMode {
        /// The mode needed.
        required: Mode,
    },
    /// The stepped reference would be below the loop's lower limit.
    BelowMinimum {
        /// Smallest amplitude accepted now (limit minus present reference). [A, rad/s, Pa]
        min: f32,
    },
    /// The stepped reference would be above the loop's upper limit.
    AboveMaximum {
        /// Largest amplitude accepted now (limit minus present reference). [A, rad/s, Pa]
        max: f32,
    },
    /// Duration outside [`MIN_DURATION_S`]..=[`MAX_DURATION_S`].
    Duration {
        /// The violated bound. [s]
        bound_s: f32,
    },
}

/// A running step test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActiveStep {
    /// The stepped loop.
    pub target: StepLoop,
    /// Reference before the step, restored at the end. [A, rad/s, Pa]
    pub base: f32,
    /// Stepped reference. [A, rad/s, Pa]
    pub stepped: f32,
    /// PWM periods left.
    pub remaining: u32,
}

/// Checks a request and returns the test to run: `reference` is the loop's present
/// reference, `[lo, hi]` its limits, `pwm_hz` the period rate the duration is counted in.
pub fn plan(
    target: StepLoop,
    amplitude: f32,
    duration_s: f32,
    reference: f32,
    limits: (f32, f32),
    pwm_hz: f32,
) -> Result<ActiveStep, StepTestError> {
    let (lo, hi) = limits;
    if duration_s.is_nan() || duration_s < MIN_DURATION_S {
        return Err(StepTestError::Duration {
            bound_s: MIN_DURATION_S,
        });
    }
    if duration_s > MAX_DURATION_S {
        return Err(StepTestError::Duration {
            bound_s: MAX_DURATION_S,
        });
    }
    let stepped = reference + amplitude;
    if amplitude.is_nan() || stepped < lo {
        return Err(StepTestError::BelowMinimum {
            min: lo - reference,
        });
    }
    if stepped > hi {
        return Err(StepTestError::AboveMaximum {
            max: hi - reference,
        });
    }
    // duration ≤ 10 s and pwm ≤ 100 kHz: at most 1e6 periods, exact in u32.
    let remaining = libm::roundf(duration_s * pwm_hz) as u32;
    Ok(ActiveStep {
        target,
        base: reference,
        stepped,
        remaining: remaining.max(1),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_inside_the_limits_runs_for_its_duration() {
        // 0.25 s at 20 kHz = 5000 periods; 50 + 20 rad/s within ±200 rad/s.
        let s = plan(StepLoop::Speed, 20.0, 0.25, 50.0, (-200.0, 200.0), 20e3).unwrap();
        assert_eq!((s.base, s.stepped, s.remaining), (50.0, 70.0, 5000));
    }

    #[test]
    fn steps_beyond_the_limits_name_the_largest_amplitude() {
        // From 5 MPa the 18 MPa maximum leaves a 13 MPa step.
        let e = plan(StepLoop::Pressure, 14e6, 1.0, 5e6, (0.0, 18e6), 20e3);
        assert_eq!(e, Err(StepTestError::AboveMaximum { max: 13e6 }));
        let e = plan(StepLoop::Pressure, -6e6, 1.0, 5e6, (0.0, 18e6), 20e3);
        assert_eq!(e, Err(StepTestError::BelowMinimum { min: -5e6 }));
        let e = plan(StepLoop::Current, f32::NAN, 1.0, 0.0, (-30.0, 30.0), 20e3);
        assert!(matches!(e, Err(StepTestError::BelowMinimum { .. })));
    }

    #[test]
    fn durations_outside_the_window_are_refused() {
        let e = plan(StepLoop::Speed, 1.0, 11.0, 0.0, (-200.0, 200.0), 20e3);
        assert_eq!(e, Err(StepTestError::Duration { bound_s: 10.0 }));
        let e = plan(StepLoop::Speed, 1.0, 0.0, 0.0, (-200.0, 200.0), 20e3);
        assert_eq!(e, Err(StepTestError::Duration { bound_s: 1e-3 }));
        let e = plan(StepLoop::Speed, 1.0, f32::NAN, 0.0, (-200.0, 200.0), 20e3);
        assert!(matches!(e, Err(StepTestError::Duration { .. })));
    }

    #[test]
    fn loop_codes_round_trip_and_name_their_mode() {
        for (code, mode) in [(1, Mode::Speed), (2, Mode::Speed), (3, Mode::Pressure)] {
            let l = StepLoop::from_code(code).unwrap();
            assert_eq!((l.code(), l.mode()), (code, mode));
        }
        assert_eq!(StepLoop::from_code(0), None);
        assert_eq!(StepLoop::from_code(4), None);
    }
}
