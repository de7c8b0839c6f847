//! The commands the host sends: the real-time commands (`SetMode`, `SetPressure`,
//! `SetSpeed`, `ClearFaults`, `Heartbeat`), the parameter commands (`SetParameter`,
//! `GetParameter`, `SaveParameters`) and the test and compensation commands (`StepTest`,
//! `Commission`, `CompensationBin`, `CompensationCommit`, `CompensationSweep`) as
//! [`Request`] values, and their translation to the controller's commands.

use super::function::Function;
use super::wire::{to_wire, EncodeError, SETPOINT_PA_PER_LSB, SETPOINT_RAD_S_PER_LSB};
use crate::controller::Command;
use crate::parameters::ParamId;
use crate::step_test::StepLoop;
use crate::supervisor::Mode;

/// A command as carried on the wire, in wire units (integers or `f32` bit patterns, so an
/// encode/decode round trip is exact).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Request {
    /// Switch the operating mode.
    SetMode(Mode),
    /// Pressure setpoint, gauge. [Pa]
    SetPressure {
        /// Setpoint. [Pa]
        pa: i32,
    },
    /// Speed setpoint. [mrad/s]
    SetSpeed {
        /// Setpoint. [mrad/s]
        mrad_s: i32,
    },
    /// Clear latched faults whose cause is gone.
    ClearFaults,
    /// Keep the command watchdog fed.
    Heartbeat,
    /// Set a parameter of the live table.
    SetParameter {
        /// The parameter.
        id: ParamId,
        /// New value. [the parameter's unit]
        value: f32,
    },
    /// Read a parameter of the live table.
    GetParameter {
        /// The parameter.
        id: ParamId,
    },
    /// Save the live table to flash.
    SaveParameters,
    /// Step one loop's reference for a while, with telemetry at full rate.
    StepTest {
        /// The stepped loop.
        target: StepLoop,
        /// Step added to the present reference. [A, rad/s or Pa]
        amplitude: f32,
        /// How long the step is held. [ms]
        duration_ms: u16,
    },
    /// Run the commissioning sequence (motor identification and gain design).
    Commission,
    /// Start loading the torque feed-forward's table.
    CompensationHeader {
        /// LSB exponent per channel. [1]
        exponents: [i8; 3],
        /// Bins per revolution.
        bins: u16,
    },
    /// One bin of the table being loaded.
    CompensationBin {
        /// Bin index (below [`COMPENSATION_HEADER_BIN`]).
        ///
        /// [`COMPENSATION_HEADER_BIN`]: super::wire::COMPENSATION_HEADER_BIN
        bin: u16,
        /// The three channels' raw values.
        raw: [i16; 3],
    },
    /// Commit the loaded table.
    CompensationCommit {
        /// CRC-32 of the table's record.
        crc: u32,
    },
    /// Run the feed-forward's bench sweep.
    CompensationSweep {
        /// Speed of the first leg. [rad/s]
        speed_rad_s: f32,
        /// Duration of each leg. [ms]
        leg_ms: u16,
    },
}

impl Request {
    /// A pressure setpoint from SI units, rounded to the wire resolution; fails for a
    /// value that is not finite or does not fit the `i32` field.
    pub fn pressure_from_pa(pa: f32) -> Result<Request, EncodeError> {
        to_wire(pa, SETPOINT_PA_PER_LSB, "pressure setpoint [Pa]")
            .map(|pa| Request::SetPressure { pa })
    }

    /// A speed setpoint from SI units, rounded to the wire resolution; fails for a value
    /// that is not finite or does not fit the `i32` field.
    pub fn speed_from_rad_s(rad_s: f32) -> Result<Request, EncodeError> {
        to_wire(rad_s, SETPOINT_RAD_S_PER_LSB, "speed setpoint [rad/s]")
            .map(|mrad_s| Request::SetSpeed { mrad_s })
    }

    /// Which command this is.
    pub fn function(&self) -> Function {
        match self {
            Request::SetMode(_) => Function::SetMode,
            Request::SetPressure { .. } => Function::SetPressure,
            Request::SetSpeed { .. } => Function::SetSpeed,
            Request::ClearFaults => Function::ClearFaults,
            Request::Heartbeat => Function::Heartbeat,
            Request::SetParameter { .. } => Function::SetParameter,
            Request::GetParameter { .. } => Function::GetParameter,
            Request::SaveParameters => Function::SaveParameters,
            Request::StepTest { .. } => Function::StepTest,
            Request::Commission => Function::Commission,
            Request::CompensationHeader { .. } | Request::CompensationBin { .. } => {
                Function::CompensationBin
            }
            Request::CompensationCommit { .. } => Function::CompensationCommit,
            Request::CompensationSweep { .. } => Function::CompensationSweep,
        }
    }

    /// Pressure setpoint in SI units, if this is one. [Pa]
    pub fn pressure_pa(&self) -> Option<f32> {
        match self {
            Request::SetPressure { pa } => Some(*pa as f32 * SETPOINT_PA_PER_LSB),
            _ => None,
        }
    }

    /// The control core's command for this request (setpoints converted to SI units), or
    /// `None` for a request the application serves itself (`GetParameter` reads
    /// [`crate::Controller::parameter`], `SaveParameters` writes the flash).
    pub fn to_command(&self) -> Option<Command> {
        Some(match *self {
            Request::SetMode(mode) => Command::SetMode(mode),
            Request::SetPressure { pa } => Command::SetPressure {
                pa: pa as f32 * SETPOINT_PA_PER_LSB,
            },
            Request::SetSpeed { mrad_s } => Command::SetSpeed {
                rad_s: mrad_s as f32 * SETPOINT_RAD_S_PER_LSB,
            },
            Request::ClearFaults => Command::ClearFaults,
            Request::Heartbeat => Command::Heartbeat,
            Request::SetParameter { id, value } => Command::SetParameter { id, value },
            Request::StepTest {
                target,
                amplitude,
                duration_ms,
            } => Command::StepTest {
                target,
                amplitude,
                duration_s: f32::from(duration_ms) * 1e-3,
            },
            Request::Commission => Command::Commission,
            Request::CompensationHeader { exponents, bins } => {
                Command::CompensationHeader { exponents, bins }
            }
            Request::CompensationBin { bin, raw } => Command::CompensationBin { bin, raw },
            Request::CompensationCommit { crc } => Command::CompensationCommit { crc },
            Request::CompensationSweep {
                speed_rad_s,
                leg_ms,
            } => Command::CompensationSweep {
                speed_rad_s,
                leg_s: f32::from(leg_ms) * 1e-3,
            },
            Request::GetParameter { .. } | Request::SaveParameters => return None,
        })
    }

    /// Speed setpoint in SI units, if this is one. [rad/s]
    pub fn speed_rad_s(&self) -> Option<f32> {
        match self {
            Request::SetSpeed { mrad_s } => Some(*mrad_s as f32 * SETPOINT_RAD_S_PER_LSB),
            _ => None,
        }
    }
}
