//! Torn double words in the parameter pages, on the store tests' RAM flash with the G4's
//! rules, which behaves like the board when a torn double word is read: its bits come back
//! as the cut left them, and the read raises an uncorrectable-ECC NMI, which the board's
//! handler counts. A save cut in the middle of programming a double word leaves some of
//! the bits it had to clear still set; that is how the tests tear one.

use super::super::*;
use super::*;
use crate::compensation::{record as comp_record, Table};
use std::vec::Vec;

use super::super::tests::{table, CutFlash, PAGE, SLOT_PAGES, WORD};

const SLOT: usize = SLOT_PAGES * PAGE;

/// Tears the double word at `at` of `f` as a cut program leaves it: of the bits it had to
/// clear, those of 0x3C in each byte still set. Returns whether any bit differs.
fn tear(f: &mut CutFlash, at: usize) -> bool {
    let at = at - at % WORD;
    let before: Vec<u8> = f.mem[at..at + WORD].to_vec();
    for b in &mut f.mem[at..at + WORD] {
        *b |= 0x3C;
    }
    f.torn.push(at);
    f.mem[at..at + WORD] != before[..]
}

/// Tears the double word at `at` of `f` with every data bit right and its ECC bits not.
fn tear_ecc_only(f: &mut CutFlash, at: usize) {
    f.torn.push(at - at % WORD);
}

/// Slot A holds table 1 (sequence 1), slot B table 2 (sequence 2, the newer).
fn two_saves() -> CutFlash {
    let mut s =
        ParamStore::new(CutFlash::blank(2 * SLOT_PAGES), 0, SLOT as u32, SLOT as u32).unwrap();
    for k in [1.0, 2.0] {
        s.save(&table(k), comp_record::source(&Table::ZERO))
            .unwrap();
    }
    s.into_inner()
}

type Checked = EccChecked<CutFlash, Box<dyn Fn() -> u32>>;

/// The store as the board opens it: reads checked against the NMI's count.
fn checked(flash: CutFlash) -> ParamStore<Checked> {
    let count = flash.ecc_errors.clone();
    let f = EccChecked::new(flash, Box::new(move || count.get()) as Box<dyn Fn() -> u32>);
    ParamStore::new(f, 0, SLOT as u32, SLOT as u32).unwrap()
}

/// The store reading the flash without the count (what the CRC alone decides).
fn unchecked(flash: CutFlash) -> ParamStore<CutFlash> {
    ParamStore::new(flash, 0, SLOT as u32, SLOT as u32).unwrap()
}

/// Where a value of the record starts: after the 16-byte header.
fn value_at(slot: usize, k: usize) -> usize {
    slot + 16 + 4 * k
}

#[test]
fn a_torn_double_word_in_the_newer_record_loads_the_other_copy() {
    let mut f = two_saves();
    assert!(tear(&mut f, value_at(SLOT, 1)));
    let errors = f.ecc_errors.clone();
    // The CRC alone refuses it.
    assert_eq!(
        unchecked(f).load(),
        (Some(table(1.0)), LoadOutcome::Loaded { sequence: 1 })
    );
    assert!(errors.get() > 0, "the read of the torn word raised the NMI");
    // And as the board reads it, with the ECC errors counted: the same.
    let mut f = two_saves();
    tear(&mut f, value_at(SLOT, 1));
    let mut s = checked(f);
    let (cfg, outcome) = boot_config(&mut s, &Config::nominal());
    assert_eq!(outcome, BootOutcome::Stored { sequence: 1 });
    assert_eq!(parameters::snapshot(&cfg), table(1.0));
}

#[test]
fn a_torn_word_whose_data_reads_right_is_refused_by_its_ecc_error() {
    // The data bits completed, the ECC bits did not: the CRC passes, the NMI does not.
    let torn = || {
        let mut f = two_saves();
        tear_ecc_only(&mut f, value_at(SLOT, 3));
        f
    };
    assert_eq!(
        unchecked(torn()).load().1,
        LoadOutcome::Loaded { sequence: 2 }
    );
    assert_eq!(
        checked(torn()).load(),
        (Some(table(1.0)), LoadOutcome::Loaded { sequence: 1 })
    );
}

#[test]
fn a_torn_commit_word_or_header_loads_the_other_copy() {
    // The commit word, the magic, the sequence number, the CRC.
    for at in [COMMIT_AT, 0, 8, CRC_AT] {
        let mut f = two_saves();
        assert!(tear(&mut f, SLOT + at), "{at}");
        assert_eq!(
            checked(f).load(),
            (Some(table(1.0)), LoadOutcome::Loaded { sequence: 1 }),
            "torn at {at}"
        );
    }
}

#[test]
fn torn_words_in_both_copies_boot_the_defaults_with_fault_16() {
    let mut f = two_saves();
    tear(&mut f, value_at(0, 1));
    tear(&mut f, value_at(SLOT, 2));
    let mut s = checked(f);
    let (cfg, outcome) = boot_config(&mut s, &Config::nominal());
    assert_eq!(cfg, Config::nominal());
    assert_eq!(
        outcome,
        BootOutcome::DefaultsAfterInvalid(LoadOutcome::Corrupt)
    );
    assert!(outcome.is_fault());
}

#[test]
fn a_torn_word_in_the_feed_forward_table_refuses_the_table_alone() {
    let mut f = two_saves();
    tear_ecc_only(&mut f, SLOT + TABLE_AT + 64);
    let mut s = checked(f);
    assert_eq!(
        s.load(),
        (Some(table(2.0)), LoadOutcome::Loaded { sequence: 2 })
    );
    let mut t = Table::ZERO;
    assert!(comp_record::read(TABLE_LEN, |at, buf| s.read_table(at, buf), &mut t).is_err());
}

#[test]
fn a_save_after_a_torn_newer_copy_overwrites_it() {
    // The torn copy counts as corrupt: the next save erases and rewrites it, keeping the
    // intact older one until the new one is committed.
    let mut f = two_saves();
    tear(&mut f, value_at(SLOT, 0));
    let mut s = checked(f);
    assert_eq!(
        s.save(&table(3.0), comp_record::source(&Table::ZERO)),
        Ok(2)
    );
    assert_eq!(
        s.load(),
        (Some(table(3.0)), LoadOutcome::Loaded { sequence: 2 })
    );
    assert_eq!(s.into_inner().into_inner().torn, Vec::<usize>::new());
}
