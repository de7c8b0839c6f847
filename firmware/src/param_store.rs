//! Persistence of the live parameter table ([`crate::parameters`]) and the torque
//! feed-forward's table ([`crate::compensation`]) in NOR flash: two slots used alternately
//! (A/B), each a whole number of erase pages holding at most one record with a format
//! version, a table fingerprint, a sequence number and a CRC-32, followed by the
//! feed-forward table's own record (version, sizes, CRC: [`crate::compensation::record`])
//! and completed by a separate commit word written last. The slot length is the caller's
//! (the board's named constant): two 2 KiB pages of the G474's bank 2 hold the record.
//!
//! Generic over [`embedded_storage::nor_flash::NorFlash`], so the same code runs on the
//! G474's flash and on a RAM-backed flash in the host tests.
//!
//! # Why two slots and a commit word
//!
//! A save erases and writes only the slot that does *not* hold the newest valid record,
//! so the previous table stays intact until the new one is complete: a power cut at any
//! point of a save (during the erase, the record, or the commit word; mid-word included)
//! leaves the old record readable, and the next load returns the old table or the new one,
//! never a mixture — the parameters and the feed-forward table are saved and committed
//! together. A record counts only when its CRC matches *and* its commit word is present;
//! the commit word is written after both records, so a save interrupted after their last
//! data word but before the commit is not taken either. The feed-forward table of the
//! record loaded is checked on its own ([`ParamStore::read_table`] feeds
//! [`crate::Controller::load_compensation_record`]): a wrong size, version or CRC refuses
//! the table alone (fault 21), the parameters still load. The sequence number
//! (newer = larger, counted with wrap-around) decides between two valid slots. Two slots cost
//! twice the record's pages of flash; a log-structured store (e.g. `sequential-storage`) would
//! level wear, but the
//! table is saved by an operator, a few times in a drive's life, far below the 10 000
//! erase cycles of the G4's flash, and the A/B scheme is a fraction of the code size.
//!
//! # Record layout (little endian, from the page start)
//!
//! | offset | size | content                                                      |
//! |--------|------|--------------------------------------------------------------|
//! | 0      | 4    | magic `0x5041_4845` (bytes `E H A P`)                        |
//! | 4      | 2    | format version ([`FORMAT_VERSION`])                          |
//! | 6      | 2    | number of values ([`crate::parameters::COUNT`])              |
//! | 8      | 4    | sequence number                                              |
//! | 12     | 4    | table fingerprint ([`crate::parameters::LAYOUT_FINGERPRINT`]) |
//! | 16     | 4·N  | values, `f32`, in [`crate::parameters::ParamId::ALL`] order  |
//! | 16+4N  | 4    | CRC-32 (ISO-HDLC) of bytes 0‥16+4N                           |
//! | …      |      | `0xFF` padding to a multiple of 8 bytes                      |
//! | R      | T    | the feed-forward table's record ([`crate::compensation::record`]) |
//! | R+T    | 8    | commit word: `0x544D_4D43` (`C M M T`), then the sequence number |
//!
//! with R = [`RECORD_LEN`], T = [`TABLE_LEN`]. The records and the commit word are
//! multiples of 8 bytes, the G4's programming unit (one double word with ECC).
//!
//! # Loading
//!
//! A record of the table before the flow-ripple modulation's parameters (ids 64–68:
//! [`parameters::LEGACY_COUNT`] values, its own fingerprint, the feed-forward table at
//! [`LEGACY_RECORD_LEN`]) still loads, the new parameters at their defaults (the
//! modulation off); the next save writes the present layout.
//!
//! [`ParamStore::load`] takes the valid record with the larger sequence number. Without
//! one, the outcome says why: both pages blank (never saved: defaults, no fault), or a
//! record that is corrupt or of another format version or table (defaults and fault 16,
//! [`crate::FaultCode::ParameterStoreInvalid`]). [`boot`] and [`boot_config`] also refuse
//! a record whose values are out of their bounds or inconsistent, so the controller never
//! starts from garbage.

pub mod ecc;

pub use crate::param_crc::CRC;

use crate::compensation::record::{self as table_record, CHUNK_MAX};
use crate::config::Config;
use crate::parameters::{self, COUNT, LEGACY_COUNT};
use embedded_storage::nor_flash::NorFlash;

/// Format version of the record; a record of another version is not loaded (version 2:
/// the feed-forward table between the record and the commit word).
pub const FORMAT_VERSION: u16 = 2;
/// Record magic (`E H A P` in memory order).
pub const MAGIC: u32 = 0x5041_4845;
/// Commit-word magic (`C M M T` in memory order).
pub const COMMIT_MAGIC: u32 = 0x544D_4D43;

const HEADER_LEN: usize = 16;
const CRC_AT: usize = HEADER_LEN + 4 * COUNT;
/// Length of a record of `count` values with its padding. [bytes]
const fn record_len(count: usize) -> usize {
    (HEADER_LEN + 4 * count + 4).div_ceil(8) * 8
}
/// Length of the record with its padding, before the commit word. [bytes]
pub const RECORD_LEN: usize = record_len(COUNT);
/// Length of a record of the table before the flow-ripple parameters. [bytes]
pub const LEGACY_RECORD_LEN: usize = record_len(LEGACY_COUNT);
/// Where the feed-forward table's record starts. [bytes]
pub const TABLE_AT: usize = RECORD_LEN;
/// Length of the feed-forward table's record. [bytes]
pub const TABLE_LEN: usize = table_record::RECORD_LEN;
/// Where the commit word starts. [bytes]
pub const COMMIT_AT: usize = TABLE_AT + TABLE_LEN;
/// Length of the commit word. [bytes]
pub const COMMIT_LEN: usize = 8;
/// Bytes a record occupies in its slot. [bytes]
pub const SPAN: usize = COMMIT_AT + COMMIT_LEN;

/// What a page holds.
#[derive(Clone, Copy, Debug)]
enum Page {
    /// Erased header: never written (or the erase of a save was the last thing done).
    Blank,
    /// A complete record of this format and table (or of the legacy table, its new
    /// parameters at their defaults), its feed-forward table at `table_at`.
    Valid {
        sequence: u32,
        values: [f32; COUNT],
        table_at: usize,
    },
    /// A record of another format version or parameter table.
    OtherVersion,
    /// Anything else: bad magic, bad CRC, missing commit word.
    Corrupt,
}

/// Result of a load.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LoadOutcome {
    /// A valid record, with its sequence number.
    Loaded {
        /// The record's sequence number.
        sequence: u32,
    },
    /// Both pages blank: nothing was ever saved (defaults, not a fault).
    Blank,
    /// No valid record, and at least one of another version or table (fault 16).
    OtherVersion,
    /// No valid record, and at least one corrupt page (fault 16).
    Corrupt,
}

/// Why a store could not be opened or a save failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StoreError<E> {
    /// The slot offsets are not erase-page aligned, the slot length is not a whole
    /// number of erase pages or is shorter than a record, the slots overlap or leave the
    /// flash, or the flash's programming unit does not divide 8 bytes.
    Layout,
    /// The flash driver failed.
    Flash(E),
}

/// The two slots of the parameter table on a flash.
#[derive(Debug)]
pub struct ParamStore<F> {
    flash: F,
    pages: [u32; 2],
    slot_len: u32,
    /// The slot the last [`ParamStore::load`] took its record from, and where its
    /// feed-forward table starts in it.
    loaded: Option<(u32, usize)>,
}

impl<F: NorFlash> ParamStore<F> {
    /// Opens the store on two slots of `slot_len` bytes at offsets `slot_a` and `slot_b` of
    /// `flash` (offsets as the driver counts them, each the start of an erase page; the
    /// length a whole number of erase pages).
    pub fn new(
        flash: F,
        slot_a: u32,
        slot_b: u32,
        slot_len: u32,
    ) -> Result<ParamStore<F>, StoreError<F::Error>> {
        let erase = F::ERASE_SIZE as u32;
        let end = |slot: u32| slot.checked_add(slot_len);
        let fits = F::WRITE_SIZE > 0
            && 8 % F::WRITE_SIZE == 0
            && erase > 0
            && slot_len as usize >= SPAN
            && slot_len % erase == 0
            && slot_a % erase == 0
            && slot_b % erase == 0
            && [slot_a, slot_b]
                .iter()
                .all(|s| end(*s).is_some_and(|e| e as usize <= flash.capacity()))
            && (end(slot_a).is_some_and(|e| e <= slot_b)
                || end(slot_b).is_some_and(|e| e <= slot_a));
        if !fits {
            return Err(StoreError::Layout);
        }
        Ok(ParamStore {
            flash,
            pages: [slot_a, slot_b],
            slot_len,
            loaded: None,
        })
    }

    /// Gives the flash back.
    pub fn into_inner(self) -> F {
        self.flash
    }

    fn read_page(&mut self, page: u32) -> Page {
        // A legacy record is shorter: the bytes read beyond it are its table's.
        let mut record = [0u8; RECORD_LEN];
        if self.flash.read(page, &mut record).is_err() {
            return Page::Corrupt;
        }
        let table_at = match usize::from(u16::from_le_bytes([record[6], record[7]])) {
            LEGACY_COUNT => LEGACY_RECORD_LEN,
            _ => RECORD_LEN,
        };
        let mut commit = [0u8; COMMIT_LEN];
        if self
            .flash
            .read(page + (table_at + TABLE_LEN) as u32, &mut commit)
            .is_err()
        {
            return Page::Corrupt;
        }
        parse(&record, &commit)
    }

    /// The newest valid table, if any, and what the pages held.
    pub fn load(&mut self) -> (Option<[f32; COUNT]>, LoadOutcome) {
        let pages = self.pages.map(|p| self.read_page(p));
        let found = newest(&pages);
        self.loaded = found.and_then(|(i, _, _)| {
            let table_at = match pages.get(i) {
                Some(Page::Valid { table_at, .. }) => *table_at,
                _ => TABLE_AT,
            };
            self.pages.get(i).map(|p| (*p, table_at))
        });
        match found {
            Some((_, sequence, values)) => (Some(values), LoadOutcome::Loaded { sequence }),
            // `matches!`, not `==`: a derived comparison of the value arrays costs flash.
            None if pages.iter().all(|p| matches!(p, Page::Blank)) => (None, LoadOutcome::Blank),
            None if pages.iter().any(|p| matches!(p, Page::OtherVersion)) => {
                (None, LoadOutcome::OtherVersion)
            }
            None => (None, LoadOutcome::Corrupt),
        }
    }

    /// Reads `buf.len()` bytes at offset `at` of the feed-forward table's record in the
    /// slot the last [`ParamStore::load`] took (false: none loaded, or the flash failed).
    pub fn read_table(&mut self, at: usize, buf: &mut [u8]) -> bool {
        let Some((page, table_at)) = self.loaded else {
            return false;
        };
        at + buf.len() <= TABLE_LEN && self.flash.read(page + (table_at + at) as u32, buf).is_ok()
    }

    /// Saves `values` (in [`parameters::ParamId::ALL`] order) and the feed-forward table
    /// whose record `table` produces chunk by chunk (it fills the buffer and returns the
    /// chunk's offset in the record and length, `None` after the last;
    /// [`crate::compensation::record::source`]) as the newest record: erases the slot not
    /// holding the newest valid record, writes the record, the table, then the commit
    /// word. Returns the new record's sequence number.
    pub fn save(
        &mut self,
        values: &[f32; COUNT],
        mut table: impl FnMut(&mut [u8; CHUNK_MAX]) -> Option<(usize, usize)>,
    ) -> Result<u32, StoreError<F::Error>> {
        let pages = self.pages.map(|p| self.read_page(p));
        let [a, b] = self.pages;
        let (page, sequence) = match newest(&pages) {
            Some((0, sequence, _)) => (b, sequence.wrapping_add(1)),
            Some((_, sequence, _)) => (a, sequence.wrapping_add(1)),
            None => (a, 1),
        };
        let record = encode(sequence, values);
        let mut commit = [0u8; COMMIT_LEN];
        commit[..4].copy_from_slice(&COMMIT_MAGIC.to_le_bytes());
        commit[4..].copy_from_slice(&sequence.to_le_bytes());
        self.flash
            .erase(page, page + self.slot_len)
            .map_err(StoreError::Flash)?;
        self.flash.write(page, &record).map_err(StoreError::Flash)?;
        let mut chunk = [0u8; CHUNK_MAX];
        while let Some((at, len)) = table(&mut chunk) {
            let bytes = chunk.get(..len).ok_or(StoreError::Layout)?;
            if at + len > TABLE_LEN {
                return Err(StoreError::Layout);
            }
            self.flash
                .write(page + (TABLE_AT + at) as u32, bytes)
                .map_err(StoreError::Flash)?;
        }
        self.flash
            .write(page + COMMIT_AT as u32, &commit)
            .map_err(StoreError::Flash)?;
        Ok(sequence)
    }
}

/// Whether sequence `a` is newer than `b` in serial-number arithmetic (RFC 1982): `save`
/// counts on with wrapping, so the record after `u32::MAX` is 0, and it must win.
fn is_newer(a: u32, b: u32) -> bool {
    (a.wrapping_sub(b) as i32) > 0
}

/// The valid page with the newer sequence number: (page index, sequence, values).
fn newest(pages: &[Page; 2]) -> Option<(usize, u32, [f32; COUNT])> {
    let mut best: Option<(usize, u32, [f32; COUNT])> = None;
    for (i, p) in pages.iter().enumerate() {
        if let Page::Valid {
            sequence, values, ..
        } = *p
        {
            if best.is_none_or(|(_, s, _)| is_newer(sequence, s)) {
                best = Some((i, sequence, values));
            }
        }
    }
    best
}

/// The record bytes (without the commit word) for `values`.
fn encode(sequence: u32, values: &[f32; COUNT]) -> [u8; RECORD_LEN] {
    let mut r = [0xFFu8; RECORD_LEN];
    r[0..4].copy_from_slice(&MAGIC.to_le_bytes());
    r[4..6].copy_from_slice(&FORMAT_VERSION.to_le_bytes());
    // COUNT is a few dozen: fits u16.
    r[6..8].copy_from_slice(&(COUNT as u16).to_le_bytes());
    r[8..12].copy_from_slice(&sequence.to_le_bytes());
    r[12..16].copy_from_slice(&parameters::LAYOUT_FINGERPRINT.to_le_bytes());
    for (chunk, v) in r[HEADER_LEN..CRC_AT].chunks_exact_mut(4).zip(values) {
        chunk.copy_from_slice(&v.to_le_bytes());
    }
    let crc = CRC.checksum(&r[..CRC_AT]);
    r[CRC_AT..CRC_AT + 4].copy_from_slice(&crc.to_le_bytes());
    r
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    let mut w = [0u8; 4];
    if let Some(src) = b.get(at..at + 4) {
        w.copy_from_slice(src);
    }
    u32::from_le_bytes(w)
}

/// Classifies a slot from its parameter record and its commit word. A record of the
/// legacy table ([`LEGACY_COUNT`] values, [`parameters::LEGACY_FINGERPRINT`]) is valid
/// too: its values are the first of [`ParamId::ALL`], the others take their defaults.
fn parse(b: &[u8; RECORD_LEN], commit: &[u8; COMMIT_LEN]) -> Page {
    if b[..HEADER_LEN].iter().all(|x| *x == 0xFF) {
        return Page::Blank;
    }
    if u32_at(b, 0) != MAGIC {
        return Page::Corrupt;
    }
    let version = u16::from_le_bytes([b[4], b[5]]);
    let count = u16::from_le_bytes([b[6], b[7]]);
    let (n, fingerprint, table_at) = match usize::from(count) {
        COUNT => (COUNT, parameters::LAYOUT_FINGERPRINT, RECORD_LEN),
        LEGACY_COUNT => (
            LEGACY_COUNT,
            parameters::LEGACY_FINGERPRINT,
            LEGACY_RECORD_LEN,
        ),
        _ => return Page::OtherVersion,
    };
    if version != FORMAT_VERSION || u32_at(b, 12) != fingerprint {
        return Page::OtherVersion;
    }
    let sequence = u32_at(b, 8);
    let crc_at = HEADER_LEN + 4 * n;
    if CRC.checksum(&b[..crc_at]) != u32_at(b, crc_at)
        || u32_at(commit, 0) != COMMIT_MAGIC
        || u32_at(commit, 4) != sequence
    {
        return Page::Corrupt;
    }
    let mut values = [0f32; COUNT];
    for (k, v) in values.iter_mut().enumerate() {
        *v = match b.get(HEADER_LEN + 4 * k..).filter(|_| k < n) {
            Some(chunk) => f32::from_bits(u32_at(chunk, 0)),
            None => parameters::ADDED_DEFAULTS
                .get(k.wrapping_sub(LEGACY_COUNT))
                .copied()
                .unwrap_or(0.0),
        };
    }
    Page::Valid {
        sequence,
        values,
        table_at,
    }
}

/// What boot made of the store.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BootOutcome {
    /// The stored table is in use.
    Stored {
        /// Its sequence number.
        sequence: u32,
    },
    /// Nothing stored: defaults, no fault.
    Defaults,
    /// The stored table was unusable (corrupt, another version, or values refused):
    /// defaults are in use and fault 16 must be reported.
    DefaultsAfterInvalid(LoadOutcome),
}

impl BootOutcome {
    /// True when the controller must latch [`crate::FaultCode::ParameterStoreInvalid`].
    pub fn is_fault(&self) -> bool {
        matches!(self, BootOutcome::DefaultsAfterInvalid(_))
    }
}

/// Boot: loads the newest table and hands it to `apply` (which checks and applies it,
/// returning false when it refuses it). A record `apply` refuses counts as invalid.
pub fn boot<F: NorFlash>(
    store: &mut ParamStore<F>,
    apply: impl FnOnce(&[f32; COUNT]) -> bool,
) -> BootOutcome {
    match store.load() {
        (Some(v), LoadOutcome::Loaded { sequence }) => {
            if apply(&v) {
                BootOutcome::Stored { sequence }
            } else {
                BootOutcome::DefaultsAfterInvalid(LoadOutcome::Corrupt)
            }
        }
        (_, LoadOutcome::Blank) => BootOutcome::Defaults,
        (_, other) => BootOutcome::DefaultsAfterInvalid(other),
    }
}

/// The configuration to boot with: `defaults` with the stored table applied, or
/// `defaults` alone when nothing usable is stored. A record whose values fail their
/// bounds or the cross-checks counts as invalid.
pub fn boot_config<F: NorFlash>(
    store: &mut ParamStore<F>,
    defaults: &Config,
) -> (Config, BootOutcome) {
    let mut cfg = *defaults;
    let outcome = boot(store, |v| parameters::apply_all(&mut cfg, v).is_ok());
    (cfg, outcome)
}

#[cfg(test)]
mod tests;
