//! The commands the drive takes (over CAN or from the host) and why one is refused:
//! [`Command`] and [`CommandError`], whose code is the CAN reject reason.

use crate::compensation::{CompensationError, Exponent, CHANNELS};
use crate::parameters::{ParamError, ParamId};
use crate::step_test::{StepLoop, StepTestError};
use crate::supervisor::{FaultCode, Mode, ModeRefusal};
use core::fmt;

/// A command to the drive (CAN or host).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    /// Requests a mode.
    SetMode(Mode),
    /// Pressure setpoint (gauge). [Pa]
    SetPressure {
        /// Setpoint. [Pa]
        pa: f32,
    },
    /// Speed setpoint. [rad/s]
    SetSpeed {
        /// Setpoint. [rad/s]
        rad_s: f32,
    },
    /// Clears a latched fault once its cause is gone.
    ClearFaults,
    /// Keeps the command timeout from expiring.
    Heartbeat,
    /// Enters Calibrating and runs the commissioning sequence after the current offsets
    /// (motor identification and gain design, [`crate::commissioning`]) instead of the
    /// plain encoder alignment.
    Commission,
    /// Sets one parameter of the live table (bounds: [`ParamId::min`], [`ParamId::max`]).
    SetParameter {
        /// The parameter.
        id: ParamId,
        /// New value. [the parameter's unit]
        value: f32,
    },
    /// Steps one loop's reference for a while with telemetry at full rate
    /// ([`crate::step_test`]).
    StepTest {
        /// The stepped loop.
        target: StepLoop,
        /// Step added to the present reference. [A, rad/s or Pa]
        amplitude: f32,
        /// How long the step is held. [s]
        duration_s: f32,
    },
    /// Starts loading the torque feed-forward's table ([`crate::compensation`]): the
    /// feed-forward is off until the commit.
    CompensationHeader {
        /// LSB exponent e per channel (values are i16 · 2^−e). [1]
        exponents: [Exponent; CHANNELS],
        /// Bins per revolution of the table sent (must be [`crate::compensation::BINS`]).
        bins: u16,
    },
    /// The next bin of the table being loaded (in order from 0).
    CompensationBin {
        /// Bin index.
        bin: u16,
        /// The three channels' raw values.
        raw: [i16; CHANNELS],
    },
    /// Ends a table load: the CRC of the record the bins make; the table is checked
    /// against the amplitude limit and takes effect.
    CompensationCommit {
        /// CRC-32 of the table's record ([`crate::compensation::record`]).
        crc: u32,
    },
    /// The feed-forward's bench procedure ([`crate::sweep`]): a constant-speed sweep in
    /// both directions, in Speed mode.
    CompensationSweep {
        /// Speed of the first leg. [rad/s]
        speed_rad_s: f32,
        /// Duration of each leg. [s]
        leg_s: f32,
    },
}

/// Why a command was refused. Its [`CommandError::code`] shows in telemetry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CommandError {
    /// Pressure setpoint outside `[min_pa, max_pa]` (`pressure.setpoint_min_pa`,
    /// `pressure.setpoint_max_pa`), or not finite.
    PressureOutOfRange {
        /// Lower bound. [Pa]
        min_pa: f32,
        /// Upper bound. [Pa]
        max_pa: f32,
    },
    /// Speed setpoint magnitude above `max_rad_s` (`speed.speed_limit_rad_s`), or not
    /// finite.
    SpeedOutOfRange {
        /// Bound on the magnitude. [rad/s]
        max_rad_s: f32,
    },
    /// Mode request refused.
    Mode(ModeRefusal),
    /// ClearFaults refused: the fault's cause is still present.
    CausePresent(FaultCode),
    /// Parameter value refused.
    Parameter(ParamError),
    /// Step test (or feed-forward sweep) refused.
    StepTest(StepTestError),
    /// Feed-forward table refused.
    Compensation(CompensationError),
}

impl CommandError {
    /// Status code for telemetry and CAN replies (0 means accepted).
    pub fn code(&self) -> u8 {
        match self {
            CommandError::PressureOutOfRange { .. } => 1,
            CommandError::SpeedOutOfRange { .. } => 2,
            CommandError::Mode(ModeRefusal::Faulted(_)) => 3,
            CommandError::Mode(ModeRefusal::ConditionPresent(_)) => 4,
            CommandError::Mode(ModeRefusal::Transition { .. }) => 5,
            CommandError::Mode(ModeRefusal::NotReady(_)) => 9,
            CommandError::CausePresent(_) => 6,
            CommandError::Parameter(_) => 7,
            CommandError::StepTest(_) => 8,
            CommandError::Compensation(_) => 10,
        }
    }
}

impl fmt::Display for CommandError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CommandError::PressureOutOfRange { min_pa, max_pa } => write!(
                f,
                "pressure setpoint outside [{min_pa} Pa, {max_pa} Pa] (pressure.setpoint_min_pa..=pressure.setpoint_max_pa)"
            ),
            CommandError::SpeedOutOfRange { max_rad_s } => write!(
                f,
                "speed setpoint magnitude above {max_rad_s} rad/s (speed.speed_limit_rad_s)"
            ),
            CommandError::Mode(ModeRefusal::Faulted(x)) => {
                write!(f, "mode refused: {x} is latched (clear it first)")
            }
            CommandError::Mode(ModeRefusal::ConditionPresent(x)) => {
                write!(f, "mode refused: condition present ({x})")
            }
            CommandError::Mode(ModeRefusal::Transition { from, to }) => {
                write!(f, "mode refused: {from:?} -> {to:?} (go through Disabled)")
            }
            CommandError::Mode(ModeRefusal::NotReady(r)) => {
                write!(f, "mode refused: not ready, {r}")
            }
            CommandError::CausePresent(x) => write!(f, "clear refused: cause still present ({x})"),
            CommandError::Parameter(e) => write!(f, "parameter refused: {e}"),
            CommandError::StepTest(StepTestError::WrongMode { required }) => {
                write!(f, "step test refused: needs mode {required:?}")
            }
            CommandError::StepTest(StepTestError::BelowMinimum { min }) => {
                write!(f, "step test refused: amplitude below {min} (loop limit)")
            }
            CommandError::StepTest(StepTestError::AboveMaximum { max }) => {
                write!(f, "step test refused: amplitude above {max} (loop limit)")
            }
            CommandError::StepTest(StepTestError::Duration { bound_s }) => {
                write!(f, "step test refused: duration beyond {bound_s} s")
            }
            CommandError::Compensation(e) => write!(f, "{e}"),
        }
    }
}
