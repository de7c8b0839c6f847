//! The `Reject` reply: why a command was refused ([`RejectReason`], the reason codes)
//! and the refusal with the bound it broke ([`Rejection`]), from a controller, parameter,
//! compensation or decode error.

use super::error::DecodeError;
use super::function::Function;
use super::id;
use super::request::Request;
use super::wire::{wire_bound, MODE_CODE_MAX, SETPOINT_PA_PER_LSB, SETPOINT_RAD_S_PER_LSB};
use crate::compensation::record::RecordError;
use crate::compensation::CompensationError;
use crate::controller::CommandError;
use crate::parameters::ParamError;
use crate::step_test::StepTestError;
use crate::supervisor::{Mode, ModeRefusal};

/// Why a command was refused (byte 1 of a reject frame).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RejectReason {
    /// Value below the minimum (the bound is the minimum). Code 1.
    BelowMinimum,
    /// Value above the maximum (the bound is the maximum). Code 2.
    AboveMaximum,
    /// Wrong data length (the bound is the expected DLC). Code 3.
    WrongLength,
    /// Unknown mode code (the bound is the highest mode code). Code 4.
    UnknownMode,
    /// Not allowed in the present state (the bound is the blocking fault's code, 0 for a
    /// mode transition that must go through Disabled). Code 5.
    NotAllowed,
    /// Unknown function in a command identifier. Code 6.
    UnknownFunction,
    /// Value refused for another reason. Code 7.
    Invalid,
    /// Unknown parameter id or step-test loop code. Code 8.
    UnknownCode,
    /// The drive is not ready for the mode yet (the bound says for what: 1 current
    /// offsets being measured, 2 rotor angle unknown). Code 9.
    NotReady,
}

impl RejectReason {
    /// Every reason, in code order.
    pub const ALL: [RejectReason; 9] = [
        RejectReason::BelowMinimum,
        RejectReason::AboveMaximum,
        RejectReason::WrongLength,
        RejectReason::UnknownMode,
        RejectReason::NotAllowed,
        RejectReason::UnknownFunction,
        RejectReason::Invalid,
        RejectReason::UnknownCode,
        RejectReason::NotReady,
    ];

    /// The wire code.
    pub fn code(self) -> u8 {
        match self {
            RejectReason::BelowMinimum => 1,
            RejectReason::AboveMaximum => 2,
            RejectReason::WrongLength => 3,
            RejectReason::UnknownMode => 4,
            RejectReason::NotAllowed => 5,
            RejectReason::UnknownFunction => 6,
            RejectReason::Invalid => 7,
            RejectReason::UnknownCode => 8,
            RejectReason::NotReady => 9,
        }
    }

    /// Parses a wire code.
    pub fn from_code(code: u8) -> Option<RejectReason> {
        match code {
            1 => Some(RejectReason::BelowMinimum),
            2 => Some(RejectReason::AboveMaximum),
            3 => Some(RejectReason::WrongLength),
            4 => Some(RejectReason::UnknownMode),
            5 => Some(RejectReason::NotAllowed),
            6 => Some(RejectReason::UnknownFunction),
            7 => Some(RejectReason::Invalid),
            8 => Some(RejectReason::UnknownCode),
            9 => Some(RejectReason::NotReady),
            _ => None,
        }
    }
}

/// A refused command, in wire units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rejection {
    /// Function code of the refused command (identifier base >> 4); kept raw because an
    /// unknown function is itself a reason for rejection.
    pub function: u8,
    /// Why.
    pub reason: RejectReason,
    /// The violated bound in the command's wire unit (Pa, mrad/s, mode code or DLC); for
    /// the configuration and test functions the bit pattern of an `f32` in SI units (see
    /// [`Rejection::si_bound`]).
    pub bound: i32,
    /// Parameter id (or unknown code) the refusal concerns, `0` for none.
    pub parameter: u8,
}

impl Rejection {
    /// The reply for a well-formed request the controller refused, naming the violated
    /// bound in the request's wire unit (rounded to the nearest wire LSB).
    pub fn for_command_error(request: &Request, err: &CommandError) -> Rejection {
        let function = request.function().code();
        let (reason, bound) = match *err {
            CommandError::PressureOutOfRange { min_pa, max_pa } => match request {
                Request::SetPressure { pa } if (*pa as f32) < min_pa => (
                    RejectReason::BelowMinimum,
                    wire_bound(min_pa, SETPOINT_PA_PER_LSB),
                ),
                Request::SetPressure { .. } => (
                    RejectReason::AboveMaximum,
                    wire_bound(max_pa, SETPOINT_PA_PER_LSB),
                ),
                _ => (RejectReason::Invalid, 0),
            },
            CommandError::SpeedOutOfRange { max_rad_s } => match request {
                Request::SetSpeed { mrad_s } if *mrad_s < 0 => (
                    RejectReason::BelowMinimum,
                    wire_bound(-max_rad_s, SETPOINT_RAD_S_PER_LSB),
                ),
                Request::SetSpeed { .. } => (
                    RejectReason::AboveMaximum,
                    wire_bound(max_rad_s, SETPOINT_RAD_S_PER_LSB),
                ),
                _ => (RejectReason::Invalid, 0),
            },
            CommandError::Mode(ModeRefusal::Faulted(f))
            | CommandError::Mode(ModeRefusal::ConditionPresent(f))
            | CommandError::CausePresent(f) => (RejectReason::NotAllowed, i32::from(f.code())),
            CommandError::Mode(ModeRefusal::Transition { .. }) => (RejectReason::NotAllowed, 0),
            CommandError::Mode(ModeRefusal::NotReady(r)) => {
                (RejectReason::NotReady, i32::from(r.code()))
            }
            CommandError::Parameter(e) => return Rejection::for_parameter_error(&e),
            CommandError::StepTest(e) => {
                let (reason, bound) = match e {
                    StepTestError::WrongMode { required } => {
                        (RejectReason::NotAllowed, f32::from(required.code()))
                    }
                    StepTestError::BelowMinimum { min } => (RejectReason::BelowMinimum, min),
                    StepTestError::AboveMaximum { max } => (RejectReason::AboveMaximum, max),
                    StepTestError::Duration { bound_s } => {
                        let asked_ms = match request {
                            Request::StepTest { duration_ms, .. } => *duration_ms,
                            Request::CompensationSweep { leg_ms, .. } => *leg_ms,
                            _ => 0,
                        };
                        let below = f32::from(asked_ms) * 1e-3 < bound_s;
                        let reason = if below {
                            RejectReason::BelowMinimum
                        } else {
                            RejectReason::AboveMaximum
                        };
                        (reason, bound_s)
                    }
                };
                return Rejection::with_si_bound(request.function(), reason, bound, 0);
            }
            CommandError::Compensation(e) => {
                return Rejection::for_compensation_error(request.function(), &e)
            }
        };
        Rejection {
            function,
            reason,
            bound,
            parameter: 0,
        }
    }

    /// The reply for a refused `SetParameter`: names the parameter and, for a value out of
    /// its bounds, the bound.
    pub fn for_parameter_error(err: &ParamError) -> Rejection {
        let (reason, bound) = match *err {
            ParamError::BelowMinimum { min, .. } => (RejectReason::BelowMinimum, min),
            ParamError::AboveMaximum { max, .. } => (RejectReason::AboveMaximum, max),
            ParamError::NotWhileRunning { .. } => {
                (RejectReason::NotAllowed, f32::from(Mode::Disabled.code()))
            }
            ParamError::NotANumber { .. }
            | ParamError::NotWhole { .. }
            | ParamError::Inconsistent { .. } => (RejectReason::Invalid, 0.0),
        };
        Rejection::with_si_bound(Function::SetParameter, reason, bound, err.id().code())
    }

    /// The reply for a refused feed-forward table frame: an amplitude over the limit names
    /// the limit [A] (reason `AboveMaximum`), an out-of-order bin the bin expected, an
    /// incomplete load the bins received (reason `Invalid`), a bin or commit without a
    /// header reason `NotAllowed`, a bad CRC or exponent reason `Invalid` with bound 0 or
    /// the largest exponent.
    pub fn for_compensation_error(function: Function, err: &CompensationError) -> Rejection {
        let (reason, bound) = match *err {
            CompensationError::Amplitude { limit_a, .. } => (RejectReason::AboveMaximum, limit_a),
            CompensationError::Record(r) => match r {
                RecordError::OutOfOrder { expected } => {
                    (RejectReason::Invalid, f32::from(expected))
                }
                RecordError::Incomplete { received } => {
                    (RejectReason::Invalid, f32::from(received))
                }
                RecordError::NotLoading => (RejectReason::NotAllowed, 0.0),
                RecordError::Exponent { .. } => (
                    RejectReason::AboveMaximum,
                    f32::from(crate::compensation::MAX_EXPONENT),
                ),
                RecordError::Bins { .. } => {
                    (RejectReason::Invalid, crate::compensation::BINS as f32)
                }
                _ => (RejectReason::Invalid, 0.0),
            },
        };
        Rejection::with_si_bound(function, reason, bound, 0)
    }

    /// A refusal of a configuration or test function, with an SI bound.
    pub fn with_si_bound(
        function: Function,
        reason: RejectReason,
        bound: f32,
        parameter: u8,
    ) -> Rejection {
        Rejection {
            function: function.code(),
            reason,
            // The f32's bit pattern travels in the i32 field unchanged.
            bound: bound.to_bits() as i32,
            parameter,
        }
    }

    /// The bound in SI units for the configuration and test functions (codes
    /// `0x20`‥`0x27`), whose bound field is an `f32`; `None` for the others.
    pub fn si_bound(&self) -> Option<f32> {
        let configuration = Function::from_code(self.function)
            .is_some_and(|f| f.id_base() >= id::SET_PARAMETER && f != Function::Commission);
        let si_reason = matches!(
            self.reason,
            RejectReason::BelowMinimum
                | RejectReason::AboveMaximum
                | RejectReason::NotAllowed
                | RejectReason::Invalid
        );
        (configuration && si_reason).then(|| f32::from_bits(self.bound as u32))
    }

    /// The reply the drive sends for a command frame that failed to decode, or `None` when
    /// the frame is to be ignored silently (addressed to another node, or not a command).
    pub fn for_decode_error(err: &DecodeError) -> Option<Rejection> {
        match *err {
            DecodeError::WrongLength {
                function, expected, ..
            } => Some(Rejection {
                function: function.code(),
                reason: RejectReason::WrongLength,
                bound: i32::from(expected),
                parameter: 0,
            }),
            DecodeError::UnknownMode { .. } => Some(Rejection {
                function: Function::SetMode.code(),
                reason: RejectReason::UnknownMode,
                bound: i32::from(MODE_CODE_MAX),
                parameter: 0,
            }),
            DecodeError::UnknownFunction { id } => Some(Rejection {
                // An 11-bit identifier shifted by 4 fits a byte.
                function: (id >> 4) as u8,
                reason: RejectReason::UnknownFunction,
                bound: 0,
                parameter: 0,
            }),
            DecodeError::UnknownCode { function, code } => Some(Rejection {
                function: function.code(),
                reason: RejectReason::UnknownCode,
                bound: 0,
                parameter: code,
            }),
            _ => None,
        }
    }
}
