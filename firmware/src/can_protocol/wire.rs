//! The wire format's numbers: frame and node limits, the fixed-point scales of set-points
//! and status values, and the little-endian field readers and writers with the saturation
//! and range checks that turn SI values into wire integers ([`EncodeError`]).

/// Highest mode code on the wire (the codes are the control core's [`Mode::code`]).
///
/// [`Mode::code`]: crate::supervisor::Mode::code
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

/// The bin number of a `CompensationBin` frame that carries the table's header.
pub const COMPENSATION_HEADER_BIN: u16 = 0xFFFF;

/// Mask selecting the node number of an identifier.
pub(super) const NODE_MASK: u16 = 0x00F;

/// A value that cannot be put on the wire.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EncodeError {
    /// Which value, with its unit.
    pub field: &'static str,
    /// What is wrong with it.
    pub problem: &'static str,
}

pub(super) fn read_i32(bytes: &[u8], at: usize) -> i32 {
    let mut b = [0u8; 4];
    if let Some(src) = bytes.get(at..at + 4) {
        b.copy_from_slice(src);
    }
    i32::from_le_bytes(b)
}

pub(super) fn write_i32(data: &mut [u8; MAX_DLC], at: usize, value: i32) {
    if let Some(dst) = data.get_mut(at..at + 4) {
        dst.copy_from_slice(&value.to_le_bytes());
    }
}

pub(super) fn read_f32(bytes: &[u8], at: usize) -> f32 {
    f32::from_bits(read_i32(bytes, at) as u32)
}

pub(super) fn write_f32(data: &mut [u8; MAX_DLC], at: usize, value: f32) {
    write_i32(data, at, value.to_bits() as i32);
}

pub(super) fn wire_bound(si: f32, per_lsb: f32) -> i32 {
    // `as` saturates (and maps NaN to 0), so a bound beyond the field is sent as its limit.
    libm::roundf(si / per_lsb) as i32
}

pub(super) fn saturate_i16(x: f32) -> i16 {
    // `as` saturates and maps NaN to 0, which is the wanted behaviour for a status field.
    libm::roundf(x) as i16
}

pub(super) fn to_wire(value: f32, per_lsb: f32, field: &'static str) -> Result<i32, EncodeError> {
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
