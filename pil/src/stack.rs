//! The stack of the PIL run, measured as the firmware measures its own
//! ([`firmware::stack`]): the runtime paints the stack region at reset (cortex-m-rt's
//! `paint-stack`; with flip-link the region is the RAM below the static data) and the
//! deepest word no longer paint is the high-water mark. [`depth`] measures one call alone:
//! it paints the free stack below the caller again, runs the call and scans the paint; the
//! run's high-water mark is taken before each such repaint, so none is lost.

use core::hint::black_box;
use core::sync::atomic::{AtomicU32, Ordering};
use firmware::stack::{StackUse, PAINT};

// The runtime paints the stack with the value the scans look for.
const _: () = assert!(cortex_m_rt::STACK_PAINT_VALUE == PAINT);

/// Free stack painted below the caller for one [`depth`] bracket. [bytes]
const WINDOW_BYTES: usize = 64 * 1024;

/// The run's high-water mark as scanned before the last repaint. [bytes]
static PEAK_BEFORE_REPAINT: AtomicU32 = AtomicU32::new(0);

extern "C" {
    static _stack_end: u32;
    static _stack_start: u32;
}

/// The bottom (lowest address) and top of the painted stack region.
fn region() -> (usize, usize) {
    (
        core::ptr::addr_of!(_stack_end) as usize,
        core::ptr::addr_of!(_stack_start) as usize,
    )
}

/// The high-water mark of the whole run so far.
pub fn whole_run() -> StackUse {
    let (bottom, top) = region();
    let base = bottom as *const u32;
    // SAFETY: the region is RAM the runtime painted; the words read lie below the deepest
    // frame or are read volatile and never referenced.
    let now = StackUse::measure((top - bottom) / 4, |k| unsafe {
        core::ptr::read_volatile(base.add(k))
    });
    StackUse {
        peak_bytes: now
            .peak_bytes
            .max(PEAK_BEFORE_REPAINT.load(Ordering::Relaxed)),
        ..now
    }
}

/// Paints the free stack below the caller again and forgets the high-water mark so far:
/// the run's mark counts from here.
#[inline(never)]
pub fn restart() {
    let (bottom, _) = region();
    let start = (cortex_m::register::msp::read() as usize - 64) & !3;
    paint(bottom, start);
    PEAK_BEFORE_REPAINT.store(0, Ordering::Relaxed);
}

/// Paints the words from `from` up to `to`.
fn paint(from: usize, to: usize) {
    let base = from as *mut u32;
    for k in 0..(to - from) / 4 {
        // SAFETY: free stack below the caller's frame and above the region's bottom;
        // nothing refers to it.
        unsafe { core::ptr::write_volatile(base.add(k), PAINT) };
    }
}

/// Calls `f` in a frame of its own, below the caller's stack pointer (what the compiler
/// inlines of `f` lands in this frame, never in the caller's).
#[inline(never)]
fn below<R>(f: impl FnOnce() -> R) -> R {
    f()
}

/// Runs `f` and returns its result with the stack it used below the caller's frame.
/// [bytes]
#[inline(never)]
pub fn depth<R>(f: impl FnOnce() -> R) -> (R, u32) {
    PEAK_BEFORE_REPAINT.store(whole_run().peak_bytes, Ordering::Relaxed);
    let (bottom, _) = region();
    let sp = cortex_m::register::msp::read() as usize;
    // Leave 64 bytes below the stack pointer for this function's own calls.
    let start = (sp - 64) & !3;
    let end = start.saturating_sub(WINDOW_BYTES).max(bottom);
    let words = (start - end) / 4;
    let base = end as *const u32;
    paint(end, start);
    let r = black_box(below(f));
    let used = StackUse::measure(words, |k| unsafe { core::ptr::read_volatile(base.add(k)) });
    (r, used.peak_bytes + (sp - start) as u32)
}
