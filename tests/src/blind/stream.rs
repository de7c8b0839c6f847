//! The generator's own stream of deviates (xoshiro256++): uniform, within a tolerance, a
//! pick among items, a sign. Every draw of the blind suite comes from one such stream per
//! seed, so a seed fixes the log it makes.

use rand_core::{RngCore, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Relative tolerance of every perturbed rig parameter: uniform in ±this. [1]
pub const TOLERANCE: f64 = 0.03;

/// Uniform deviates from the generator's own xoshiro stream.
pub(crate) struct Stream(Xoshiro256PlusPlus);

impl Stream {
    /// The stream of `seed`.
    pub(crate) fn seeded(seed: u64) -> Stream {
        Stream(Xoshiro256PlusPlus::seed_from_u64(seed))
    }

    /// The next 64 raw bits.
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// Uniform in [0, 1) from the top 53 bits.
    pub(crate) fn unit(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub(crate) fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// `x` scaled by a factor uniform in 1 ± [`TOLERANCE`].
    pub(crate) fn tolerance(&mut self, x: f64) -> f64 {
        x * self.uniform(1.0 - TOLERANCE, 1.0 + TOLERANCE)
    }

    /// One of `items`, uniformly.
    pub(crate) fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        let k = (self.unit() * items.len() as f64) as usize;
        items[k.min(items.len() - 1)]
    }

    /// +1 or −1 with equal probability.
    pub(crate) fn sign(&mut self) -> f64 {
        if self.unit() < 0.5 {
            -1.0
        } else {
            1.0
        }
    }
}
