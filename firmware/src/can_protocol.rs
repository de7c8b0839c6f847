//! CAN frame codec of the drive's command interface (classic CAN 2.0A, 11-bit identifiers,
//! at most 8 data bytes; no CAN-FD features are used, so any classic controller can talk
//! to the drive).
//!
//! Hardware-free: frames are plain [`Frame`] values; the application converts them to and
//! from the FDCAN driver's frames. Decoding is total: every malformed frame gives a
//! [`DecodeError`] naming what is wrong, never a panic.
//!
//! # Identifiers
//!
//! `id = function base + node`, with the node number in the low 4 bits (0‥15, so up to 16
//! drives share one bus) and the function in the upper 7 bits. The real-time commands
//! (`0x100`‥`0x140`) have lower identifiers than the replies, so on a busy bus they win
//! arbitration.
//!
//! | base    | direction    | name           | DLC | payload (little endian)                 |
//! |---------|--------------|----------------|-----|-----------------------------------------|
//! | `0x100` | host → drive | `SetMode`      | 1   | `u8` mode code (table below)            |
//! | `0x110` | host → drive | `SetPressure`  | 4   | `i32` pressure setpoint, gauge, 1 Pa/LSB |
//! | `0x120` | host → drive | `SetSpeed`     | 4   | `i32` speed setpoint, 1 mrad/s per LSB  |
//! | `0x130` | host → drive | `ClearFaults`  | 0   | —                                       |
//! | `0x140` | host → drive | `Heartbeat`    | 0   | —                                       |
//! | `0x180` | drive → host | `Status`       | 8   | see below                               |
//! | `0x190` | drive → host | `Reject`       | 8   | see below                               |
//! | `0x1A0` | drive → host | `Parameter`    | 8   | see below                               |
//! | `0x1B0` | drive → host | `Diagnostics`  | 8   | see below                               |
//! | `0x200` | host → drive | `SetParameter` | 5   | `u8` parameter id, `f32` value in the parameter's unit |
//! | `0x210` | host → drive | `GetParameter` | 1   | `u8` parameter id                       |
//! | `0x220` | host → drive | `SaveParameters` | 0 | — (allowed in Disabled only)            |
//! | `0x230` | host → drive | `StepTest`     | 7   | `u8` loop (1 current, 2 speed, 3 pressure), `f32` amplitude [A, rad/s, Pa], `u16` duration [ms] |
//! | `0x240` | host → drive | `Commission`   | 0   | — runs the commissioning sequence ([`crate::commissioning`]) in Calibrating |
//! | `0x250` | host → drive | `CompensationBin` | 8 | `u16` bin, then its three `i16` channel values; bin `0xFFFF` is the table's header: three `i8` LSB exponents, `u8` 0, `u16` bin count |
//! | `0x260` | host → drive | `CompensationCommit` | 4 | `u32` CRC-32 of the table's record ([`crate::compensation::record`]) |
//! | `0x270` | host → drive | `CompensationSweep` | 6 | `f32` speed [rad/s], `u16` duration of each leg [ms] ([`crate::sweep`], Speed mode) |
//!
//! Mode codes: `0` disabled, `1` calibrating, `2` speed control, `3` pressure control.
//!
//! The configuration and test commands (`0x200`‥`0x270`) sit above the replies on purpose:
//! set-points, mode changes and the drive's status win arbitration over them. The torque
//! feed-forward's table ([`crate::compensation`]) loads as a header, its 512 bins in order
//! and a commit carrying the record's CRC (a lost or repeated frame fails the commit; the
//! feed-forward is off from the header to an accepted commit); each accepted frame is
//! acknowledged by a status. A refused commit names the bound it broke: reason `2` with
//! `compensation.max_current_a` [A] for an amplitude over the limit, reason `7` with the
//! expected bin (out-of-order bin) or `0` (CRC) otherwise. Parameter ids, names,
//! units and bounds are the table of [`crate::parameters`]; values are IEEE-754 `f32`
//! (little endian) in SI units, so a value read back is bit-identical to the one set.
//! `SetParameter` is answered with a `Parameter` frame echoing the value now in use,
//! `GetParameter` with a `Parameter` frame, `SaveParameters` and `StepTest` with a
//! status (their function code in byte 6); `Commission` is answered by the status frames,
//! whose mode shows Calibrating while it runs (or a reject when the mode is refused).
//!
//! A command frame must have exactly the DLC in the table; remote (RTR) and extended
//! (29-bit) frames are not part of the protocol (the application's acceptance filter
//! drops them). Range checks of setpoints are the controller's business: the codec only
//! checks the frame's shape, the controller checks the value and the application answers
//! an out-of-range value with a `Reject` naming the violated bound.
//!
//! Heartbeats keep the command watchdog of the controller fed; any accepted command also
//! counts as one. Without either for the configured timeout the drive goes to a safe state.
//!
//! # Status (`0x180 + node`, DLC 8)
//!
//! Sent periodically and after every accepted command (except a heartbeat, and the
//! parameter commands answered by a `Parameter` frame).
//!
//! | bytes | type  | content                                                          |
//! |-------|-------|------------------------------------------------------------------|
//! | 0     | `u8`  | mode code                                                        |
//! | 1     | `u8`  | latched fault code ([`crate::FaultCode`], `1`‥`18`; `0` = no fault) |
//! | 2‥3   | `i16` | measured pressure, gauge, 1 kPa per LSB (saturating)             |
//! | 4‥5   | `i16` | measured shaft speed, 0.1 rad/s per LSB (saturating)             |
//! | 6     | `u8`  | function code of the last accepted command (`0xFF` = none yet)   |
//! | 7     | `u8`  | status sequence counter, wraps at 256                            |
//!
//! # Reject (`0x190 + node`, DLC 8)
//!
//! Sent instead of a status when a command frame is malformed or its value is refused.
//!
//! | bytes | type  | content                                                          |
//! |-------|-------|------------------------------------------------------------------|
//! | 0     | `u8`  | function code of the refused command (identifier base >> 4, e.g. `0x11` for `SetPressure`) |
//! | 1     | `u8`  | reason code ([`RejectReason`])                                   |
//! | 2‥5   | `i32` | the bound that was violated, in the command's wire unit (Pa, mrad/s, mode code or DLC); `0` when the reason has no bound |
//! | 6     | `u8`  | parameter id (or unknown code) the refusal concerns, `0` for none |
//! | 7     | —     | reserved, `0`                                                    |
//!
//! For the configuration and test functions (codes `0x20`‥`0x23`) with reasons `1`, `2`,
//! `5` and `7`, bytes 2‥5 are the bound as an IEEE-754 `f32` in SI units instead: the
//! parameter's unit; A, rad/s or Pa for a step amplitude; s for a step duration; for
//! reason `5` the code of the mode the command needs ([`Rejection::si_bound`]).
//!
//! Reason codes: `1` value below the minimum, `2` value above the maximum, `3` wrong data
//! length (bound = expected DLC), `4` unknown mode code (bound = highest mode code), `5`
//! refused in the present state (bound = the code of the latched or present fault that
//! blocks it, `0` for a mode change that must go through disabled), `6` unknown function
//! (bound = `0`), `7` value not acceptable for another reason (for a parameter: not a
//! number, not whole, or in conflict with another parameter; bound = `0`), `8` unknown
//! parameter id or step-test loop code (bound = `0`, byte 6 = the offending code), `9`
//! mode refused because the drive is not ready for it yet (bound = `1`: the phase-current
//! offsets are still being measured after power-up; `2`: the rotor angle is unknown, no
//! encoder index and no alignment since power-up — see `docs/bring-up.md`).
//!
//! # Parameter (`0x1A0 + node`, DLC 8)
//!
//! | bytes | type  | content                                                          |
//! |-------|-------|------------------------------------------------------------------|
//! | 0     | `u8`  | parameter id                                                     |
//! | 1‥4   | `f32` | value in use, in the parameter's unit                            |
//! | 5‥7   | —     | reserved, `0`                                                    |
//!
//! # Diagnostics (`0x1B0 + node`, DLC 8)
//!
//! Sent once a second, unsolicited: what the drive measures of itself for the bench.
//!
//! | bytes | type  | content                                                          |
//! |-------|-------|------------------------------------------------------------------|
//! | 0‥3   | `u32` | stack high-water mark since power-up: the deepest the stack has reached, in bytes (painted at boot, scanned since) |
//! | 4‥7   | `u32` | the stack's size: the RAM below the static data, in bytes        |

use crate::compensation::record::RecordError;
use crate::compensation::CompensationError;
use crate::controller::{Command, CommandError};
use crate::parameters::{ParamError, ParamId};
use crate::step_test::{StepLoop, StepTestError};
use crate::supervisor::{Mode, ModeRefusal};

/// Highest mode code on the wire (the codes are the control core's [`Mode::code`]).
pub const MODE_CODE_MAX: u8 = 3;

/// Highest node number (the node occupies the identifier's low 4 bits).
pub const NODE_MAX: u8 = 15;
/// Classic CAN payload limit. [bytes]
pub const MAX_DLC: usize = 8;
/// Largest 11-bit identifier.
pub const STANDARD_ID_MAX: u16 = 0x7FF;

/// Pressure setpoint resolution on the wire. [Pa/LSB]
pub const SETPOINT_PA_PER_LSB: f32 = 1.0;
/// Speed setpoint resolution on the wire. [rad/s per LSB]
pub const SETPOINT_RAD_S_PER_LSB: f32 = 1.0e-3;
/// Pressure resolution of the status frame. [Pa/LSB]
pub const STATUS_PA_PER_LSB: f32 = 1000.0;
/// Speed resolution of the status frame. [rad/s per LSB]
pub const STATUS_RAD_S_PER_LSB: f32 = 0.1;
/// `last_command` value of a status frame before any command was accepted.
pub const NO_COMMAND: u8 = 0xFF;

/// Identifier bases (node number added in the low 4 bits).
pub mod id {
    /// `SetMode` command.
    pub const SET_MODE: u16 = 0x100;
    /// `SetPressure` command.
    pub const SET_PRESSURE: u16 = 0x110;
    /// `SetSpeed` command.
    pub const SET_SPEED: u16 = 0x120;
    /// `ClearFaults` command.
    pub const CLEAR_FAULTS: u16 = 0x130;
    /// `Heartbeat` command.
    pub const HEARTBEAT: u16 = 0x140;
    /// `Status` reply.
    pub const STATUS: u16 = 0x180;
    /// `Reject` reply.
    pub const REJECT: u16 = 0x190;
    /// `Parameter` reply.
    pub const PARAMETER: u16 = 0x1A0;
    /// `Diagnostics` reply.
    pub const DIAGNOSTICS: u16 = 0x1B0;
    /// `SetParameter` command.
    pub const SET_PARAMETER: u16 = 0x200;
    /// `GetParameter` command.
    pub const GET_PARAMETER: u16 = 0x210;
    /// `SaveParameters` command.
    pub const SAVE_PARAMETERS: u16 = 0x220;
    /// `StepTest` command.
    pub const STEP_TEST: u16 = 0x230;
    /// `Commission` command.
    pub const COMMISSION: u16 = 0x240;
    /// `CompensationBin` command (and the table's header).
    pub const COMPENSATION_BIN: u16 = 0x250;
    /// `CompensationCommit` command.
    pub const COMPENSATION_COMMIT: u16 = 0x260;
    /// `CompensationSweep` command.
    pub const COMPENSATION_SWEEP: u16 = 0x270;
}

/// The bin number of a `CompensationBin` frame that carries the table's header.
pub const COMPENSATION_HEADER_BIN: u16 = 0xFFFF;

/// Mask selecting the node number of an identifier.
const NODE_MASK: u16 = 0x00F;

/// A classic CAN data frame with an 11-bit identifier, independent of any CAN driver.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frame {
    id: u16,
    len: u8,
    data: [u8; MAX_DLC],
}

impl Frame {
    /// Builds a frame; fails if the identifier is not 11-bit or the payload exceeds 8 bytes.
    pub fn new(id: u16, payload: &[u8]) -> Result<Frame, DecodeError> {
        if id > STANDARD_ID_MAX {
            return Err(DecodeError::IdentifierTooLarge { id: u32::from(id) });
        }
        let mut data = [0u8; MAX_DLC];
        let Some(dst) = data.get_mut(..payload.len()) else {
            return Err(DecodeError::PayloadTooLong { len: payload.len() });
        };
        dst.copy_from_slice(payload);
        // `get_mut(..len)` succeeded, so `len <= 8` and the cast is lossless.
        Ok(Frame {
            id,
            len: payload.len() as u8,
            data,
        })
    }

    /// The 11-bit identifier.
    pub fn id(&self) -> u16 {
        self.id
    }

    /// The payload (DLC bytes).
    pub fn payload(&self) -> &[u8] {
        self.data.get(..usize::from(self.len)).unwrap_or(&[])
    }
}

/// The frame in the `cansend`/`candump` notation of Linux SocketCAN: three hex digits of
/// identifier, `#`, the payload in hex (`203#0A0000803E`), so a printed command can be
/// sent with `cansend can0 <frame>`.
impl core::fmt::Display for Frame {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{:03X}#", self.id)?;
        for b in self.payload() {
            write!(f, "{b:02X}")?;
        }
        Ok(())
    }
}

/// Node number of a drive on the bus (0‥15).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodeId(u8);

impl NodeId {
    /// Validates a node number.
    pub fn new(node: u8) -> Result<NodeId, DecodeError> {
        if node > NODE_MAX {
            Err(DecodeError::NodeOutOfRange { node })
        } else {
            Ok(NodeId(node))
        }
    }

    /// The node number.
    pub fn get(self) -> u8 {
        self.0
    }

    fn id(self, base: u16) -> u16 {
        base | u16::from(self.0)
    }
}

/// Which command a frame carries; its code is the identifier base shifted right by 4.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Function {
    /// `SetMode`, code `0x10`.
    SetMode,
    /// `SetPressure`, code `0x11`.
    SetPressure,
    /// `SetSpeed`, code `0x12`.
    SetSpeed,
    /// `ClearFaults`, code `0x13`.
    ClearFaults,
    /// `Heartbeat`, code `0x14`.
    Heartbeat,
    /// `SetParameter`, code `0x20`.
    SetParameter,
    /// `GetParameter`, code `0x21`.
    GetParameter,
    /// `SaveParameters`, code `0x22`.
    SaveParameters,
    /// `StepTest`, code `0x23`.
    StepTest,
    /// `Commission`, code `0x24`.
    Commission,
    /// `CompensationBin`, code `0x25`.
    CompensationBin,
    /// `CompensationCommit`, code `0x26`.
    CompensationCommit,
    /// `CompensationSweep`, code `0x27`.
    CompensationSweep,
}

impl Function {
    /// Every command, in identifier order.
    pub const ALL: [Function; 13] = [
        Function::SetMode,
        Function::SetPressure,
        Function::SetSpeed,
        Function::ClearFaults,
        Function::Heartbeat,
        Function::SetParameter,
        Function::GetParameter,
        Function::SaveParameters,
        Function::StepTest,
        Function::Commission,
        Function::CompensationBin,
        Function::CompensationCommit,
        Function::CompensationSweep,
    ];

    /// Identifier base of the command.
    pub fn id_base(self) -> u16 {
        match self {
            Function::SetMode => id::SET_MODE,
            Function::SetPressure => id::SET_PRESSURE,
            Function::SetSpeed => id::SET_SPEED,
            Function::ClearFaults => id::CLEAR_FAULTS,
            Function::Heartbeat => id::HEARTBEAT,
            Function::SetParameter => id::SET_PARAMETER,
            Function::GetParameter => id::GET_PARAMETER,
            Function::SaveParameters => id::SAVE_PARAMETERS,
            Function::StepTest => id::STEP_TEST,
            Function::Commission => id::COMMISSION,
            Function::CompensationBin => id::COMPENSATION_BIN,
            Function::CompensationCommit => id::COMPENSATION_COMMIT,
            Function::CompensationSweep => id::COMPENSATION_SWEEP,
        }
    }

    /// Function code carried in status and reject frames (identifier base >> 4).
    pub fn code(self) -> u8 {
        // Bases are at most 0x230, so the shifted value fits a byte.
        (self.id_base() >> 4) as u8
    }

    /// Parses a function code.
    pub fn from_code(code: u8) -> Option<Function> {
        Function::from_base(u16::from(code) << 4)
    }

    fn from_base(base: u16) -> Option<Function> {
        match base {
            id::SET_MODE => Some(Function::SetMode),
            id::SET_PRESSURE => Some(Function::SetPressure),
            id::SET_SPEED => Some(Function::SetSpeed),
            id::CLEAR_FAULTS => Some(Function::ClearFaults),
            id::HEARTBEAT => Some(Function::Heartbeat),
            id::SET_PARAMETER => Some(Function::SetParameter),
            id::GET_PARAMETER => Some(Function::GetParameter),
            id::SAVE_PARAMETERS => Some(Function::SaveParameters),
            id::STEP_TEST => Some(Function::StepTest),
            id::COMMISSION => Some(Function::Commission),
            id::COMPENSATION_BIN => Some(Function::CompensationBin),
            id::COMPENSATION_COMMIT => Some(Function::CompensationCommit),
            id::COMPENSATION_SWEEP => Some(Function::CompensationSweep),
            _ => None,
        }
    }

    /// Required data length of the command frame. [bytes]
    pub fn dlc(self) -> u8 {
        match self {
            Function::SetMode | Function::GetParameter => 1,
            Function::SetPressure | Function::SetSpeed => 4,
            Function::SetParameter => 5,
            Function::StepTest => 7,
            Function::CompensationBin => 8,
            Function::CompensationCommit => 4,
            Function::CompensationSweep => 6,
            Function::ClearFaults
            | Function::Heartbeat
            | Function::SaveParameters
            | Function::Commission => 0,
        }
    }
}

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

/// A frame the codec cannot turn into a message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeError {
    /// Identifier wider than 11 bits.
    IdentifierTooLarge {
        /// The identifier.
        id: u32,
    },
    /// More than 8 data bytes.
    PayloadTooLong {
        /// Offered length. [bytes]
        len: usize,
    },
    /// Node number above [`NODE_MAX`].
    NodeOutOfRange {
        /// The offered node number.
        node: u8,
    },
    /// The frame is addressed to another node.
    OtherNode {
        /// Node number in the identifier.
        node: u8,
    },
    /// The identifier's function is not a command (when decoding commands) or not a reply
    /// (when decoding replies).
    UnknownFunction {
        /// The identifier.
        id: u16,
    },
    /// The data length does not match the function.
    WrongLength {
        /// The function of the frame.
        function: Function,
        /// Required data length. [bytes]
        expected: u8,
        /// Received data length. [bytes]
        got: u8,
    },
    /// A reply frame whose data length is not 8.
    WrongReplyLength {
        /// Received data length. [bytes]
        got: u8,
    },
    /// A `SetMode` frame with a mode code above [`MODE_CODE_MAX`].
    UnknownMode {
        /// The received code.
        code: u8,
    },
    /// A reject frame with an unknown reason code.
    UnknownReason {
        /// The received code.
        code: u8,
    },
    /// A reject frame whose reserved bytes are not zero.
    ReservedNotZero,
    /// A parameter id or step-test loop code that does not exist.
    UnknownCode {
        /// The function of the frame.
        function: Function,
        /// The received code.
        code: u8,
    },
}

/// A value that cannot be put on the wire.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EncodeError {
    /// Which value, with its unit.
    pub field: &'static str,
    /// What is wrong with it.
    pub problem: &'static str,
}

/// Standard-identifier acceptance filters, as (identifier, mask) pairs (a frame passes when
/// `id & mask == identifier & mask`), that pass exactly the command blocks of `node`: the
/// real-time commands `0x100`‥`0x170` and the configuration commands `0x200`‥`0x270` with
/// its node number. Replies, other nodes' frames and every other identifier stay in the
/// controller's filter, out of the drive's receive FIFO; a free function code of these
/// blocks still reaches the drive, which rejects it as unknown.
pub fn acceptance_filters(node: NodeId) -> [(u16, u16); 2] {
    // Bits 10..7 select the block, bits 3..0 the node.
    const MASK: u16 = 0x780 | NODE_MASK;
    [
        (node.id(id::SET_MODE), MASK),
        (node.id(id::SET_PARAMETER), MASK),
    ]
}

/// Decodes a command frame addressed to `node`.
///
/// A frame addressed to another node is [`DecodeError::OtherNode`] whatever its function
/// (another drive's status or reject included), so the drive never answers it: only its
/// own node's unknown functions get a reject.
pub fn decode_command(frame: &Frame, node: NodeId) -> Result<Request, DecodeError> {
    let frame_node = (frame.id & NODE_MASK) as u8;
    let base = frame.id & !NODE_MASK;
    if frame_node != node.0 {
        return Err(DecodeError::OtherNode { node: frame_node });
    }
    let function =
        Function::from_base(base).ok_or(DecodeError::UnknownFunction { id: frame.id })?;
    let payload = frame.payload();
    let expected = function.dlc();
    if payload.len() != usize::from(expected) {
        return Err(DecodeError::WrongLength {
            function,
            expected,
            got: frame.len,
        });
    }
    match function {
        Function::SetMode => {
            let code = payload.first().copied().unwrap_or(u8::MAX);
            Mode::from_code(code)
                .map(Request::SetMode)
                .ok_or(DecodeError::UnknownMode { code })
        }
        Function::SetPressure => Ok(Request::SetPressure {
            pa: read_i32(payload, 0),
        }),
        Function::SetSpeed => Ok(Request::SetSpeed {
            mrad_s: read_i32(payload, 0),
        }),
        Function::ClearFaults => Ok(Request::ClearFaults),
        Function::Heartbeat => Ok(Request::Heartbeat),
        Function::SetParameter => Ok(Request::SetParameter {
            id: parameter_id(function, payload)?,
            value: read_f32(payload, 1),
        }),
        Function::GetParameter => Ok(Request::GetParameter {
            id: parameter_id(function, payload)?,
        }),
        Function::SaveParameters => Ok(Request::SaveParameters),
        Function::Commission => Ok(Request::Commission),
        Function::CompensationBin => {
            // The length was checked: the frame's whole data array is the payload.
            let d = &frame.data;
            let bin = u16::from_le_bytes([d[0], d[1]]);
            if bin == COMPENSATION_HEADER_BIN {
                Ok(Request::CompensationHeader {
                    exponents: [d[2] as i8, d[3] as i8, d[4] as i8],
                    bins: u16::from_le_bytes([d[6], d[7]]),
                })
            } else {
                Ok(Request::CompensationBin {
                    bin,
                    raw: [
                        i16::from_le_bytes([d[2], d[3]]),
                        i16::from_le_bytes([d[4], d[5]]),
                        i16::from_le_bytes([d[6], d[7]]),
                    ],
                })
            }
        }
        Function::CompensationCommit => Ok(Request::CompensationCommit {
            crc: read_i32(payload, 0) as u32,
        }),
        Function::CompensationSweep => Ok(Request::CompensationSweep {
            speed_rad_s: read_f32(payload, 0),
            leg_ms: u16::from_le_bytes([frame.data[4], frame.data[5]]),
        }),
        Function::StepTest => {
            let code = payload.first().copied().unwrap_or(0);
            let target =
                StepLoop::from_code(code).ok_or(DecodeError::UnknownCode { function, code })?;
            let mut ms = [0u8; 2];
            if let Some(src) = payload.get(5..7) {
                ms.copy_from_slice(src);
            }
            Ok(Request::StepTest {
                target,
                amplitude: read_f32(payload, 1),
                duration_ms: u16::from_le_bytes(ms),
            })
        }
    }
}

/// The parameter id in byte 0 of a parameter command.
fn parameter_id(function: Function, payload: &[u8]) -> Result<ParamId, DecodeError> {
    let code = payload.first().copied().unwrap_or(0);
    ParamId::from_code(code).ok_or(DecodeError::UnknownCode { function, code })
}

/// Frame setting parameter `id` to `value` [the parameter's unit] on drive `node`.
pub fn encode_set_parameter(id: ParamId, value: f32, node: NodeId) -> Frame {
    encode_command(&Request::SetParameter { id, value }, node)
}

/// Frame asking drive `node` for the value of parameter `id`.
pub fn encode_get_parameter(id: ParamId, node: NodeId) -> Frame {
    encode_command(&Request::GetParameter { id }, node)
}

/// Encodes a command for `node`.
pub fn encode_command(request: &Request, node: NodeId) -> Frame {
    let id = node.id(request.function().id_base());
    let mut data = [0u8; MAX_DLC];
    match *request {
        Request::SetMode(mode) => data[0] = mode.code(),
        Request::SetPressure { pa } => write_i32(&mut data, 0, pa),
        Request::SetSpeed { mrad_s } => write_i32(&mut data, 0, mrad_s),
        Request::SetParameter { id, value } => {
            data[0] = id.code();
            write_f32(&mut data, 1, value);
        }
        Request::GetParameter { id } => data[0] = id.code(),
        Request::StepTest {
            target,
            amplitude,
            duration_ms,
        } => {
            data[0] = target.code();
            write_f32(&mut data, 1, amplitude);
            data[5..7].copy_from_slice(&duration_ms.to_le_bytes());
        }
        Request::CompensationHeader { exponents, bins } => {
            data[0..2].copy_from_slice(&COMPENSATION_HEADER_BIN.to_le_bytes());
            for (c, e) in exponents.iter().enumerate() {
                data[2 + c] = *e as u8;
            }
            data[6..8].copy_from_slice(&bins.to_le_bytes());
        }
        Request::CompensationBin { bin, raw } => {
            data[0..2].copy_from_slice(&bin.to_le_bytes());
            for (c, v) in raw.iter().enumerate() {
                data[2 + 2 * c..4 + 2 * c].copy_from_slice(&v.to_le_bytes());
            }
        }
        Request::CompensationCommit { crc } => write_i32(&mut data, 0, crc as i32),
        Request::CompensationSweep {
            speed_rad_s,
            leg_ms,
        } => {
            write_f32(&mut data, 0, speed_rad_s);
            data[4..6].copy_from_slice(&leg_ms.to_le_bytes());
        }
        Request::ClearFaults
        | Request::Heartbeat
        | Request::SaveParameters
        | Request::Commission => {}
    }
    Frame {
        id,
        len: request.function().dlc(),
        data,
    }
}

/// Encodes a reply of `node`.
pub fn encode_reply(reply: &Reply, node: NodeId) -> Frame {
    let mut data = [0u8; MAX_DLC];
    let base = match *reply {
        Reply::Status(s) => {
            data[0] = s.mode;
            data[1] = s.fault;
            data[2..4].copy_from_slice(&s.pressure_kpa.to_le_bytes());
            data[4..6].copy_from_slice(&s.speed_drad_s.to_le_bytes());
            data[6] = s.last_command;
            data[7] = s.sequence;
            id::STATUS
        }
        Reply::Reject(r) => {
            data[0] = r.function;
            data[1] = r.reason.code();
            write_i32(&mut data, 2, r.bound);
            data[6] = r.parameter;
            id::REJECT
        }
        Reply::Parameter { id, value } => {
            data[0] = id.code();
            write_f32(&mut data, 1, value);
            id::PARAMETER
        }
        Reply::Diagnostics(d) => {
            data[..4].copy_from_slice(&d.stack_peak_bytes.to_le_bytes());
            data[4..].copy_from_slice(&d.stack_size_bytes.to_le_bytes());
            id::DIAGNOSTICS
        }
    };
    Frame {
        id: node.id(base),
        len: MAX_DLC as u8,
        data,
    }
}

/// Decodes a reply frame sent by `node` (the host side of the protocol).
pub fn decode_reply(frame: &Frame, node: NodeId) -> Result<Reply, DecodeError> {
    let frame_node = (frame.id & NODE_MASK) as u8;
    let base = frame.id & !NODE_MASK;
    if ![id::STATUS, id::REJECT, id::PARAMETER, id::DIAGNOSTICS].contains(&base) {
        return Err(DecodeError::UnknownFunction { id: frame.id });
    }
    if frame_node != node.0 {
        return Err(DecodeError::OtherNode { node: frame_node });
    }
    let d = frame.payload();
    let [b0, b1, b2, b3, b4, b5, b6, b7] = <[u8; MAX_DLC]>::try_from(d)
        .map_err(|_| DecodeError::WrongReplyLength { got: frame.len })?;
    if base == id::STATUS {
        Ok(Reply::Status(Status {
            mode: b0,
            fault: b1,
            pressure_kpa: i16::from_le_bytes([b2, b3]),
            speed_drad_s: i16::from_le_bytes([b4, b5]),
            last_command: b6,
            sequence: b7,
        }))
    } else if base == id::DIAGNOSTICS {
        Ok(Reply::Diagnostics(Diagnostics {
            stack_peak_bytes: u32::from_le_bytes([b0, b1, b2, b3]),
            stack_size_bytes: u32::from_le_bytes([b4, b5, b6, b7]),
        }))
    } else if base == id::PARAMETER {
        if b5 != 0 || b6 != 0 || b7 != 0 {
            return Err(DecodeError::ReservedNotZero);
        }
        let id = ParamId::from_code(b0).ok_or(DecodeError::UnknownCode {
            function: Function::GetParameter,
            code: b0,
        })?;
        Ok(Reply::Parameter {
            id,
            value: f32::from_le_bytes([b1, b2, b3, b4]),
        })
    } else {
        if b7 != 0 {
            return Err(DecodeError::ReservedNotZero);
        }
        let reason = RejectReason::from_code(b1).ok_or(DecodeError::UnknownReason { code: b1 })?;
        Ok(Reply::Reject(Rejection {
            function: b0,
            reason,
            bound: i32::from_le_bytes([b2, b3, b4, b5]),
            parameter: b6,
        }))
    }
}

fn read_i32(bytes: &[u8], at: usize) -> i32 {
    let mut b = [0u8; 4];
    if let Some(src) = bytes.get(at..at + 4) {
        b.copy_from_slice(src);
    }
    i32::from_le_bytes(b)
}

fn write_i32(data: &mut [u8; MAX_DLC], at: usize, value: i32) {
    if let Some(dst) = data.get_mut(at..at + 4) {
        dst.copy_from_slice(&value.to_le_bytes());
    }
}

fn read_f32(bytes: &[u8], at: usize) -> f32 {
    f32::from_bits(read_i32(bytes, at) as u32)
}

fn write_f32(data: &mut [u8; MAX_DLC], at: usize, value: f32) {
    write_i32(data, at, value.to_bits() as i32);
}

fn wire_bound(si: f32, per_lsb: f32) -> i32 {
    // `as` saturates (and maps NaN to 0), so a bound beyond the field is sent as its limit.
    libm::roundf(si / per_lsb) as i32
}

fn saturate_i16(x: f32) -> i16 {
    // `as` saturates and maps NaN to 0, which is the wanted behaviour for a status field.
    libm::roundf(x) as i16
}

fn to_wire(value: f32, per_lsb: f32, field: &'static str) -> Result<i32, EncodeError> {
    if !value.is_finite() {
        return Err(EncodeError {
            field,
            problem: "is not a finite number",
        });
    }
    let lsb = libm::roundf(value / per_lsb);
    // i32::MAX is not exact in f32; 2^31 is, and anything at or above it does not fit.
    const LIMIT: f32 = 2_147_483_648.0;
    if !(-LIMIT..LIMIT).contains(&lsb) {
        return Err(EncodeError {
            field,
            problem: "does not fit the 32-bit wire field",
        });
    }
    Ok(lsb as i32)
}

#[cfg(test)]
mod tests;
