//! The parameter table in the G474's flash: two slots at the end of bank 2, opened at boot
//! and written by the `SaveParameters` command through [`firmware::param_store`].
//!
//! # Geometry
//!
//! The part runs dual-bank (option bit DBANK set, as it ships): two 256 KiB banks of
//! 2 KiB pages. The program is linked into bank 1 only (`memory.x`); the store's slots
//! are the last [`SLOT_BYTES`] × 2 of bank 2. [`SLOT_BYTES`] is the one number to change
//! when the stored record grows (a compensation table of a few KiB): a whole number of
//! pages per slot, the slots move down from the end of bank 2, nothing else in the image
//! or the linker script changes (the compile-time checks below hold the layout to that).
//! A part with DBANK cleared (single bank, 4 KiB pages) would have the driver erase the
//! wrong pages: [`super::board::init`] leaves the flash unopened there and the drive runs
//! on its defaults with fault 18 (`docs/bring-up.md` says how to set the bit).
//!
//! # Saving while the loop runs
//!
//! Erasing or programming bank 2 does not stall instruction fetches from bank 1 (the G4
//! reads one bank while it writes the other), so the current-loop interrupt keeps running
//! through a save. The CAN task that saves is blocked for the erase of the slot's two pages
//! (about 22 ms each, datasheet at most 24.5 ms) and the programming, about 50 ms in all,
//! and so is the rest of the thread-mode executor — the supervision task included. Around
//! the flash operations this module therefore stretches the independent watchdog's reload
//! to its longest (about 0.5 s) and restores it after: the 20 ms timeout is shorter than
//! one erase. The supervision task needs nothing: it judges the loop by the time that has
//! actually elapsed between its checks ([`firmware::liveness`]), so its first check after
//! the save sees 50 ms of interrupts and the ones its timer fires late, back to back, are
//! too close together to be judged.
//!
//! Saving is still allowed in Disabled only ([`firmware::can_server::serve`]): the
//! command timeout and the CAN replies wait for the erase.
//!
//! # A save cut by a power loss
//!
//! The store's A/B slots and commit word keep the previous table through a cut at any
//! point ([`firmware::param_store`]). A double word whose programming was cut can hold
//! data and ECC bits that disagree: reading it at the next boot raises an uncorrectable
//! ECC error, an NMI, which [`super::safe_state`] counts and clears. The store reads
//! through [`EccChecked`], so such a read fails and that copy is refused like a corrupt
//! one (its CRC would refuse it too): the other copy loads, or the defaults with fault 16.

use embassy_stm32::flash::{Blocking, Flash, FLASH_SIZE, MAX_ERASE_SIZE};
use embassy_stm32::pac;
use embassy_stm32::pac::iwdg::vals::Key;
use firmware::compensation::record::Encoder;
use firmware::param_store::ecc::{CheckedError, EccChecked};
use firmware::param_store::{ParamStore, StoreError, SPAN};
use firmware::parameters::COUNT;

use super::safe_state;

/// The G474 flash, its reads checked for uncorrectable ECC errors.
pub type CheckedFlash = EccChecked<Flash<'static, Blocking>, fn() -> u32>;
/// The store on the G474 flash.
pub type Store = ParamStore<CheckedFlash>;
/// Why a store operation failed.
pub type Error = StoreError<CheckedError<embassy_stm32::flash::Error>>;

/// Erase page of bank 2 in dual-bank mode. [bytes]
pub const PAGE_BYTES: u32 = MAX_ERASE_SIZE as u32;
/// One slot (A or B) of the stored record: a whole number of [`PAGE_BYTES`]. Two pages
/// hold the record ([`SPAN`] bytes: the live table with header and CRC, the torque
/// feed-forward's table record, the commit word); grow it in whole pages when the record
/// grows. [bytes]
pub const SLOT_BYTES: u32 = 2 * PAGE_BYTES;
/// Offset of bank 2 from the flash start. [bytes]
pub const BANK2: u32 = (FLASH_SIZE / 2) as u32;
/// Offset of slot B (the last slot of bank 2) from the flash start. [bytes]
pub const SLOT_B: u32 = FLASH_SIZE as u32 - SLOT_BYTES;
/// Offset of slot A (right below slot B) from the flash start. [bytes]
pub const SLOT_A: u32 = SLOT_B - SLOT_BYTES;

const _: () = assert!(SLOT_BYTES % PAGE_BYTES == 0, "a slot is whole pages");
const _: () = assert!(SPAN as u32 <= SLOT_BYTES, "the record fits its slot");
const _: () = assert!(
    SLOT_A >= BANK2,
    "the store stays in bank 2, clear of the program"
);

/// Longest IWDG reload value (12-bit counter).
const IWDG_RELOAD_MAX: u16 = 0x0FFF;

/// Opens the store on its two slots.
pub fn open(flash: Flash<'static, Blocking>) -> Result<Store, Error> {
    let checked: CheckedFlash = EccChecked::new(flash, safe_state::ecc_errors);
    ParamStore::new(checked, SLOT_A, SLOT_B, SLOT_BYTES)
}

/// Saves `values` and the controller's torque feed-forward table with the watchdog
/// stretched; returns the record's sequence number. Call only with the bridge disabled.
/// The table's record is copied out of the controller 48 bytes at a time, each copy a
/// short critical section, never across a flash operation.
pub fn save(store: &mut Store, values: &[f32; COUNT]) -> Result<u32, Error> {
    let reload = set_watchdog_reload(IWDG_RELOAD_MAX);
    let mut encoder = Encoder::new();
    let result = store.save(values, |buf| {
        super::control::with_controller(|c| {
            encoder.next(c.compensation().table()).map(|(at, bytes)| {
                buf[..bytes.len()].copy_from_slice(bytes);
                (at, bytes.len())
            })
        })
        .flatten()
    });
    set_watchdog_reload(reload);
    result
}

/// Sets the IWDG reload value (prescaler unchanged) and reloads the counter with it;
/// returns the previous value. The driver owned by the supervision task only ever writes
/// the reload key, which this leaves working.
fn set_watchdog_reload(reload: u16) -> u16 {
    let iwdg = pac::IWDG;
    let previous = iwdg.rlr().read().rl();
    iwdg.kr().write(|w| w.set_key(Key::ENABLE));
    iwdg.rlr().write(|w| w.set_rl(reload));
    // The new value reaches the watchdog's clock domain a few LSI cycles later (~125 µs);
    // bounded (about 10 ms at 170 MHz) so a stopped LSI cannot hang the save.
    for _ in 0..1_000_000u32 {
        if !iwdg.sr().read().rvu() {
            break;
        }
    }
    iwdg.kr().write(|w| w.set_key(Key::RESET));
    previous
}
