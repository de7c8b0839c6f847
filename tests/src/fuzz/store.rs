//! The stored-parameter record loader: two flash slots of arbitrary content (optionally
//! with a correct CRC and commit word, so the checks behind them are reached), booted into
//! a configuration and the torque feed-forward's table read from the loaded slot; what
//! boots is a valid configuration with an accepted table or none, and a save on top of any
//! content loads back exactly.

use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};
use firmware::compensation::record::source;
use firmware::param_store::{
    boot_config, LoadOutcome, ParamStore, COMMIT_AT, COMMIT_LEN, COMMIT_MAGIC, CRC, SPAN, TABLE_LEN,
};
use firmware::parameters::{self, COUNT};
use firmware::{Config, Controller};

/// Erase page of the RAM flash. [bytes]
const PAGE: usize = 256;
/// A slot: whole pages holding a record, the feed-forward table and the commit word.
const SLOT: usize = SPAN.div_ceil(PAGE) * PAGE;
/// Programming unit (the G4's double word). [bytes]
const WORD: usize = 8;
/// Where the record's CRC sits (the documented layout: a 16-byte header, the values).
const CRC_AT: usize = 16 + 4 * COUNT;

/// A NOR flash in RAM with the G4's rules: erase to 0xFF by page, program erased double
/// words only.
struct RamFlash(Vec<u8>);

#[derive(Debug)]
struct FlashError(NorFlashErrorKind);

impl NorFlashError for FlashError {
    fn kind(&self) -> NorFlashErrorKind {
        self.0
    }
}

impl ErrorType for RamFlash {
    type Error = FlashError;
}

impl ReadNorFlash for RamFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), FlashError> {
        let at = offset as usize;
        let src = self
            .0
            .get(at..at + bytes.len())
            .ok_or(FlashError(NorFlashErrorKind::OutOfBounds))?;
        bytes.copy_from_slice(src);
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.0.len()
    }
}

impl NorFlash for RamFlash {
    const WRITE_SIZE: usize = WORD;
    const ERASE_SIZE: usize = PAGE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), FlashError> {
        let (from, to) = (from as usize, to as usize);
        if from % PAGE != 0 || to % PAGE != 0 || to < from {
            return Err(FlashError(NorFlashErrorKind::NotAligned));
        }
        self.0
            .get_mut(from..to)
            .ok_or(FlashError(NorFlashErrorKind::OutOfBounds))?
            .fill(0xFF);
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), FlashError> {
        let at = offset as usize;
        if at % WORD != 0 || bytes.len() % WORD != 0 {
            return Err(FlashError(NorFlashErrorKind::NotAligned));
        }
        let dst = self
            .0
            .get_mut(at..at + bytes.len())
            .ok_or(FlashError(NorFlashErrorKind::OutOfBounds))?;
        if dst.iter().any(|b| *b != 0xFF) {
            return Err(FlashError(NorFlashErrorKind::Other));
        }
        dst.copy_from_slice(bytes);
        Ok(())
    }
}

/// Makes the record at `page` carry a correct CRC and commit word (for its sequence
/// number), so that what the CRC protects is what is fuzzed.
fn seal(page: &mut [u8]) {
    let crc = CRC.checksum(&page[..CRC_AT]);
    page[CRC_AT..CRC_AT + 4].copy_from_slice(&crc.to_le_bytes());
    let seq = [page[8], page[9], page[10], page[11]];
    page[COMMIT_AT..COMMIT_AT + 4].copy_from_slice(&COMMIT_MAGIC.to_le_bytes());
    page[COMMIT_AT + 4..COMMIT_AT + COMMIT_LEN].copy_from_slice(&seq);
}

/// Two slots from `data` (first byte: bit 0/1 seal slot A/B), booted, then a save of the
/// booted table on top that must load back exactly.
pub fn param_store(data: &[u8]) {
    let Some((&flags, data)) = data.split_first() else {
        return;
    };
    let mut mem = vec![0xFF; 2 * SLOT];
    for (k, chunk) in data.chunks(SPAN).take(2).enumerate() {
        let page = &mut mem[k * SLOT..k * SLOT + SPAN];
        page[..chunk.len()].copy_from_slice(chunk);
        if flags >> k & 1 == 1 {
            seal(page);
        }
    }
    let mut store =
        ParamStore::new(RamFlash(mem), 0, SLOT as u32, SLOT as u32).expect("the layout fits");
    let defaults = Config::nominal();
    let (config, outcome) = boot_config(&mut store, &defaults);
    assert!(
        config.validate().is_ok(),
        "booted an invalid configuration ({outcome:?})"
    );
    // The feed-forward table of the loaded slot: accepted within its limit, or refused
    // leaving none.
    let mut controller = Controller::new(&config);
    let read = |at: usize, buf: &mut [u8]| store.read_table(at, buf);
    match controller.load_compensation_record(TABLE_LEN, read) {
        Ok(()) => assert!(controller.compensation().amplitude_bound().is_finite()),
        Err(_) => assert!(controller.compensation().table().is_zero()),
    }
    let values = parameters::snapshot(&config);
    let sequence = store
        .save(&values, source(controller.compensation().table()))
        .expect("a save on RAM flash");
    match store.load() {
        (Some(v), LoadOutcome::Loaded { sequence: s }) => {
            assert_eq!(s, sequence);
            assert!(
                v.iter()
                    .zip(&values)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "the saved table reads back changed"
            );
        }
        other => panic!("a saved table does not load: {other:?}"),
    }
}
