//! The message a frame carries, by its identifier's function code (the identifier base
//! without the node number), with each command's fixed data length.

use super::id;

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

    pub(super) fn from_base(base: u16) -> Option<Function> {
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
