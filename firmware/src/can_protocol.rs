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
//! drives share one bus) and the function in the upper 7 bits. Commands have lower
//! identifiers than replies, so on a busy bus they win arbitration.
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
//!
//! Mode codes: `0` disabled, `1` calibrating, `2` speed control, `3` pressure control.
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
//! Sent periodically and after every accepted command.
//!
//! | bytes | type  | content                                                          |
//! |-------|-------|------------------------------------------------------------------|
//! | 0     | `u8`  | mode code                                                        |
//! | 1     | `u8`  | fault code of the controller (`0` = no fault)                    |
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
//! | 6‥7   | —     | reserved, `0`                                                    |
//!
//! Reason codes: `1` value below the minimum, `2` value above the maximum, `3` wrong data
//! length (bound = expected DLC), `4` unknown mode code (bound = highest mode code), `5`
//! refused in the present state (bound = the code of the latched or present fault that
//! blocks it, `0` for a mode change that must go through disabled), `6` unknown function
//! (bound = `0`), `7` value not acceptable for another reason.

use crate::controller::{Command, CommandError};
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
}

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
}

impl Function {
    /// Identifier base of the command.
    pub fn id_base(self) -> u16 {
        match self {
            Function::SetMode => id::SET_MODE,
            Function::SetPressure => id::SET_PRESSURE,
            Function::SetSpeed => id::SET_SPEED,
            Function::ClearFaults => id::CLEAR_FAULTS,
            Function::Heartbeat => id::HEARTBEAT,
        }
    }

    /// Function code carried in status and reject frames (identifier base >> 4).
    pub fn code(self) -> u8 {
        // Bases are at most 0x140, so the shifted value fits a byte.
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
            _ => None,
        }
    }

    /// Required data length of the command frame. [bytes]
    pub fn dlc(self) -> u8 {
        match self {
            Function::SetMode => 1,
            Function::SetPressure | Function::SetSpeed => 4,
            Function::ClearFaults | Function::Heartbeat => 0,
        }
    }
}

/// A command as carried on the wire, in wire units (integers, so an encode/decode round
/// trip is exact).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
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
        }
    }

    /// Pressure setpoint in SI units, if this is one. [Pa]
    pub fn pressure_pa(&self) -> Option<f32> {
        match self {
            Request::SetPressure { pa } => Some(*pa as f32 * SETPOINT_PA_PER_LSB),
            _ => None,
        }
    }

    /// The control core's command for this request (setpoints converted to SI units).
    pub fn to_command(&self) -> Command {
        match *self {
            Request::SetMode(mode) => Command::SetMode(mode),
            Request::SetPressure { pa } => Command::SetPressure {
                pa: pa as f32 * SETPOINT_PA_PER_LSB,
            },
            Request::SetSpeed { mrad_s } => Command::SetSpeed {
                rad_s: mrad_s as f32 * SETPOINT_RAD_S_PER_LSB,
            },
            Request::ClearFaults => Command::ClearFaults,
            Request::Heartbeat => Command::Heartbeat,
        }
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
}

impl RejectReason {
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

/// A refused command, in wire units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rejection {
    /// Function code of the refused command (identifier base >> 4); kept raw because an
    /// unknown function is itself a reason for rejection.
    pub function: u8,
    /// Why.
    pub reason: RejectReason,
    /// The violated bound in the command's wire unit (Pa, mrad/s, mode code or DLC).
    pub bound: i32,
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
        };
        Rejection {
            function,
            reason,
            bound,
        }
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
            }),
            DecodeError::UnknownMode { .. } => Some(Rejection {
                function: Function::SetMode.code(),
                reason: RejectReason::UnknownMode,
                bound: i32::from(MODE_CODE_MAX),
            }),
            DecodeError::UnknownFunction { id } => Some(Rejection {
                // An 11-bit identifier shifted by 4 fits a byte.
                function: (id >> 4) as u8,
                reason: RejectReason::UnknownFunction,
                bound: 0,
            }),
            _ => None,
        }
    }
}

/// A frame sent by the drive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reply {
    /// Periodic or acknowledging status.
    Status(Status),
    /// Refused command.
    Reject(Rejection),
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
}

/// A value that cannot be put on the wire.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EncodeError {
    /// Which value, with its unit.
    pub field: &'static str,
    /// What is wrong with it.
    pub problem: &'static str,
}

/// Decodes a command frame addressed to `node`.
pub fn decode_command(frame: &Frame, node: NodeId) -> Result<Request, DecodeError> {
    let frame_node = (frame.id & NODE_MASK) as u8;
    let base = frame.id & !NODE_MASK;
    let function =
        Function::from_base(base).ok_or(DecodeError::UnknownFunction { id: frame.id })?;
    if frame_node != node.0 {
        return Err(DecodeError::OtherNode { node: frame_node });
    }
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
    }
}

/// Encodes a command for `node`.
pub fn encode_command(request: &Request, node: NodeId) -> Frame {
    let id = node.id(request.function().id_base());
    let mut data = [0u8; MAX_DLC];
    match *request {
        Request::SetMode(mode) => data[0] = mode.code(),
        Request::SetPressure { pa } => write_i32(&mut data, 0, pa),
        Request::SetSpeed { mrad_s } => write_i32(&mut data, 0, mrad_s),
        Request::ClearFaults | Request::Heartbeat => {}
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
            id::REJECT
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
    if base != id::STATUS && base != id::REJECT {
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
    } else {
        if b6 != 0 || b7 != 0 {
            return Err(DecodeError::ReservedNotZero);
        }
        let reason = RejectReason::from_code(b1).ok_or(DecodeError::UnknownReason { code: b1 })?;
        Ok(Reply::Reject(Rejection {
            function: b0,
            reason,
            bound: i32::from_le_bytes([b2, b3, b4, b5]),
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
mod tests {
    use super::*;
    use crate::supervisor::FaultCode;

    fn node(n: u8) -> NodeId {
        NodeId::new(n).expect("valid node")
    }

    #[test]
    fn command_layout_matches_the_documented_table() {
        // Bytes written out by hand from the module documentation.
        let f = encode_command(&Request::SetPressure { pa: 5_000_000 }, node(3));
        assert_eq!(f.id(), 0x113);
        assert_eq!(f.payload(), &[0x40, 0x4B, 0x4C, 0x00]);
        let f = encode_command(&Request::SetSpeed { mrad_s: -1500 }, node(0));
        assert_eq!(f.id(), 0x120);
        assert_eq!(f.payload(), &[0x24, 0xFA, 0xFF, 0xFF]);
        let f = encode_command(&Request::SetMode(Mode::Pressure), node(15));
        assert_eq!((f.id(), f.payload()), (0x10F, &[3u8][..]));
        assert_eq!(encode_command(&Request::ClearFaults, node(1)).id(), 0x131);
        assert_eq!(
            encode_command(&Request::Heartbeat, node(1)).payload(),
            &[] as &[u8]
        );
    }

    #[test]
    fn every_command_round_trips() {
        let requests = [
            Request::SetMode(Mode::Disabled),
            Request::SetMode(Mode::Calibrating),
            Request::SetMode(Mode::Speed),
            Request::SetMode(Mode::Pressure),
            Request::SetPressure { pa: 0 },
            Request::SetPressure { pa: i32::MIN },
            Request::SetPressure { pa: i32::MAX },
            Request::SetSpeed { mrad_s: -314_159 },
            Request::ClearFaults,
            Request::Heartbeat,
        ];
        for n in [0, 7, NODE_MAX] {
            for r in requests {
                let frame = encode_command(&r, node(n));
                assert_eq!(decode_command(&frame, node(n)), Ok(r));
            }
        }
    }

    #[test]
    fn si_constructors_round_to_the_wire_resolution() {
        assert_eq!(
            Request::pressure_from_pa(3.0e6),
            Ok(Request::SetPressure { pa: 3_000_000 })
        );
        assert_eq!(
            Request::speed_from_rad_s(-12.3456),
            Ok(Request::SetSpeed { mrad_s: -12_346 })
        );
        let back = Request::SetSpeed { mrad_s: 12_345 }
            .speed_rad_s()
            .unwrap_or(f32::NAN);
        assert!((back - 12.345).abs() < 1e-5, "{back}");
        assert!(Request::pressure_from_pa(f32::NAN).is_err());
        assert!(Request::pressure_from_pa(3.0e9).is_err());
        assert!(Request::speed_from_rad_s(f32::INFINITY).is_err());
    }

    #[test]
    fn malformed_commands_are_rejected_with_the_reason() {
        let me = node(2);
        let f = Frame::new(0x112, &[1, 2, 3]).unwrap();
        let err = decode_command(&f, me).unwrap_err();
        assert_eq!(
            err,
            DecodeError::WrongLength {
                function: Function::SetPressure,
                expected: 4,
                got: 3
            }
        );
        assert_eq!(
            Rejection::for_decode_error(&err),
            Some(Rejection {
                function: 0x11,
                reason: RejectReason::WrongLength,
                bound: 4
            })
        );

        let f = Frame::new(0x132, &[0]).unwrap();
        assert!(matches!(
            decode_command(&f, me),
            Err(DecodeError::WrongLength {
                expected: 0,
                got: 1,
                ..
            })
        ));

        let f = Frame::new(0x102, &[4]).unwrap();
        let err = decode_command(&f, me).unwrap_err();
        assert_eq!(err, DecodeError::UnknownMode { code: 4 });
        assert_eq!(
            Rejection::for_decode_error(&err).map(|r| (r.reason, r.bound)),
            Some((RejectReason::UnknownMode, 3))
        );

        let f = Frame::new(0x152, &[]).unwrap();
        let err = decode_command(&f, me).unwrap_err();
        assert_eq!(err, DecodeError::UnknownFunction { id: 0x152 });
        assert_eq!(
            Rejection::for_decode_error(&err).map(|r| r.function),
            Some(0x15)
        );

        // Another node's command is ignored silently; so is a reply seen on the bus.
        let f = Frame::new(0x113, &[0; 4]).unwrap();
        let err = decode_command(&f, me).unwrap_err();
        assert_eq!(err, DecodeError::OtherNode { node: 3 });
        assert_eq!(Rejection::for_decode_error(&err), None);
        let f = Frame::new(0x182, &[0; 8]).unwrap();
        assert_eq!(
            decode_command(&f, me),
            Err(DecodeError::UnknownFunction { id: 0x182 })
        );
    }

    #[test]
    fn frame_and_node_bounds_are_checked() {
        assert_eq!(
            Frame::new(0x800, &[]),
            Err(DecodeError::IdentifierTooLarge { id: 0x800 })
        );
        assert_eq!(
            Frame::new(0x100, &[0; 9]),
            Err(DecodeError::PayloadTooLong { len: 9 })
        );
        assert_eq!(
            NodeId::new(16),
            Err(DecodeError::NodeOutOfRange { node: 16 })
        );
        assert!(Frame::new(0x7FF, &[0; 8]).is_ok());
    }

    #[test]
    fn status_layout_and_round_trip() {
        // 5.2 MPa -> 5200 kPa = 0x1450; -31.4 rad/s -> -314 = 0xFEC6.
        let s = Status::from_si(
            Mode::Pressure,
            4,
            5.2e6,
            -31.4,
            Function::SetPressure.code(),
            200,
        );
        let f = encode_reply(&Reply::Status(s), node(5));
        assert_eq!(f.id(), 0x185);
        assert_eq!(f.payload(), &[3, 4, 0x50, 0x14, 0xC6, 0xFE, 0x11, 200]);
        assert_eq!(decode_reply(&f, node(5)), Ok(Reply::Status(s)));
    }

    #[test]
    fn status_fields_saturate() {
        let s = Status::from_si(Mode::Speed, 0, 1.0e9, f32::NAN, NO_COMMAND, 0);
        assert_eq!((s.pressure_kpa, s.speed_drad_s), (i16::MAX, 0));
        let s = Status::from_si(Mode::Speed, 0, -1.0e9, -1.0e6, NO_COMMAND, 0);
        assert_eq!((s.pressure_kpa, s.speed_drad_s), (i16::MIN, i16::MIN));
    }

    #[test]
    fn reject_layout_and_round_trip() {
        // Pressure above a 16 MPa maximum: bound 16_000_000 = 0x00F42400.
        let r = Rejection {
            function: 0x11,
            reason: RejectReason::AboveMaximum,
            bound: 16_000_000,
        };
        let f = encode_reply(&Reply::Reject(r), node(0));
        assert_eq!(f.id(), 0x190);
        assert_eq!(f.payload(), &[0x11, 2, 0x00, 0x24, 0xF4, 0x00, 0, 0]);
        assert_eq!(decode_reply(&f, node(0)), Ok(Reply::Reject(r)));
        for code in 1..=7 {
            let reason = RejectReason::from_code(code).unwrap();
            assert_eq!(reason.code(), code);
        }
    }

    #[test]
    fn malformed_replies_are_rejected() {
        let me = node(1);
        assert!(matches!(
            decode_reply(&Frame::new(0x181, &[0; 7]).unwrap(), me),
            Err(DecodeError::WrongReplyLength { got: 7 })
        ));
        assert_eq!(
            decode_reply(
                &Frame::new(0x191, &[0x11, 9, 0, 0, 0, 0, 0, 0]).unwrap(),
                me
            ),
            Err(DecodeError::UnknownReason { code: 9 })
        );
        assert_eq!(
            decode_reply(
                &Frame::new(0x191, &[0x11, 1, 0, 0, 0, 0, 0, 1]).unwrap(),
                me
            ),
            Err(DecodeError::ReservedNotZero)
        );
        assert_eq!(
            decode_reply(&Frame::new(0x182, &[0; 8]).unwrap(), me),
            Err(DecodeError::OtherNode { node: 2 })
        );
        assert_eq!(
            decode_reply(&Frame::new(0x111, &[0; 4]).unwrap(), me),
            Err(DecodeError::UnknownFunction { id: 0x111 })
        );
    }

    #[test]
    fn requests_map_to_core_commands_in_si_units() {
        assert_eq!(
            Request::SetPressure { pa: 4_500_000 }.to_command(),
            Command::SetPressure { pa: 4.5e6 }
        );
        assert_eq!(
            Request::SetSpeed { mrad_s: -2_500 }.to_command(),
            Command::SetSpeed { rad_s: -2.5 }
        );
        assert_eq!(
            Request::SetMode(Mode::Speed).to_command(),
            Command::SetMode(Mode::Speed)
        );
        assert_eq!(Request::Heartbeat.to_command(), Command::Heartbeat);
        assert_eq!(Request::ClearFaults.to_command(), Command::ClearFaults);
    }

    #[test]
    fn refusals_name_the_violated_bound() {
        let range = CommandError::PressureOutOfRange {
            min_pa: 0.0,
            max_pa: 18e6,
        };
        let r = Rejection::for_command_error(&Request::SetPressure { pa: 20_000_000 }, &range);
        assert_eq!(
            r,
            Rejection {
                function: 0x11,
                reason: RejectReason::AboveMaximum,
                bound: 18_000_000
            }
        );
        let r = Rejection::for_command_error(&Request::SetPressure { pa: -5 }, &range);
        assert_eq!((r.reason, r.bound), (RejectReason::BelowMinimum, 0));

        let speed = CommandError::SpeedOutOfRange { max_rad_s: 200.0 };
        let r = Rejection::for_command_error(&Request::SetSpeed { mrad_s: -250_000 }, &speed);
        assert_eq!(
            (r.function, r.reason, r.bound),
            (0x12, RejectReason::BelowMinimum, -200_000)
        );
        let r = Rejection::for_command_error(&Request::SetSpeed { mrad_s: 250_000 }, &speed);
        assert_eq!((r.reason, r.bound), (RejectReason::AboveMaximum, 200_000));

        // Over-pressure is fault code 4 in the supervisor's table.
        let blocked = CommandError::CausePresent(FaultCode::OverPressure);
        let r = Rejection::for_command_error(&Request::ClearFaults, &blocked);
        assert_eq!(
            (r.function, r.reason, r.bound),
            (0x13, RejectReason::NotAllowed, 4)
        );
        let transition = CommandError::Mode(ModeRefusal::Transition {
            from: Mode::Speed,
            to: Mode::Calibrating,
        });
        let r = Rejection::for_command_error(&Request::SetMode(Mode::Calibrating), &transition);
        assert_eq!(
            (r.function, r.reason, r.bound),
            (0x10, RejectReason::NotAllowed, 0)
        );
    }

    #[test]
    fn mode_codes_are_the_four_documented_ones() {
        // 0 disabled, 1 calibrating, 2 speed, 3 pressure (module documentation).
        let documented = [
            Mode::Disabled,
            Mode::Calibrating,
            Mode::Speed,
            Mode::Pressure,
        ];
        for (code, mode) in documented.into_iter().enumerate() {
            let f = encode_command(&Request::SetMode(mode), node(0));
            assert_eq!(f.payload(), &[code as u8]);
        }
        assert_eq!(usize::from(MODE_CODE_MAX) + 1, documented.len());
        let f = Frame::new(0x100, &[MODE_CODE_MAX + 1]).unwrap();
        assert!(matches!(
            decode_command(&f, node(0)),
            Err(DecodeError::UnknownMode { .. })
        ));
    }

    #[test]
    fn function_codes_are_the_identifier_base_shifted() {
        for f in [
            Function::SetMode,
            Function::SetPressure,
            Function::SetSpeed,
            Function::ClearFaults,
            Function::Heartbeat,
        ] {
            assert_eq!(u16::from(f.code()) << 4, f.id_base());
            assert_eq!(Function::from_code(f.code()), Some(f));
        }
        assert_eq!(Function::from_code(0x18), None);
    }
}
