//! The bridge's safe state whatever the software does: all six switches off.
//!
//! - A break ([`force_break`]): TIM1's break-generation bit clears MOE in hardware, the
//!   outputs go to their idle level (off, `board`), and the break flag tells the control
//!   interrupt, which latches fault 17 if it ever runs again. AOE is off, so only software
//!   sets MOE again. Used by the panic handler, the HardFault handler and the supervision
//!   task when the current loop stalls.
//! - A debug halt ([`freeze_in_debug_halt`]): DBGMCU stops TIM1 with the core, and an
//!   advanced timer stopped in debug disables its outputs as if MOE were cleared; the
//!   independent watchdog stops too, so a breakpoint does not end in a reset.
//! - A panic: no message is formatted (core::fmt would cost flash); the break comes first,
//!   then a `udf` turns it into a HardFault, where probe-rs stops and prints the backtrace
//!   (what panic-probe does, which this replaces because it has no hook for the break).
//! - A HardFault: the break, then the core waits for the independent watchdog (≤ 20 ms)
//!   to reset it. A fault that locks the core up before its handler runs leaves TIM1
//!   switching with the last duties until that reset — the one case the watchdog's
//!   timeout bounds alone.

use core::panic::PanicInfo;

use cortex_m_rt::{exception, ExceptionFrame};
use embassy_stm32::pac;

use super::board::PWM_REGS;

/// Clears MOE through TIM1's break generation (EGR.BG): the bridge is off within a few
/// timer clocks. Safe from any context, interrupts masked or not.
#[inline(always)]
pub fn force_break() {
    PWM_REGS.egr().write(|w| w.set_bg(0, true));
}

/// Stops TIM1 (outputs disabled) and the independent watchdog while the core is halted by
/// a debugger.
pub fn freeze_in_debug_halt() {
    pac::DBGMCU.apb2fzr().modify(|w| w.set_tim1(true));
    pac::DBGMCU.apb1lfzr().modify(|w| w.set_iwdg(true));
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
