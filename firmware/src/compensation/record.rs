//! The compensation table's record: the one byte format of the table file `eha compensate`
//! writes, of the table's section in the parameter flash, and of the CRC a CAN load is
//! committed with.
//!
//! # Layout (little endian)
//!
//! | offset | size | content                                                       |
//! |--------|------|---------------------------------------------------------------|
//! | 0      | 4    | magic `0x5443_4845` (bytes `E H C T`)                         |
//! | 4      | 2    | format version ([`VERSION`])                                  |
//! | 6      | 2    | bins per revolution ([`super::table::BINS`])                         |
//! | 8      | 1    | channels ([`super::table::CHANNELS`])                                |
//! | 9      | 1    | reserved, 0                                                   |
//! | 10     | 3    | LSB exponent e per channel (`i8`, 0‥=100): value = raw · 2^−e |
//! | 13     | 3    | reserved, 0                                                   |
//! | 16     | 6·N  | per bin the three channels' raw values (`i16`)                |
//! | 16+6N  | 4    | CRC-32 (ISO-HDLC) of bytes 0‥16+6N                            |
//! | 20+6N  | 4    | `0xFF` padding to a multiple of 8 bytes                       |
//!
//! [`RECORD_LEN`] bytes in all (3096). A record of another length, magic, version, bin or
//! channel count, exponent range or CRC is refused ([`RecordError`]).
//!
//! A CAN load ([`Loader`]) receives the header's exponents and bin count, then the bins in
//! order, feeding the same CRC as it goes, and is committed with the CRC of the record
//! that carries them: the host sends the CRC of the file it wrote, so a lost, repeated or
//! corrupted frame fails the commit.

use super::table::{Exponent, Table, BINS, CHANNELS, MAX_EXPONENT};
use core::fmt;
use crc::{Crc, Digest, NoTable, CRC_32_ISO_HDLC};

/// CRC-32 of the record (the parameter record's, bitwise: no table in flash).
pub static CRC: Crc<u32, NoTable> = Crc::<u32, NoTable>::new(&CRC_32_ISO_HDLC);

/// Record magic (`E H C T` in memory order).
pub const MAGIC: u32 = 0x5443_4845;
/// Format version; a record of another version is refused.
pub const VERSION: u16 = 1;
/// Header length. [bytes]
pub const HEADER_LEN: usize = 16;
/// Bytes of one bin's values. [bytes]
pub const BIN_LEN: usize = 2 * CHANNELS;
/// Where the CRC sits. [bytes]
pub const CRC_AT: usize = HEADER_LEN + BIN_LEN * BINS;
/// The record's length with its padding: a multiple of 8 (the G4's programming unit).
/// [bytes]
pub const RECORD_LEN: usize = (CRC_AT + 4).div_ceil(8) * 8;
/// Bins per chunk of [`Encoder`] and [`read`]: 8 bins, 48 bytes, a multiple of 8.
pub const CHUNK_BINS: usize = 8;
/// Largest chunk [`Encoder::next`] produces. [bytes]
pub const CHUNK_MAX: usize = CHUNK_BINS * BIN_LEN;

const _: () = assert!(BINS % CHUNK_BINS == 0 && CHUNK_MAX % 8 == 0 && HEADER_LEN % 8 == 0);

/// Why a record (or a CAN load) was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecordError {
    /// Not [`RECORD_LEN`] bytes.
    Length {
        /// What was there. [bytes]
        found: usize,
    },
    /// Not a compensation table (bad magic).
    Magic,
    /// Another format version.
    Version {
        /// The record's version.
        found: u16,
    },
    /// Another bin count.
    Bins {
        /// The record's bin count.
        found: u16,
    },
    /// Another channel count.
    Channels {
        /// The record's channel count.
        found: u8,
    },
    /// An LSB exponent outside 0‥=[`MAX_EXPONENT`].
    Exponent {
        /// Its channel.
        channel: u8,
        /// Its value.
        found: i8,
    },
    /// The CRC does not match the content.
    Crc {
        /// The CRC the record (or the commit) carries.
        stored: u32,
        /// The CRC of what was read (or received).
        computed: u32,
    },
    /// The storage could not be read.
    Read,
    /// A CAN bin or commit without a header first.
    NotLoading,
    /// A CAN bin out of order.
    OutOfOrder {
        /// The bin expected next.
        expected: u16,
    },
    /// A commit before the last bin.
    Incomplete {
        /// Bins received.
        received: u16,
    },
}

impl RecordError {
    /// What is wrong, in a few words without numbers (for a log that formats no floats).
    pub fn kind(&self) -> &'static str {
        match self {
            RecordError::Length { .. } => "wrong record length",
            RecordError::Magic => "not a compensation table",
            RecordError::Version { .. } => "other format version",
            RecordError::Bins { .. } => "other bin count",
            RecordError::Channels { .. } => "other channel count",
            RecordError::Exponent { .. } => "LSB exponent out of range",
            RecordError::Crc { .. } => "CRC mismatch",
            RecordError::Read => "flash read failed",
            RecordError::NotLoading => "no load started",
            RecordError::OutOfOrder { .. } => "bin out of order",
            RecordError::Incomplete { .. } => "incomplete load",
        }
    }
}

impl fmt::Display for RecordError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RecordError::Length { found } => {
                write!(f, "{found} bytes, a table record has {RECORD_LEN}")
            }
            RecordError::Magic => write!(f, "not a compensation table (magic)"),
            RecordError::Version { found } => {
                write!(f, "format version {found}, this firmware reads {VERSION}")
            }
            RecordError::Bins { found } => write!(f, "{found} bins, this firmware has {BINS}"),
            RecordError::Channels { found } => {
                write!(f, "{found} channels, this firmware has {CHANNELS}")
            }
            RecordError::Exponent { channel, found } => write!(
                f,
                "channel {channel}'s LSB exponent {found} outside 0..={}",
                MAX_EXPONENT
            ),
            RecordError::Crc { stored, computed } => write!(
                f,
                "CRC {stored:#010x} does not match the content ({computed:#010x})"
            ),
            RecordError::Read => write!(f, "the record could not be read"),
            RecordError::NotLoading => write!(f, "no table load started (header first)"),
            RecordError::OutOfOrder { expected } => {
                write!(f, "bin out of order, expected bin {expected}")
            }
            RecordError::Incomplete { received } => {
                write!(f, "commit after {received} of {BINS} bins")
            }
        }
    }
}

/// The header bytes of a record with `exponents`.
pub fn header(exponents: [Exponent; CHANNELS]) -> [u8; HEADER_LEN] {
    let mut h = [0u8; HEADER_LEN];
    h[0..4].copy_from_slice(&MAGIC.to_le_bytes());
    h[4..6].copy_from_slice(&VERSION.to_le_bytes());
    h[6..8].copy_from_slice(&(BINS as u16).to_le_bytes());
    h[8] = CHANNELS as u8;
    for (c, e) in exponents.iter().enumerate() {
        h[10 + c] = *e as u8;
    }
    h
}

/// The header's exponents, after checking everything else in it.
fn parse_header(h: &[u8; HEADER_LEN]) -> Result<[Exponent; CHANNELS], RecordError> {
    if u32::from_le_bytes([h[0], h[1], h[2], h[3]]) != MAGIC {
        return Err(RecordError::Magic);
    }
    let version = u16::from_le_bytes([h[4], h[5]]);
    if version != VERSION {
        return Err(RecordError::Version { found: version });
    }
    let bins = u16::from_le_bytes([h[6], h[7]]);
    if usize::from(bins) != BINS {
        return Err(RecordError::Bins { found: bins });
    }
    if usize::from(h[8]) != CHANNELS {
        return Err(RecordError::Channels { found: h[8] });
    }
    let exponents: [Exponent; CHANNELS] = core::array::from_fn(|c| h[10 + c] as i8);
    check_exponents(exponents)?;
    Ok(exponents)
}

fn check_exponents(exponents: [Exponent; CHANNELS]) -> Result<(), RecordError> {
    match exponents
        .iter()
        .position(|e| !(0..=MAX_EXPONENT).contains(e))
    {
        Some(c) => Err(RecordError::Exponent {
            channel: c as u8,
            found: exponents[c],
        }),
        None => Ok(()),
    }
}

fn bin_values(bytes: &[u8]) -> [i16; CHANNELS] {
    core::array::from_fn(|c| i16::from_le_bytes([bytes[2 * c], bytes[2 * c + 1]]))
}

/// Reads a record of `len` bytes through `read(offset, buffer)` (false: the storage
/// failed) into `table`, in chunks of [`CHUNK_MAX`] bytes (no record-sized buffer). On any
/// refusal `table` is left zero.
pub fn read(
    len: usize,
    mut read: impl FnMut(usize, &mut [u8]) -> bool,
    table: &mut Table,
) -> Result<(), RecordError> {
    let result = (|| {
        if len != RECORD_LEN {
            return Err(RecordError::Length { found: len });
        }
        let mut h = [0u8; HEADER_LEN];
        if !read(0, &mut h) {
            return Err(RecordError::Read);
        }
        let exponents = parse_header(&h)?;
        table.start(exponents).map_err(|_| RecordError::Read)?;
        let mut digest = CRC.digest();
        digest.update(&h);
        let mut chunk = [0u8; CHUNK_MAX];
        for first in (0..BINS).step_by(CHUNK_BINS) {
            if !read(HEADER_LEN + first * BIN_LEN, &mut chunk) {
                return Err(RecordError::Read);
            }
            digest.update(&chunk);
            for (i, b) in chunk.chunks_exact(BIN_LEN).enumerate() {
                table.set_bin(first + i, bin_values(b));
            }
        }
        let mut stored = [0u8; 4];
        if !read(CRC_AT, &mut stored) {
            return Err(RecordError::Read);
        }
        let stored = u32::from_le_bytes(stored);
        let computed = digest.finalize();
        if stored != computed {
            return Err(RecordError::Crc { stored, computed });
        }
        Ok(())
    })();
    if result.is_err() {
        *table = Table::ZERO;
    }
    result
}

/// Reads a record held in `bytes`.
pub fn from_bytes(bytes: &[u8], table: &mut Table) -> Result<(), RecordError> {
    read(
        bytes.len(),
        |at, buf| match bytes.get(at..at + buf.len()) {
            Some(src) => {
                buf.copy_from_slice(src);
                true
            }
            None => false,
        },
        table,
    )
}

/// Produces a table's record chunk by chunk (header, 64 chunks of 8 bins, CRC and padding),
/// each a multiple of 8 bytes at an offset that is one: what a flash driver programs. The
/// table is borrowed per chunk only, so a caller can take it from under a lock each time.
#[derive(Clone)]
pub struct Encoder {
    next: usize,
    digest: Digest<'static, u32, NoTable>,
    buf: [u8; CHUNK_MAX],
}

impl Default for Encoder {
    fn default() -> Self {
        Encoder::new()
    }
}

impl Encoder {
    /// Before the first chunk.
    pub fn new() -> Encoder {
        Encoder {
            next: 0,
            digest: CRC.digest(),
            buf: [0; CHUNK_MAX],
        }
    }

    /// The next chunk of `table`'s record and its offset, `None` after the last. The
    /// table must not change between the calls of one record.
    pub fn next(&mut self, table: &Table) -> Option<(usize, &[u8])> {
        const DATA_CHUNKS: usize = BINS / CHUNK_BINS;
        let step = self.next;
        self.next += 1;
        match step {
            0 => {
                let h = header(table.exponents());
                self.digest.update(&h);
                self.buf[..HEADER_LEN].copy_from_slice(&h);
                Some((0, &self.buf[..HEADER_LEN]))
            }
            s if s <= DATA_CHUNKS => {
                let first = (s - 1) * CHUNK_BINS;
                for i in 0..CHUNK_BINS {
                    for (c, v) in table.raw(first + i).iter().enumerate() {
                        let at = i * BIN_LEN + 2 * c;
                        self.buf[at..at + 2].copy_from_slice(&v.to_le_bytes());
                    }
                }
                self.digest.update(&self.buf);
                Some((HEADER_LEN + first * BIN_LEN, &self.buf[..]))
            }
            s if s == DATA_CHUNKS + 1 => {
                let crc = self.digest.clone().finalize();
                let tail = RECORD_LEN - CRC_AT;
                self.buf[..tail].fill(0xFF);
                self.buf[..4].copy_from_slice(&crc.to_le_bytes());
                Some((CRC_AT, &self.buf[..tail]))
            }
            _ => None,
        }
    }

    /// The whole record of `table` in `out` (a host convenience).
    pub fn write_all(table: &Table, out: &mut [u8; RECORD_LEN]) {
        let mut e = Encoder::new();
        while let Some((at, bytes)) = e.next(table) {
            out[at..at + bytes.len()].copy_from_slice(bytes);
        }
    }
}

/// The CRC a record of `table` carries (what a CAN load is committed with).
pub fn crc_of(table: &Table) -> u32 {
    let mut e = Encoder::new();
    let mut crc = 0;
    while let Some((at, bytes)) = e.next(table) {
        if at == CRC_AT {
            crc = u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
        }
    }
    crc
}

/// A CAN load in progress: the bins received so far and the CRC of the record they make.
#[derive(Clone)]
pub struct Loader {
    next: u16,
    digest: Digest<'static, u32, NoTable>,
}

impl fmt::Debug for Loader {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Loader").field("next", &self.next).finish()
    }
}

impl fmt::Debug for Encoder {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Encoder").field("next", &self.next).finish()
    }
}

impl Loader {
    /// Starts a load into `table` (zeroed) with `exponents` for `bins` bins.
    pub fn begin(
        table: &mut Table,
        exponents: [Exponent; CHANNELS],
        bins: u16,
    ) -> Result<Loader, RecordError> {
        if usize::from(bins) != BINS {
            return Err(RecordError::Bins { found: bins });
        }
        check_exponents(exponents)?;
        table.start(exponents).map_err(|_| RecordError::Read)?;
        let mut digest = CRC.digest();
        digest.update(&header(exponents));
        Ok(Loader { next: 0, digest })
    }

    /// Bin `bin` with its raw values; bins come in order from 0.
    pub fn bin(
        &mut self,
        table: &mut Table,
        bin: u16,
        raw: [i16; CHANNELS],
    ) -> Result<(), RecordError> {
        if bin != self.next || usize::from(bin) >= BINS {
            return Err(RecordError::OutOfOrder {
                expected: self.next,
            });
        }
        table.set_bin(usize::from(bin), raw);
        let mut b = [0u8; BIN_LEN];
        for (c, v) in raw.iter().enumerate() {
            b[2 * c..2 * c + 2].copy_from_slice(&v.to_le_bytes());
        }
        self.digest.update(&b);
        self.next += 1;
        Ok(())
    }

    /// The load is complete and what arrived has the CRC `crc`.
    pub fn finish(self, crc: u32) -> Result<(), RecordError> {
        if usize::from(self.next) != BINS {
            return Err(RecordError::Incomplete {
                received: self.next,
            });
        }
        let computed = self.digest.finalize();
        if computed != crc {
            return Err(RecordError::Crc {
                stored: crc,
                computed,
            });
        }
        Ok(())
    }
}

/// A save's source of `table`'s record for [`crate::param_store::ParamStore::save`]:
/// fills the buffer with the next chunk and returns its offset and length.
pub fn source(table: &Table) -> impl FnMut(&mut [u8; CHUNK_MAX]) -> Option<(usize, usize)> + '_ {
    let mut e = Encoder::new();
    move |buf| {
        let (at, bytes) = e.next(table)?;
        let len = bytes.len();
        buf[..len].copy_from_slice(bytes);
        Some((at, len))
    }
}
