//! White Gaussian noise for the sensors: standard normal deviates by Marsaglia's polar method
//! on a xoshiro256++ stream, drawn a block at a time.
//!
//! The polar method takes two uniforms u, v on (−1, 1), keeps them when s = u² + v² lies in
//! (0, 1) and returns the pair u·f, v·f with f = √(−2·ln s / s). Drawing [`BLOCK`] deviates
//! at once gives the same sequence as drawing them one by one (the first of each pair, then
//! the second), but takes the pairs' logarithms, divisions and square roots side by side,
//! two pairs to an instruction, instead of one chain after another on the sensors' critical
//! path every PWM period. The logarithm is `libm`'s algorithm, bit for bit, without the
//! branches a polar pair never takes.

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

    /// Draws the next [`BLOCK`] deviates: first the accepted pairs of uniforms in the
    /// stream's order, then their factors, lane by lane so the compiler can take them two
    /// or four at a time.
    #[inline(never)]
    fn refill(&mut self) {
        let mut u = [0.0; PAIRS];
        let mut v = [0.0; PAIRS];
        let mut s = [0.5; PAIRS];
        let mut n = 0;
        while n < PAIRS {
            let a = 2.0 * unit(self.rng.next_u64()) - 1.0;
            let b = 2.0 * unit(self.rng.next_u64()) - 1.0;
            let r = a * a + b * b;
            // Written unconditionally and kept by advancing the count: no branch on the
            // acceptance, which rejects a fifth of the candidates at random.
            u[n] = a;
            v[n] = b;
            s[n] = r;
            n += usize::from(r > 0.0 && r < 1.0);
        }
        let mut f = [0.0; PAIRS];
        for (f, &s) in f.iter_mut().zip(&s) {
            *f = -2.0 * ln_open_unit(s) / s;
        }
        // Apart: libm's square root is the processor's instruction through an intrinsic,
        // which the vectoriser does not take.
        for f in &mut f {
            *f = libm::sqrt(*f);
        }
        for (k, pair) in self.block.chunks_exact_mut(2).enumerate() {
            pair[0] = u[k] * f[k];
            pair[1] = v[k] * f[k];
        }
        self.next = 0;
    }
}

/// Pairs per refill.
const PAIRS: usize = BLOCK / 2;

/// ln s for s in (2⁻¹⁰²², 1), bit for bit the value of `libm::log`.
///
/// It is the straight path of that function's algorithm (FreeBSD's `e_log.c`): s written as
/// 2ᵏ·(1 + f) with 1 + f in [√2/2, √2), then ln(1 + f) from the series in t = f/(2 + f)
/// with Remez coefficients Lg1…Lg7 and k·ln 2 in two parts. The branches `libm::log` takes
/// for zero, negative, subnormal, infinite and unit arguments are left out: a polar pair's
/// s is a sum of squares of multiples of 2⁻⁵³ below one, so it never takes them. Without
/// them the function is plain arithmetic, which the compiler computes for several pairs in
/// one instruction; the operations and their order are `libm`'s, so are the roundings.
///
/// The algorithm and its constants: Copyright (C) 1993 by Sun Microsystems, Inc. All
/// rights reserved. Developed at SunSoft, a Sun Microsystems, Inc. business. Permission to
/// use, copy, modify, and distribute this software is freely granted, provided that this
/// notice is preserved.
#[inline(always)]
fn ln_open_unit(s: f64) -> f64 {
    const LN2_HI: f64 = f64::from_bits(0x3fe62e42_fee00000); // 6.93147180369123816490e-01
    const LN2_LO: f64 = f64::from_bits(0x3dea39ef_35793c76); // 1.90821492927058770002e-10
    const LG1: f64 = f64::from_bits(0x3fe55555_55555593); // 6.666666666666735130e-01
    const LG2: f64 = f64::from_bits(0x3fd99999_9997fa04); // 3.999999999940941908e-01
    const LG3: f64 = f64::from_bits(0x3fd24924_94229359); // 2.857142874366239149e-01
    const LG4: f64 = f64::from_bits(0x3fcc71c5_1d8e78af); // 2.222219843214978396e-01
    const LG5: f64 = f64::from_bits(0x3fc74664_96cb03de); // 1.818357216161805012e-01
    const LG6: f64 = f64::from_bits(0x3fc39a09_d078c69f); // 1.531383769920937332e-01
    const LG7: f64 = f64::from_bits(0x3fc2f112_df3e5244); // 1.479819860511658591e-01

    // s = 2ᵏ·x with x in [√2/2, √2): the exponent field moved so that a mantissa above √2/2
    // carries into it, then the mantissa put back under x's exponent.
    let moved = s.to_bits() + ((0x3ff0_0000 - 0x3fe6_a09e) << 32);
    let x = f64::from_bits((moved & 0x000f_ffff_ffff_ffff) + (0x3fe6_a09e << 32));
    // k = biased exponent − 1023, exactly, from the float 2⁵² + biased exponent (no integer
    // to float conversion, which two-lane SSE2 lacks for 64-bit lanes).
    let dk =
        f64::from_bits(0x4330_0000_0000_0000 | (moved >> 52)) - (4_503_599_627_370_496.0 + 1023.0);
    let f = x - 1.0;
    let hfsq = 0.5 * f * f;
    let t = f / (2.0 + f);
    let z = t * t;
    let w = z * z;
    let t1 = w * (LG2 + w * (LG4 + w * LG6));
    let t2 = z * (LG1 + w * (LG3 + w * (LG5 + w * LG7)));
    let r = t2 + t1;
    t * (hfsq + r) + dk * LN2_LO - hfsq + f + dk * LN2_HI
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
    fn the_open_unit_logarithm_is_libms_bit_for_bit() {
        // The ends a polar pair's s can reach (the least sum of squares of multiples of
        // 2⁻⁵³, the greatest below one), the reduction's boundary at √2/2, powers of two,
        // and a million values spread over every binade between.
        let ends = [
            f64::from_bits(0x3950_0000_0000_0000), // 2⁻¹⁰⁶
            1.0 - f64::EPSILON / 2.0,
            core::f64::consts::FRAC_1_SQRT_2,
            f64::from_bits(core::f64::consts::FRAC_1_SQRT_2.to_bits() + 1),
            f64::from_bits(core::f64::consts::FRAC_1_SQRT_2.to_bits() - 1),
            0.5,
            0.25,
            f64::MIN_POSITIVE,
        ];
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        let spread = (0..1_000_000).map(|_| {
            // A uniform mantissa in a uniform binade from 2⁻¹⁰⁶ to 2⁻¹.
            let m = rng.next_u64() >> 12;
            let e = 0x3fe - (rng.next_u64() % 106);
            f64::from_bits((e << 52) | m)
        });
        for s in ends.into_iter().chain(spread) {
            assert!(s > 0.0 && s < 1.0);
            assert_eq!(
                ln_open_unit(s).to_bits(),
                libm::log(s).to_bits(),
                "s = {s:e}"
            );
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
