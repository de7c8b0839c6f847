//! TIM1's break as the control interrupt sees it: the break flags (BIF, SBIF) and the
//! latched break sources (the phase comparators' and the gate driver's fault line's EXTI
//! pending bits), so which source broke the bridge is known even when it has gone again
//! by the time the interrupt looks (RM0440, TIM1_SR and EXTI).

use embassy_stm32::interrupt::{self, InterruptExt};
use embassy_stm32::pac;

use super::regs::PWM_REGS;

/// EXTI lines of the comparators of phases U, V, W (COMP3, COMP1, COMP4; RM0440, EXTI
/// line connections).
const COMPARATOR_EXTI_LINES: [usize; 3] = [29, 21, 30];
/// EXTI line of the gate driver's fault line (PB12: line 12, port B selected in
/// SYSCFG_EXTICR4).
const FAULT_LINE_EXTI: usize = 12;
/// SYSCFG_EXTICR port code of GPIOB.
const EXTI_PORT_B: u8 = 1;

/// TIM1's break flags: `Some(system)` when a break has fired since they were cleared
/// (TIM1_SR.BIF: break input, comparators, software; SBIF, `system`: core lockup or flash
/// ECC error), `None` otherwise.
#[inline]
pub fn break_flags() -> Option<bool> {
    let sr = PWM_REGS.sr().read();
    (sr.bif(0) || sr.sbif()).then_some(sr.sbif())
}

/// Clears TIM1's break flags BIF and SBIF. TIM1_SR's flags are cleared by writing 0 and
/// kept by writing 1 (rc_w0), so every other flag is written 1: a read-modify-write would
/// clear a flag the hardware set between its read and its write.
#[inline]
pub fn clear_break_flags() {
    let mut keep = pac::timer::regs::SrAdv(0);
    keep.set_uif(true);
    for n in 0..4 {
        keep.set_ccif(n, true);
        keep.set_ccof(n, true);
    }
    keep.set_comif(true);
    keep.set_tif(true);
    keep.set_bif(1, true);
    keep.set_ccif5(true);
    keep.set_ccif6(true);
    keep.set_idxif(true);
    keep.set_dirif(true);
    keep.set_ierrif(true);
    keep.set_terrif(true);
    PWM_REGS.sr().write_value(keep);
}

/// Latches the break sources that may be gone by the time the control interrupt looks:
/// the comparators' outputs rising (EXTI rising-edge triggers on their lines) and the
/// gate driver's fault line falling (PB12 on EXTI line 12, falling edge). The lines are
/// unmasked so the pending bits are set; their interrupts stay disabled in the NVIC.
pub(super) fn latch_break_sources() {
    // The comparators' interrupt (enabled by their driver) is not used: its handler would
    // mask the EXTI lines that latch the break sources. Off before the lines are unmasked.
    interrupt::COMP1_2_3.disable();
    interrupt::COMP4_5_6.disable();
    // SYSCFG_EXTICR4 selects the port of lines 12‥15; line 12 is its first field.
    pac::SYSCFG
        .exticr(3)
        .modify(|w| w.set_exti(FAULT_LINE_EXTI - 12, EXTI_PORT_B));
    pac::EXTI.rtsr(0).modify(|w| {
        for line in COMPARATOR_EXTI_LINES {
            w.set_line(line, true);
        }
    });
    pac::EXTI
        .ftsr(0)
        .modify(|w| w.set_line(FAULT_LINE_EXTI, true));
    pac::EXTI.imr(0).modify(|w| {
        for line in COMPARATOR_EXTI_LINES {
            w.set_line(line, true);
        }
        w.set_line(FAULT_LINE_EXTI, true);
    });
    clear_break_latches();
}

/// Clears the latched break sources (EXTI_PR1 is cleared by writing 1 to a line's bit).
pub fn clear_break_latches() {
    pac::EXTI.pr(0).write(|w| {
        for line in COMPARATOR_EXTI_LINES {
            w.set_line(line, true);
        }
        w.set_line(FAULT_LINE_EXTI, true);
    });
}

/// What broke the bridge, latched or still active: bit 0‥2 the comparators of phases
/// U, V, W, bit 3 the gate driver's fault line, bit 4 a system break (`system`: core lockup
/// or flash ECC error), bit 5 a non-maskable interrupt (`nmi`). None of them: a break
/// forced by software (a stalled loop).
pub fn break_sources(system: bool, nmi: bool) -> u8 {
    let pending = pac::EXTI.pr(0).read();
    let comparators = [pac::COMP3, pac::COMP1, pac::COMP4];
    let mut bits = 0u8;
    for (k, (c, line)) in comparators.iter().zip(COMPARATOR_EXTI_LINES).enumerate() {
        if pending.line(line) || c.csr().read().value() {
            bits |= 1 << k;
        }
    }
    if pending.line(FAULT_LINE_EXTI) || pac::GPIOB.idr().read().idr(12) == pac::gpio::vals::Idr::LOW
    {
        bits |= 1 << 3;
    }
    if system {
        bits |= 1 << 4;
    }
    if nmi {
        bits |= 1 << 5;
    }
    bits
}
