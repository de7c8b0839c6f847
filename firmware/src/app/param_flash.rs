//! The parameter table in the G474's flash: the last two erase pages of the bank (4 KiB
//! each in single-bank mode, outside the program: `memory.x` gives the linker 8 KiB less
//! than the part has), opened at boot and written by the `SaveParameters` command through
//! [`firmware::param_store`].
//!
//! A page erase stalls every instruction fetch from the (single) bank for about 22 ms
//! (datasheet: 24.5 ms at most), the current-loop interrupt and the executor included.
//! Saving is therefore allowed in Disabled only (checked by
//! [`firmware::can_server::serve`]), and around the flash operations this module
//!
//! - masks the current-loop interrupt, so the loop resumes cleanly afterwards instead of
//!   running once, late, on a stale sample (its overrun check would latch the watchdog
//!   fault);
//! - stretches the independent watchdog's reload to its longest (about 0.5 s) and restores
//!   it after: the 20 ms timeout is shorter than one erase;
//! - counts a maintenance window ([`maintenance_windows`]), so the supervision task does
//!   not take the missing interrupts for a stalled loop.

use core::sync::atomic::{AtomicU32, Ordering};

use embassy_stm32::flash::{Blocking, Flash, FLASH_SIZE, MAX_ERASE_SIZE};
use embassy_stm32::interrupt::{self, InterruptExt};
use embassy_stm32::pac;
use embassy_stm32::pac::iwdg::vals::Key;
use firmware::param_store::{ParamStore, StoreError};
use firmware::parameters::COUNT;

/// The store on the G474 flash.
pub type Store = ParamStore<Flash<'static, Blocking>>;

/// Offset of page A (second-to-last erase page) from the flash start. [bytes]
pub const PAGE_A: u32 = (FLASH_SIZE - 2 * MAX_ERASE_SIZE) as u32;
/// Offset of page B (last erase page) from the flash start. [bytes]
pub const PAGE_B: u32 = (FLASH_SIZE - MAX_ERASE_SIZE) as u32;

/// Longest IWDG reload value (12-bit counter).
const IWDG_RELOAD_MAX: u16 = 0x0FFF;

static MAINTENANCE: AtomicU32 = AtomicU32::new(0);

/// Number of flash maintenance windows so far (wraps); the supervision task skips its
/// liveness verdict when this moved.
pub fn maintenance_windows() -> u32 {
    MAINTENANCE.load(Ordering::Relaxed)
}

/// Opens the store on the last two pages.
pub fn open(
    flash: Flash<'static, Blocking>,
) -> Result<Store, StoreError<embassy_stm32::flash::Error>> {
    ParamStore::new(flash, PAGE_A, PAGE_B, MAX_ERASE_SIZE as u32)
}

/// Saves `values` with the current loop masked and the watchdog stretched; returns the
/// record's sequence number. Call only with the bridge disabled.
pub fn save(
    store: &mut Store,
    values: &[f32; COUNT],
) -> Result<u32, StoreError<embassy_stm32::flash::Error>> {
    MAINTENANCE.fetch_add(1, Ordering::Relaxed);
    interrupt::ADC1_2.disable();
    let reload = set_watchdog_reload(IWDG_RELOAD_MAX);
    let result = store.save(values);
    set_watchdog_reload(reload);
    interrupt::ADC1_2.unpend();
    // SAFETY: re-enables the handler that was enabled before this call; it only touches
    // state behind a critical-section mutex.
    unsafe { interrupt::ADC1_2.enable() };
    MAINTENANCE.fetch_add(1, Ordering::Relaxed);
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
