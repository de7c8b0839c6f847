//! Frames to messages and back: the drive decodes commands and encodes replies, the host
//! encodes commands and decodes replies. Decoding is total: every malformed frame gives a
//! [`DecodeError`].

use super::error::DecodeError;
use super::frame::{Frame, NodeId};
use super::function::Function;
use super::id;
use super::reject::{RejectReason, Rejection};
use super::reply::{Diagnostics, Reply, Status};
use super::request::Request;
use super::wire::{
    read_f32, read_i32, write_f32, write_i32, COMPENSATION_HEADER_BIN, MAX_DLC, NODE_MASK,
};
use crate::parameters::ParamId;
use crate::step_test::StepLoop;
use crate::supervisor::Mode;

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
