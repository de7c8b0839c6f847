//! White Gaussian noise for the sensors: standard normal deviates by Marsaglia's polar method
//! on a xoshiro256++ stream, drawn a block at a time.
//!
//! The polar method takes two uniforms u, v on (−1, 1), keeps them when s = u² + v² lies in
//! (0, 1) and returns the pair u·f, v·f with f = √(−2·ln s / s). Drawing [`BLOCK`] deviates
//! at once gives the same sequence as drawing them one by one (the first of each pair, then
//! the second), but lets the processor overlap the pairs' logarithms, which one by one sit
//! on the sensors' critical path every PWM period.

use rand_core::{RngCore, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Deviates drawn per refill (even: the polar method yields pairs).
const BLOCK: usize = 16;

/// A stream of standard normal deviates from a seed.
#[derive(Clone, Debug)]
pub(crate) struct NormalStream {
    rng: Xoshiro256PlusPlus,
    block: [f64; BLOCK],
    next: usize,
}

impl NormalStream {
    /// The stream of `seed`.
    pub(crate) fn new(seed: u64) -> NormalStream {
        NormalStream {
            rng: Xoshiro256PlusPlus::seed_from_u64(seed),
            block: [0.0; BLOCK],
            next: BLOCK,
        }
    }

    /// The next standard normal deviate.
    #[inline]
    pub(crate) fn next(&mut self) -> f64 {
        if self.next >= BLOCK {
            self.refill();
        }
        let z = self.block[self.next];
        self.next += 1;
        z
    }

    /// Draws the next [`BLOCK`] deviates, pair by pair.
    #[inline(never)]
    fn refill(&mut self) {
        for pair in self.block.chunks_exact_mut(2) {
            let (u, v, s) = loop {
                let u = 2.0 * unit(self.rng.next_u64()) - 1.0;
                let v = 2.0 * unit(self.rng.next_u64()) - 1.0;
                let s = u * u + v * v;
                if s > 0.0 && s < 1.0 {
                    break (u, v, s);
                }
            };
            let f = libm::sqrt(-2.0 * libm::log(s) / s);
            pair[0] = u * f;
            pair[1] = v * f;
        }
        self.next = 0;
    }
}

/// Uniform in [0, 1) from the top 53 bits.
fn unit(x: u64) -> f64 {
    (x >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Marsaglia's polar method one deviate at a time, as the textbook states it.
    fn one_by_one(seed: u64, n: usize) -> [f64; 64] {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut out = [0.0; 64];
        let mut spare = None;
        for z in out.iter_mut().take(n) {
            *z = match spare.take() {
                Some(z) => z,
                None => loop {
                    let u = 2.0 * unit(rng.next_u64()) - 1.0;
                    let v = 2.0 * unit(rng.next_u64()) - 1.0;
                    let s = u * u + v * v;
                    if s > 0.0 && s < 1.0 {
                        let f = libm::sqrt(-2.0 * libm::log(s) / s);
                        spare = Some(v * f);
                        break u * f;
                    }
                },
            };
        }
        out
    }

    #[test]
    fn blocks_give_the_one_by_one_sequence() {
        for seed in [0, 1, 42, u64::MAX] {
            let want = one_by_one(seed, 64);
            let mut stream = NormalStream::new(seed);
            for (k, w) in want.iter().enumerate() {
                assert_eq!(
                    stream.next().to_bits(),
                    w.to_bits(),
                    "seed {seed}, deviate {k}"
                );
            }
        }
    }

    #[test]
    fn deviates_have_unit_variance_and_zero_mean() {
        // 200 000 deviates: the sample mean's standard error is 0.0022, the variance's 0.0032.
        let mut stream = NormalStream::new(7);
        let n = 200_000;
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..n {
            let z = stream.next();
            sum += z;
            sum2 += z * z;
        }
        let mean = sum / n as f64;
        let var = sum2 / n as f64 - mean * mean;
        assert!(libm::fabs(mean) < 0.01, "mean {mean}");
        assert!(libm::fabs(var - 1.0) < 0.015, "variance {var}");
    }
}
