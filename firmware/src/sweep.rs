//! The torque feed-forward's bench procedure: a slow constant-speed sweep of the shaft in
//! both directions (moteus records its cogging table the same way), run by the drive
//! itself in Speed mode with the payload free, so the pressure stays at the fill level.
//!
//! The speed setpoint is +ω for the leg's duration, then −ω for as long, then 0; the
//! telemetry at its configured rate is the log `eha compensate` learns the table from.
//! At constant speed the shaft's acceleration is only the ripple's own, so the torque
//! balance per revolution reads the angle-locked torques directly; turning both ways lets
//! the host tell a torque fixed to the angle (same sign both ways: cogging, a current
//! offset's image) from one that follows the motion (friction, a lag). At the fill
//! pressure the load-scaled effects (the pump's ripple ∝ Δp, the flux harmonics ∝ i_q)
//! are too small to see: their channels come from a log at working pressure (a hold,
//! `docs/compensation.md`). A new speed setpoint, a mode change or a fault ends the sweep.

use crate::step_test::StepTestError;
use crate::supervisor::Mode;

/// Shortest leg. [s]
pub const MIN_LEG_S: f32 = 0.5;
/// Longest leg. [s]
pub const MAX_LEG_S: f32 = 60.0;

/// A running sweep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sweep {
    /// Speed of the first leg (the second is its opposite). [rad/s]
    pub speed_rad_s: f32,
    /// PWM periods per leg.
    pub leg_periods: u32,
    /// PWM periods run.
    pub elapsed: u32,
}

impl Sweep {
    /// Checks a request in `mode` against the speed limit `limit_rad_s` [rad/s]: a speed
    /// of magnitude in (0, limit], legs of [`MIN_LEG_S`]..=[`MAX_LEG_S`] counted at
    /// `pwm_hz` periods per second.
    pub fn plan(
        mode: Mode,
        speed_rad_s: f32,
        leg_s: f32,
        limit_rad_s: f32,
        pwm_hz: f32,
    ) -> Result<Sweep, StepTestError> {
        if mode != Mode::Speed {
            return Err(StepTestError::WrongMode {
                required: Mode::Speed,
            });
        }
        if leg_s.is_nan() || leg_s < MIN_LEG_S {
            return Err(StepTestError::Duration { bound_s: MIN_LEG_S });
        }
        if leg_s > MAX_LEG_S {
            return Err(StepTestError::Duration { bound_s: MAX_LEG_S });
        }
        if speed_rad_s.is_nan() || speed_rad_s < -limit_rad_s {
            return Err(StepTestError::BelowMinimum { min: -limit_rad_s });
        }
        if speed_rad_s > limit_rad_s {
            return Err(StepTestError::AboveMaximum { max: limit_rad_s });
        }
        if speed_rad_s == 0.0 {
            // A sweep that does not turn: the smallest magnitude accepted is above 0.
            return Err(StepTestError::BelowMinimum { min: 0.0 });
        }
        Ok(Sweep {
            speed_rad_s,
            leg_periods: (leg_s * pwm_hz) as u32,
            elapsed: 0,
        })
    }

    /// The speed setpoint of the next period [rad/s], `None` once both legs are done.
    #[inline]
    pub fn advance(&mut self) -> Option<f32> {
        let k = self.elapsed;
        self.elapsed = self.elapsed.saturating_add(1);
        if k < self.leg_periods {
            Some(self.speed_rad_s)
        } else if k < 2 * self.leg_periods {
            Some(-self.speed_rad_s)
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_legs_of_opposite_speed_then_done() {
        let mut s = Sweep::plan(Mode::Speed, 8.0, 0.5, 200.0, 100.0).unwrap();
        let seen: std::vec::Vec<Option<f32>> = (0..101).map(|_| s.advance()).collect();
        assert!(seen[..50].iter().all(|w| *w == Some(8.0)));
        assert!(seen[50..100].iter().all(|w| *w == Some(-8.0)));
        assert_eq!(seen[100], None);
    }

    #[test]
    fn requests_outside_the_limits_are_refused_naming_the_bound() {
        let plan = |mode, w, t| Sweep::plan(mode, w, t, 200.0, 20e3);
        assert_eq!(
            plan(Mode::Pressure, 8.0, 5.0),
            Err(StepTestError::WrongMode {
                required: Mode::Speed
            })
        );
        assert_eq!(
            plan(Mode::Speed, 250.0, 5.0),
            Err(StepTestError::AboveMaximum { max: 200.0 })
        );
        assert_eq!(
            plan(Mode::Speed, -250.0, 5.0),
            Err(StepTestError::BelowMinimum { min: -200.0 })
        );
        assert_eq!(
            plan(Mode::Speed, 8.0, 100.0),
            Err(StepTestError::Duration { bound_s: 60.0 })
        );
        assert_eq!(
            plan(Mode::Speed, 8.0, f32::NAN),
            Err(StepTestError::Duration { bound_s: 0.5 })
        );
        assert!(plan(Mode::Speed, 0.0, 5.0).is_err());
        assert!(plan(Mode::Speed, f32::NAN, 5.0).is_err());
    }
}
