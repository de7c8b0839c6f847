//! The replies the drive sends: `Status` (mode, fault, pressure, speed, last command),
//! `Reject` ([`super::reject`]), `Parameter` and `Diagnostics`, as [`Reply`] values.

use super::reject::Rejection;
use super::wire::{saturate_i16, STATUS_PA_PER_LSB, STATUS_RAD_S_PER_LSB};
use crate::parameters::ParamId;
use crate::supervisor::Mode;

/// Periodic drive status, in wire units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Status {
    /// Operating mode code (see [`Mode`]).
    pub mode: u8,
    /// Controller fault code, `0` for none.
    pub fault: u8,
    /// Measured pressure, gauge. [kPa]
    pub pressure_kpa: i16,
    /// Measured shaft speed. [0.1 rad/s]
    pub speed_drad_s: i16,
    /// Function code of the last accepted command, [`NO_COMMAND`] before the first.
    ///
    /// [`NO_COMMAND`]: super::wire::NO_COMMAND
    pub last_command: u8,
    /// Sequence counter.
    pub sequence: u8,
}

impl Status {
    /// Builds a status from SI measurements, saturating them to the wire fields.
    pub fn from_si(
        mode: Mode,
        fault: u8,
        pressure_pa: f32,
        speed_rad_s: f32,
        last_command: u8,
        sequence: u8,
    ) -> Status {
        Status {
            mode: mode.code(),
            fault,
            pressure_kpa: saturate_i16(pressure_pa / STATUS_PA_PER_LSB),
            speed_drad_s: saturate_i16(speed_rad_s / STATUS_RAD_S_PER_LSB),
            last_command,
            sequence,
        }
    }
}

/// The drive's measurements of itself, sent once a second.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Diagnostics {
    /// Stack high-water mark since power-up. [bytes]
    pub stack_peak_bytes: u32,
    /// The stack's size. [bytes]
    pub stack_size_bytes: u32,
}

/// A frame sent by the drive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reply {
    /// Periodic or acknowledging status.
    Status(Status),
    /// Refused command.
    Reject(Rejection),
    /// A parameter's value in use (answer to `GetParameter` and `SetParameter`).
    Parameter {
        /// The parameter.
        id: ParamId,
        /// Its value. [the parameter's unit]
        value: f32,
    },
    /// The drive's measurements of itself.
    Diagnostics(Diagnostics),
}
