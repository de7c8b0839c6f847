//! The CRC-32 (ISO-HDLC) of the stored parameter record and of the parameter table's
//! layout fingerprint: one definition below both the parameter table
//! ([`crate::parameters`]) and its store ([`crate::param_store`]).

use crc::{Crc, NoTable, CRC_32_ISO_HDLC};

/// CRC-32 used for the record and the table fingerprint (bitwise: no 1 KiB lookup table in
/// flash; a record is checked once per boot and save).
pub const CRC: Crc<u32, NoTable> = Crc::<u32, NoTable>::new(&CRC_32_ISO_HDLC);
