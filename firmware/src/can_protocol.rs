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

pub mod codec;
pub mod error;
pub mod frame;
pub mod function;
pub mod id;
pub mod reject;
pub mod reply;
pub mod request;
pub mod wire;

pub use codec::{
    decode_command, decode_reply, encode_command, encode_get_parameter, encode_reply,
    encode_set_parameter,
};
pub use error::DecodeError;
pub use frame::{acceptance_filters, Frame, NodeId};
pub use function::Function;
pub use reject::{RejectReason, Rejection};
pub use reply::{Diagnostics, Reply, Status};
pub use request::Request;
pub use wire::{
    EncodeError, COMPENSATION_HEADER_BIN, MAX_DLC, MODE_CODE_MAX, NODE_MAX, NO_COMMAND,
    SETPOINT_PA_PER_LSB, SETPOINT_RAD_S_PER_LSB, STANDARD_ID_MAX, STATUS_PA_PER_LSB,
    STATUS_RAD_S_PER_LSB,
};

#[cfg(test)]
mod tests;
