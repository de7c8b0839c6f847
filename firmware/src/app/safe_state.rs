//! The bridge's safe state whatever the software does: all six switches off.
//!
//! - A break ([`force_break`]): TIM1's break-generation bit clears MOE in hardware, the
//!   outputs go to their idle level (off, `board`), and the break flag tells the control
//!   interrupt, which latches fault 17 if it ever runs again. AOE is off, so only software
//!   sets MOE again. Used by the panic handler, the HardFault handler, the NMI handler and
//!   the supervision task when the current loop stalls.
//! - A debug halt (set up by `board::init`): DBGMCU stops TIM1 with the core, and an
//!   advanced timer stopped in debug disables its outputs as if MOE were cleared; the
//!   independent watchdog stops too, so a breakpoint does not end in a reset; and TIM15,
//!   the executor's clock, stops, so the time the supervision task measures excludes the
//!   halt just as the loop's interrupt count does ([`firmware::liveness`]).
//! - A core lockup or an uncorrectable flash ECC error: a *system break* of TIM1 in
//!   hardware (SYSCFG_CFGR2.CLL and ECCL, set by `board::init`), so even a core that locked
//!   up before any handler ran leaves the bridge off; the watchdog then resets it.
//! - A panic: no message is formatted (core::fmt would cost flash); the break comes first,
//!   then a `udf` turns it into a HardFault, where probe-rs stops and prints the backtrace
//!   (what panic-probe does, which this replaces because it has no hook for the break).
//! - A HardFault: the break, then the core waits for the independent watchdog (≤ 20 ms)
//!   to reset it. A stack overflow is one: with `flip-link` the stack ends at the start of
//!   RAM and growing past it faults instead of overwriting the statics; if stacking the
//!   fault's own frame fails there too, the core locks up, which is a system break (CLL),
//!   and the watchdog resets it all the same.
//! - A non-maskable interrupt ([`NonMaskableInt`]): the break, then its source found and
//!   cleared. An uncorrectable (double-bit) flash ECC error — a double word left half
//!   programmed by a power loss during a parameter save — sets FLASH_ECCR.ECCD; the
//!   handler counts it ([`ecc_errors`], which the parameter store's reads check), clears
//!   ECCD (and ECCC) by writing 1 and returns, so the read that raised it completes and
//!   its record is refused. A clock-security failure (RCC_CIFR.CSSF) and an SRAM parity
//!   error (SYSCFG_CFGR2.SPF) are cleared the same way. Without a handler the default one
//!   would loop with the bridge on (at boot: forever, the watchdog not yet started).

use core::panic::PanicInfo;
use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m_rt::{exception, ExceptionFrame};
use embassy_stm32::pac;

use super::board::regs::PWM_REGS;

/// Uncorrectable flash ECC errors so far (wraps).
static ECC_ERRORS: AtomicU32 = AtomicU32::new(0);
/// FLASH_ECCR of the last of them (ADDR_ECC, BK_ECC, SYSF_ECC as the flash reported them).
static ECC_LAST: AtomicU32 = AtomicU32::new(0);
/// Non-maskable interrupts so far, of any source (wraps).
static NMIS: AtomicU32 = AtomicU32::new(0);

/// Clears MOE through TIM1's break generation (EGR.BG): the bridge is off within a few
/// timer clocks. Safe from any context, interrupts masked or not.
#[inline(always)]
pub fn force_break() {
    PWM_REGS.egr().write(|w| w.set_bg(0, true));
}

/// Uncorrectable flash ECC errors the NMI handler has counted so far (wrapping), after
/// the barriers that let an NMI pending from the last read run first.
pub fn ecc_errors() -> u32 {
    cortex_m::asm::dsb();
    cortex_m::asm::isb();
    ECC_ERRORS.load(Ordering::Acquire)
}

/// FLASH_ECCR as the last uncorrectable error left it: the failing double word's address
/// within its bank (ADDR_ECC, bits 0‥18) and the bank (BK_ECC, bit 21).
pub fn last_ecc_error() -> u32 {
    ECC_LAST.load(Ordering::Relaxed)
}

/// Non-maskable interrupts so far, of any source (wraps).
pub fn nmis() -> u32 {
    NMIS.load(Ordering::Relaxed)
}

#[exception]
unsafe fn NonMaskableInt() {
    force_break();
    NMIS.fetch_add(1, Ordering::Relaxed);
    let eccr = pac::FLASH.eccr().read();
    if eccr.eccd() {
        ECC_LAST.store(eccr.0 & 0x0067_FFFF, Ordering::Relaxed);
        ECC_ERRORS.fetch_add(1, Ordering::Release);
        // ECCD and ECCC are cleared by writing 1; the interrupt enable is kept.
        pac::FLASH.eccr().write(|w| {
            w.set_eccie(eccr.eccie());
            w.set_eccc(eccr.eccc());
            w.set_eccd(true);
        });
    }
    if pac::RCC.cifr().read().cssf() {
        pac::RCC.cicr().write(|w| w.set_cssc(true));
    }
    let cfgr2 = pac::SYSCFG.cfgr2().read();
    if cfgr2.spf() {
        // SPF is cleared by writing 1; the lock bits are set-only, writing them back as read
        // changes nothing.
        pac::SYSCFG.cfgr2().write_value(cfgr2);
    }
}

#[panic_handler]
fn panic(_info: &PanicInfo) -> ! {
    cortex_m::interrupt::disable();
    force_break();
    // A UsageFault handler is not installed; with it disabled `udf` escalates to the
    // HardFault probe-rs catches.
    // SAFETY: a read-modify-write of SCB.SHCSR with interrupts masked, on the way down.
    unsafe {
        let scb = &*cortex_m::peripheral::SCB::PTR;
        scb.shcsr.modify(|v| v & !(1 << 18));
    }
    cortex_m::asm::udf()
}

#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    force_break();
    // Nothing feeds the independent watchdog from here: it resets the MCU, and the next
    // boot reports it (fault 11).
    loop {
        cortex_m::asm::nop();
    }
}
