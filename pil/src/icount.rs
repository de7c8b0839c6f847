//! Instruction counts from SysTick under `qemu-system-arm -icount shift=0`.
//!
//! With `shift=0` QEMU advances virtual time by 1 ns per executed instruction, and the
//! mps2-an386's SysTick counts the 25 MHz system clock in virtual time: one tick is 40
//! instructions. A single bracket therefore resolves 40 instructions, but the bracket's
//! start falls at an arbitrary phase of the tick (the plant's work between calls varies),
//! so the mean over many calls converges on the mean instruction count. The bracket's own
//! cost (two SysTick reads and the optimisation barriers) is measured on an empty body
//! and subtracted, and the tick-to-instruction ratio is checked on a loop of known length.

use core::hint::black_box;
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;

/// Instructions per SysTick tick: 1 ns per instruction over a 25 MHz clock.
pub const INSTRUCTIONS_PER_TICK: u32 = 40;

/// SysTick is a 24-bit down counter.
const MASK: u32 = 0x00FF_FFFF;

/// Starts SysTick free-running on the core clock over its whole 24-bit range, no interrupt.
pub fn start(syst: &mut SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(MASK);
    syst.clear_current();
    syst.disable_interrupt();
    syst.enable_counter();
}

/// Ticks and calls of one measured operation.
#[derive(Clone, Copy, Default)]
pub struct Tally {
    ticks: u64,
    calls: u64,
}

impl Tally {
    /// Runs `f(input)` between two SysTick reads and adds the ticks. `input` and the result
    /// pass through [`black_box`], so the work (including loads through references in
    /// `input`) cannot move out of the bracket.
    #[inline(always)]
    pub fn measure<T, R>(&mut self, input: T, f: impl FnOnce(T) -> R) -> R {
        let t0 = SYST::get_current();
        let r = black_box(f(black_box(input)));
        let t1 = SYST::get_current();
        // Down counter: elapsed = start − end, modulo the 24-bit range (a bracket is far
        // shorter than one 0.67 s period).
        self.ticks += (t0.wrapping_sub(t1) & MASK) as u64;
        self.calls += 1;
        r
    }

    /// Number of calls measured.
    pub fn calls(&self) -> u64 {
        self.calls
    }

    /// Mean ticks per call.
    pub fn mean_ticks(&self) -> f64 {
        self.ticks as f64 / (self.calls.max(1)) as f64
    }

    /// Mean instructions per call, less the empty bracket's `overhead` (also a [`Tally`]).
    pub fn mean_instructions(&self, overhead: &Tally) -> f64 {
        (self.mean_ticks() - overhead.mean_ticks()) * INSTRUCTIONS_PER_TICK as f64
    }
}

/// Instructions per tick measured on a loop of known length (`subs`/`bne`, 2 instructions
/// per turn): 40 when QEMU runs with `-icount shift=0` on mps2-an386, something else when
/// it does not, which makes every count of the run meaningless.
pub fn measured_instructions_per_tick() -> f64 {
    const TURNS: u32 = 200_000;
    let mut t = Tally::default();
    t.measure(TURNS, |n| {
        // SAFETY: a register-only countdown loop; touches no memory and no flags that
        // outlive it.
        unsafe {
            core::arch::asm!(
                "2:",
                "subs {n}, {n}, #1",
                "bne 2b",
                n = inout(reg) n => _,
                options(nomem, nostack),
            );
        }
    });
    (2 * TURNS) as f64 / t.mean_ticks()
}
