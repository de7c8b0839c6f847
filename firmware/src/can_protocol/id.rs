//! Identifier bases of every message: `id = base + node` (the node number in the low 4
//! bits). Commands (`0x100`‥`0x140`), replies (`0x180`‥`0x1B0`), then the parameter and
//! test commands (`0x200`‥`0x270`), as `eha.dbc` lists them.

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
