//! The stack's high-water mark: how deep the stack has ever reached, found from paint.
//!
//! At reset, before `main`, the runtime fills the whole stack region with one word
//! ([`PAINT`]; cortex-m-rt's `paint-stack`). The stack grows down from the region's top,
//! and every word it reaches is overwritten (a call pushes its return address and saved
//! registers at the lowest addresses of its frame). So the deepest point ever reached is
//! just above the region's lowest word that is no longer paint, found by scanning up from
//! the bottom. The scan costs one read per unused word; it can underestimate only where a
//! frame's lowest word held exactly the paint value, or a frame reserved memory it never
//! wrote.
//!
//! With `flip-link` the region is the RAM below the static data: the stack ends at the
//! start of RAM, so growing past it faults instead of overwriting the statics.

/// The word the stack is painted with (cortex-m-rt's `STACK_PAINT_VALUE`).
pub const PAINT: u32 = 0xCCCC_CCCC;

/// How much of the stack region has been used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StackUse {
    /// The deepest the stack has reached, from the region's top. [bytes]
    pub peak_bytes: u32,
    /// The region's size. [bytes]
    pub size_bytes: u32,
}

impl StackUse {
    /// Scans a painted region of `words` words, `read(k)` giving word `k` counted from the
    /// region's bottom (lowest address).
    pub fn measure(words: usize, mut read: impl FnMut(usize) -> u32) -> StackUse {
        let untouched = (0..words).take_while(|k| read(*k) == PAINT).count();
        StackUse {
            peak_bytes: (4 * (words - untouched)) as u32,
            size_bytes: (4 * words) as u32,
        }
    }

    /// How many times the peak fits in the region (size / peak; infinite before any use).
    pub fn margin(&self) -> f32 {
        self.size_bytes as f32 / self.peak_bytes as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_peak_is_the_lowest_word_no_longer_paint() {
        // A 1 KiB region whose top 300 bytes were used; in between, a frame left some words
        // unwritten (paint inside the used part does not shorten the peak).
        let mut region = [PAINT; 256];
        for w in region[181..].iter_mut() {
            *w = 0x2000_1234;
        }
        region[200] = PAINT;
        let u = StackUse::measure(region.len(), |k| region[k]);
        assert_eq!(
            u,
            StackUse {
                peak_bytes: 300,
                size_bytes: 1024
            }
        );
        assert!((u.margin() - 1024.0 / 300.0).abs() < 1e-6);
        // Untouched, and overflowing to the very bottom.
        assert_eq!(StackUse::measure(256, |_| PAINT).peak_bytes, 0);
        assert!(StackUse::measure(256, |_| PAINT).margin().is_infinite());
        assert_eq!(StackUse::measure(256, |_| 0).peak_bytes, 1024);
    }
}
