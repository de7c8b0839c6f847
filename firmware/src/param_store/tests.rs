//! Store tests on a RAM-backed NOR flash that can lose power after any number of byte
//! operations: a save cut at every possible point (inside the erase, inside a double
//! word of the record, inside the commit word) must leave the previous table loadable;
//! corrupt, other-version and out-of-bounds records fall back to the defaults with the
//! fault. Records for the layout tests are built here from the module's table, not with
//! the module's encoder. A save carries the torque feed-forward's table too: a cut leaves
//! the previous parameters *and* the previous table.

use super::*;
use crate::compensation::{record as comp_record, Table, BINS, CHANNELS};
use crate::parameters::ParamId;
use embedded_storage::nor_flash::{ErrorType, NorFlashError, NorFlashErrorKind, ReadNorFlash};
use std::cell::Cell;
use std::rc::Rc;
use std::vec::Vec;

/// G474 dual-bank erase page and programming unit.
pub(super) const PAGE: usize = 2048;
pub(super) const WORD: usize = 8;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum FlashError {
    PowerCut,
    NotErased,
    Unaligned,
    OutOfBounds,
}

impl NorFlashError for FlashError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            FlashError::Unaligned => NorFlashErrorKind::NotAligned,
            FlashError::OutOfBounds => NorFlashErrorKind::OutOfBounds,
            _ => NorFlashErrorKind::Other,
        }
    }
}

/// NOR flash in RAM with the G4's rules (erase to 0xFF by page, program whole erased
/// double words only) and a power budget in byte operations: the byte at which the
/// budget runs out is left half-done (an interrupted erase or program leaves bits that are
/// neither old nor new), and every later operation fails. Double words marked torn
/// ([`CutFlash::torn`]) read back as they are and raise an uncorrectable ECC error, which
/// [`CutFlash::ecc_errors`] counts as the board's NMI handler does.
pub(super) struct CutFlash {
    pub(super) mem: Vec<u8>,
    budget: Option<usize>,
    dead: bool,
    /// Offsets of the double words whose ECC bits disagree with their data.
    pub(super) torn: Vec<usize>,
    /// Uncorrectable ECC errors raised by reads so far.
    pub(super) ecc_errors: Rc<Cell<u32>>,
}

impl CutFlash {
    pub(super) fn blank(pages: usize) -> CutFlash {
        CutFlash::reboot(vec![0xFF; pages * PAGE], None)
    }

    /// The same memory after a reboot, with `budget` byte operations before power fails.
    fn reboot(mem: Vec<u8>, budget: Option<usize>) -> CutFlash {
        CutFlash {
            mem,
            budget,
            dead: false,
            torn: Vec::new(),
            ecc_errors: Rc::new(Cell::new(0)),
        }
    }

    /// Spends one byte operation; false when power fails at this one.
    fn spend(&mut self) -> bool {
        match &mut self.budget {
            Some(0) => {
                self.dead = true;
                false
            }
            Some(n) => {
                *n -= 1;
                true
            }
            None => true,
        }
    }
}

impl ErrorType for CutFlash {
    type Error = FlashError;
}

impl ReadNorFlash for CutFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), FlashError> {
        let at = offset as usize;
        let src = self
            .mem
            .get(at..at + bytes.len())
            .ok_or(FlashError::OutOfBounds)?;
        bytes.copy_from_slice(src);
        for w in &self.torn {
            if *w < at + bytes.len() && at < *w + WORD {
                self.ecc_errors.set(self.ecc_errors.get().wrapping_add(1));
            }
        }
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.mem.len()
    }
}

impl NorFlash for CutFlash {
    const WRITE_SIZE: usize = WORD;
    const ERASE_SIZE: usize = PAGE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), FlashError> {
        let (from, to) = (from as usize, to as usize);
        if from % PAGE != 0 || to % PAGE != 0 || to < from {
            return Err(FlashError::Unaligned);
        }
        if to > self.mem.len() {
            return Err(FlashError::OutOfBounds);
        }
        for i in from..to {
            if self.dead || !self.spend() {
                // Half-erased: some bits set, some still as before.
                self.mem[i] |= 0x5A;
                return Err(FlashError::PowerCut);
            }
            self.mem[i] = 0xFF;
        }
        self.torn.retain(|w| !(from..to).contains(w));
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), FlashError> {
        let at = offset as usize;
        if at % WORD != 0 || bytes.len() % WORD != 0 {
            return Err(FlashError::Unaligned);
        }
        if at + bytes.len() > self.mem.len() {
            return Err(FlashError::OutOfBounds);
        }
        if self.mem[at..at + bytes.len()].iter().any(|b| *b != 0xFF) {
            return Err(FlashError::NotErased);
        }
        for (i, b) in bytes.iter().enumerate() {
            if self.dead || !self.spend() {
                // Half-programmed: only some of the bits to clear are cleared.
                self.mem[at + i] &= *b | 0x3C;
                return Err(FlashError::PowerCut);
            }
            self.mem[at + i] = *b;
        }
        Ok(())
    }
}

/// Erase pages per slot: the record and the feed-forward table need two.
pub(super) const SLOT_PAGES: usize = SPAN.div_ceil(PAGE);

fn store(flash: CutFlash) -> ParamStore<CutFlash> {
    store_in_slots(flash, SLOT_PAGES)
}

/// A feed-forward table that differs with `k`: a ramp in the constant channel.
fn comp_table(k: i16) -> Table {
    let mut raw = [[0i16; CHANNELS]; BINS];
    for (b, r) in raw.iter_mut().enumerate() {
        *r = [k * (b as i16 % 50), -k, 3 * k];
    }
    Table::from_raw([15, 40, 20], &raw).unwrap()
}

/// Saves `values` with the feed-forward table `t`.
fn save_with(
    s: &mut ParamStore<CutFlash>,
    values: &[f32; COUNT],
    t: &Table,
) -> Result<u32, StoreError<FlashError>> {
    s.save(values, comp_record::source(t))
}

/// Saves `values` with an empty feed-forward table.
fn save(
    s: &mut ParamStore<CutFlash>,
    values: &[f32; COUNT],
) -> Result<u32, StoreError<FlashError>> {
    save_with(s, values, &Table::ZERO)
}

/// The feed-forward table of the record the last load took.
fn loaded_table(s: &mut ParamStore<CutFlash>) -> Result<Table, comp_record::RecordError> {
    let mut t = Table::ZERO;
    comp_record::read(TABLE_LEN, |at, buf| s.read_table(at, buf), &mut t).map(|()| t)
}

/// The store on slots of `pages` erase pages each, A first, B right after it.
fn store_in_slots(flash: CutFlash, pages: usize) -> ParamStore<CutFlash> {
    let len = (pages * PAGE) as u32;
    ParamStore::new(flash, 0, len, len).expect("layout")
}

/// A table that differs from the defaults in every entry by `k` (valid for small k).
pub(super) fn table(k: f32) -> [f32; COUNT] {
    let mut cfg = Config::nominal();
    ParamId::SpeedKp.set(&mut cfg, 0.14 + 0.01 * k).unwrap();
    ParamId::AbsorberPrechargePa
        .set(&mut cfg, 3e6 + 1e5 * k)
        .unwrap();
    ParamId::TelemetryDecimation
        .set(&mut cfg, 20.0 + k)
        .unwrap();
    parameters::snapshot(&cfg)
}

/// Every power-cut point of a save that follows `before` saves: the reboot loads the
/// last complete table until the very last byte of the commit word is written, and the
/// new one from then on; a save after the cut always succeeds. Returns the number of cut
/// points tried.
fn cut_everywhere(before: &[[f32; COUNT]]) -> usize {
    cut_everywhere_in(SLOT_PAGES, before)
}

/// [`cut_everywhere`] on slots of `pages` erase pages each. Save k carries the
/// feed-forward table `comp_table(k)`; the cut save carries `comp_table(9)`.
fn cut_everywhere_in(pages: usize, before: &[[f32; COUNT]]) -> usize {
    let mut base = store_in_slots(CutFlash::blank(2 * pages), pages);
    for (k, t) in before.iter().enumerate() {
        save_with(&mut base, t, &comp_table(k as i16 + 1)).unwrap();
    }
    let base_mem = base.into_inner().mem;
    let old = before.last().copied();
    let old_table = (!before.is_empty()).then(|| comp_table(before.len() as i16));
    let new = table(9.0);
    let total = pages * PAGE + RECORD_LEN + TABLE_LEN + COMMIT_LEN;
    // Every cut in the erase and the first and last 64 bytes of each record, and every
    // 7th byte between (the table's 3 KiB would take minutes byte by byte).
    let cuts = (0..=total).filter(|c| {
        let w = c.saturating_sub(pages * PAGE);
        *c < pages * PAGE
            || w < 64
            || total - c < 64
            || (w + 64 > TABLE_AT && w < TABLE_AT + 64)
            || c % 7 == 0
    });
    let mut tried = 0;
    for cut in cuts {
        tried += 1;
        let mut s = store_in_slots(CutFlash::reboot(base_mem.clone(), Some(cut)), pages);
        let result = save_with(&mut s, &new, &comp_table(9));
        let mem = s.into_inner().mem;
        let mut rebooted = store_in_slots(CutFlash::reboot(mem.clone(), None), pages);
        let (values, outcome) = rebooted.load();
        if cut < total {
            assert_eq!(
                result,
                Err(StoreError::Flash(FlashError::PowerCut)),
                "cut {cut}"
            );
            assert_eq!(values, old, "cut {cut}: {outcome:?}");
            if old.is_some() {
                assert!(matches!(outcome, LoadOutcome::Loaded { .. }), "cut {cut}");
                assert_eq!(loaded_table(&mut rebooted).ok(), old_table, "cut {cut}");
            }
        } else {
            assert!(result.is_ok(), "cut {cut}: {result:?}");
            assert_eq!(values, Some(new), "cut {cut}");
            assert_eq!(loaded_table(&mut rebooted), Ok(comp_table(9)), "cut {cut}");
        }
        // The next save works whatever the cut left behind.
        let again = table(10.0);
        save(&mut rebooted, &again).unwrap();
        assert_eq!(rebooted.load().0, Some(again), "save after cut {cut}");
    }
    println!(
        "{} saves before: {tried} of {} cut points (erase {} B, record {RECORD_LEN} B, table {TABLE_LEN} B, commit {COMMIT_LEN} B), each reloads the previous table",
        before.len(),
        total + 1,
        pages * PAGE
    );
    total + 1
}

#[test]
fn a_power_cut_anywhere_in_the_first_save_leaves_the_store_blank() {
    let n = cut_everywhere(&[]);
    assert_eq!(
        n,
        SLOT_PAGES * PAGE + RECORD_LEN + TABLE_LEN + COMMIT_LEN + 1
    );
}

#[test]
fn a_power_cut_anywhere_in_a_save_leaves_the_previous_table() {
    // One table before: the save goes to the blank page B.
    cut_everywhere(&[table(1.0)]);
}

#[test]
fn a_power_cut_while_overwriting_the_older_page_leaves_the_newer_table() {
    // A holds table 1, B table 2: the save erases A; table 2 must survive.
    cut_everywhere(&[table(1.0), table(2.0)]);
}

#[test]
fn a_slot_of_more_pages_is_erased_whole_and_survives_a_cut_in_any_page() {
    // A slot longer than the record: the save erases the whole slot, and a cut in its
    // last page still leaves the previous table in the other slot.
    let n = cut_everywhere_in(SLOT_PAGES + 1, &[table(1.0), table(2.0)]);
    assert_eq!(
        n,
        (SLOT_PAGES + 1) * PAGE + RECORD_LEN + TABLE_LEN + COMMIT_LEN + 1
    );
}

#[test]
fn the_newest_of_two_valid_records_wins_and_pages_alternate() {
    let mut s = store(CutFlash::blank(2 * SLOT_PAGES));
    assert_eq!(s.load(), (None, LoadOutcome::Blank));
    for k in 1..=5u32 {
        let t = table(k as f32);
        assert_eq!(save_with(&mut s, &t, &comp_table(k as i16)), Ok(k));
        assert_eq!(s.load(), (Some(t), LoadOutcome::Loaded { sequence: k }));
        assert_eq!(loaded_table(&mut s), Ok(comp_table(k as i16)));
    }
    // Sequence 5 went to slot A (odd), 4 to slot B.
    let mem = s.into_inner().mem;
    let b = SLOT_PAGES * PAGE;
    assert_eq!(u32::from_le_bytes(mem[8..12].try_into().unwrap()), 5);
    assert_eq!(
        u32::from_le_bytes(mem[b + 8..b + 12].try_into().unwrap()),
        4
    );
}

/// A record built from the module's layout table, independently of its encoder.
fn documented_record(version: u16, fingerprint: u32, sequence: u32, values: &[f32]) -> Vec<u8> {
    let mut r = Vec::new();
    r.extend_from_slice(b"EHAP");
    r.extend_from_slice(&version.to_le_bytes());
    r.extend_from_slice(&(values.len() as u16).to_le_bytes());
    r.extend_from_slice(&sequence.to_le_bytes());
    r.extend_from_slice(&fingerprint.to_le_bytes());
    for v in values {
        r.extend_from_slice(&v.to_le_bytes());
    }
    // The table-driven CRC of the crate: another implementation than the store's.
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC).checksum(&r);
    r.extend_from_slice(&crc.to_le_bytes());
    while r.len() % 8 != 0 {
        r.push(0xFF);
    }
    r.extend_from_slice(&documented_empty_table());
    r.extend_from_slice(b"CMMT");
    r.extend_from_slice(&sequence.to_le_bytes());
    r
}

/// An all-zero feed-forward table's record from the layout documented in
/// `compensation::record` (exponents 0), independently of its encoder.
fn documented_empty_table() -> Vec<u8> {
    let mut r = Vec::new();
    r.extend_from_slice(b"EHCT");
    r.extend_from_slice(&1u16.to_le_bytes());
    r.extend_from_slice(&512u16.to_le_bytes());
    r.push(3);
    r.extend_from_slice(&[0; 7]);
    r.extend_from_slice(&[0; 512 * 6]);
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC).checksum(&r);
    r.extend_from_slice(&crc.to_le_bytes());
    r.extend_from_slice(&[0xFF; 4]);
    r
}

fn flash_with(page_a: &[u8]) -> CutFlash {
    let mut f = CutFlash::blank(2 * SLOT_PAGES);
    f.mem[..page_a.len()].copy_from_slice(page_a);
    f
}

#[test]
fn the_crc_is_crc32_iso_hdlc() {
    // The standard check value of CRC-32 over "123456789".
    assert_eq!(CRC.checksum(b"123456789"), 0xCBF4_3926);
}

#[test]
fn a_record_written_to_the_documented_layout_loads() {
    let t = table(3.0);
    let rec = documented_record(2, parameters::LAYOUT_FINGERPRINT, 7, &t);
    assert_eq!(rec.len(), SPAN);
    let mut s = store(flash_with(&rec));
    assert_eq!(s.load(), (Some(t), LoadOutcome::Loaded { sequence: 7 }));
    // And the store writes exactly that layout.
    let mut w = store(CutFlash::blank(2 * SLOT_PAGES));
    save(&mut w, &t).unwrap();
    let mem = w.into_inner().mem;
    let rec1 = documented_record(2, parameters::LAYOUT_FINGERPRINT, 1, &t);
    assert_eq!(&mem[..SPAN], &rec1[..]);
}

#[test]
fn a_record_of_the_table_before_the_flow_ripple_parameters_still_loads() {
    // 34 values, the fingerprint of the first 34 ids and names (computed here with the
    // table-driven CRC), the feed-forward table right after the shorter record: the
    // values load, ids 64-68 at their defaults, and the table is found.
    let t = table(3.0);
    let legacy = &t[..34];
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);
    let mut d = crc.digest();
    for p in &ParamId::ALL[..34] {
        d.update(&[*p as u8]);
        d.update(p.name().as_bytes());
    }
    let rec = documented_record(2, d.finalize(), 9, legacy);
    assert_eq!(
        rec.len(),
        SPAN - 16,
        "four values fewer, 16 bytes with padding"
    );
    let mut s = store(flash_with(&rec));
    let (values, outcome) = s.load();
    assert_eq!(outcome, LoadOutcome::Loaded { sequence: 9 });
    let values = values.unwrap();
    assert_eq!(&values[..34], legacy);
    for (p, v) in ParamId::ALL[34..].iter().zip(&values[34..]) {
        assert_eq!(*v, p.default_value(), "{p}");
    }
    assert_eq!(values[34..], [0.0, 0.0, 0.0, 8.0e-4, 0.1]);
    assert_eq!(loaded_table(&mut s), Ok(Table::ZERO));
    // A save writes the present layout; the next load takes it.
    save(&mut s, &values).unwrap();
    assert_eq!(
        s.load(),
        (Some(values), LoadOutcome::Loaded { sequence: 10 })
    );
    // The legacy record with a flipped value is still refused.
    let mut bad = rec.clone();
    bad[20] ^= 1;
    boots_to_defaults_with_fault(flash_with(&bad), LoadOutcome::Corrupt);
}

#[test]
fn the_save_after_the_last_sequence_number_wins() {
    // Found by fuzzing: a record at sequence u32::MAX; the save after it wraps to 0 and
    // used to lose to it ("newer = larger"), so the saved table vanished at the next boot.
    let old = table(3.0);
    let rec = documented_record(2, parameters::LAYOUT_FINGERPRINT, u32::MAX, &old);
    let mut s = store(flash_with(&rec));
    let new = table(4.0);
    assert_eq!(save(&mut s, &new), Ok(0));
    assert_eq!(s.load(), (Some(new), LoadOutcome::Loaded { sequence: 0 }));
    let newer = table(5.0);
    assert_eq!(save(&mut s, &newer), Ok(1));
    assert_eq!(s.load(), (Some(newer), LoadOutcome::Loaded { sequence: 1 }));
}

fn boots_to_defaults_with_fault(flash: CutFlash, want: LoadOutcome) {
    let mut s = store(flash);
    let (cfg, outcome) = boot_config(&mut s, &Config::nominal());
    assert_eq!(cfg, Config::nominal());
    assert_eq!(outcome, BootOutcome::DefaultsAfterInvalid(want));
    assert!(outcome.is_fault());
}

#[test]
fn a_corrupt_record_gives_the_defaults_and_the_fault() {
    let t = table(3.0);
    let fp = parameters::LAYOUT_FINGERPRINT;
    // One flipped bit in a value: the CRC no longer matches.
    let mut rec = documented_record(2, fp, 1, &t);
    rec[20] ^= 0x01;
    boots_to_defaults_with_fault(flash_with(&rec), LoadOutcome::Corrupt);
    // A record without its commit word (cut between record and commit).
    let mut rec = documented_record(2, fp, 1, &t);
    let n = rec.len();
    rec[n - 8..].fill(0xFF);
    boots_to_defaults_with_fault(flash_with(&rec), LoadOutcome::Corrupt);
    // Garbage in the header.
    boots_to_defaults_with_fault(flash_with(&[0x12; 64]), LoadOutcome::Corrupt);
}

#[test]
fn an_old_version_or_another_table_gives_the_defaults_and_the_fault() {
    let t = table(3.0);
    let fp = parameters::LAYOUT_FINGERPRINT;
    // Version 1: the layout before the feed-forward table.
    let rec = documented_record(1, fp, 1, &t);
    boots_to_defaults_with_fault(flash_with(&rec), LoadOutcome::OtherVersion);
    let rec = documented_record(2, fp ^ 1, 1, &t);
    boots_to_defaults_with_fault(flash_with(&rec), LoadOutcome::OtherVersion);
    // A shorter table of an older firmware.
    let rec = documented_record(2, fp, 1, &t[..COUNT - 1]);
    boots_to_defaults_with_fault(flash_with(&rec), LoadOutcome::OtherVersion);
}

#[test]
fn stored_values_out_of_bounds_or_inconsistent_give_the_defaults_and_the_fault() {
    let fp = parameters::LAYOUT_FINGERPRINT;
    let mut t = table(3.0);
    t[0] = 1e6; // current.kp_d above 200 V/A, CRC valid
    let rec = documented_record(2, fp, 1, &t);
    boots_to_defaults_with_fault(flash_with(&rec), LoadOutcome::Corrupt);
    let mut t = table(3.0);
    t[0] = f32::NAN;
    let rec = documented_record(2, fp, 1, &t);
    boots_to_defaults_with_fault(flash_with(&rec), LoadOutcome::Corrupt);
}

#[test]
fn a_blank_store_boots_the_defaults_without_a_fault_and_a_valid_one_its_table() {
    let mut s = store(CutFlash::blank(2 * SLOT_PAGES));
    let (cfg, outcome) = boot_config(&mut s, &Config::nominal());
    assert_eq!((cfg, outcome), (Config::nominal(), BootOutcome::Defaults));
    assert!(!outcome.is_fault());
    let t = table(4.0);
    save(&mut s, &t).unwrap();
    let (cfg, outcome) = boot_config(&mut s, &Config::nominal());
    assert_eq!(outcome, BootOutcome::Stored { sequence: 1 });
    assert_eq!(cfg.speed.kp, 0.14 + 0.01 * 4.0);
    assert_eq!(cfg.rates.telemetry_decimation, 24);
    assert_eq!(parameters::snapshot(&cfg), t);
}

#[test]
fn a_corrupt_newer_page_falls_back_to_the_older_valid_one_without_a_fault() {
    let mut s = store(CutFlash::blank(2 * SLOT_PAGES));
    save(&mut s, &table(1.0)).unwrap();
    save(&mut s, &table(2.0)).unwrap();
    let mut f = s.into_inner();
    f.mem[SLOT_PAGES * PAGE + 40] ^= 0x80; // slot B holds sequence 2
    let mut s = store(f);
    assert_eq!(
        s.load(),
        (Some(table(1.0)), LoadOutcome::Loaded { sequence: 1 })
    );
}

#[test]
fn a_corrupt_feed_forward_table_is_refused_alone() {
    // One flipped bit in the table's values: the parameters still load, the table's CRC
    // refuses it (the controller then runs uncompensated with fault 21).
    let mut s = store(CutFlash::blank(2 * SLOT_PAGES));
    save_with(&mut s, &table(1.0), &comp_table(4)).unwrap();
    let mut f = s.into_inner();
    f.mem[TABLE_AT + 100] ^= 0x04;
    let mut s = store(f);
    assert_eq!(
        s.load(),
        (Some(table(1.0)), LoadOutcome::Loaded { sequence: 1 })
    );
    assert!(matches!(
        loaded_table(&mut s),
        Err(comp_record::RecordError::Crc { .. })
    ));
    // Nothing loaded yet: no table to read.
    let mut blank = store(CutFlash::blank(2 * SLOT_PAGES));
    let mut buf = [0u8; 8];
    assert!(!blank.read_table(0, &mut buf));
}

#[test]
fn misplaced_slots_are_refused() {
    let page = PAGE as u32;
    let slot = SLOT_PAGES as u32 * page;
    let pages = 2 * SLOT_PAGES;
    for (a, b, len, why) in [
        (8, slot, slot, "not page-aligned"),
        (0, 0, slot, "the same slot"),
        (0, 2 * slot, slot, "B past the end of the flash"),
        (0, slot, 2 * slot, "overlapping slots"),
        (0, slot, slot + 8, "not a whole number of pages"),
        (0, slot, 0, "empty"),
        (0, page, page, "shorter than a record"),
        (slot, 0, u32::MAX, "past the address range"),
    ] {
        assert!(
            matches!(
                ParamStore::new(CutFlash::blank(pages), a, b, len),
                Err(StoreError::Layout)
            ),
            "{why}"
        );
    }
    // B before A is fine.
    assert!(ParamStore::new(CutFlash::blank(pages), slot, 0, slot).is_ok());
}
