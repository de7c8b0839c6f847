//! Angles on a fixed-point grid, for the tables the current-loop step interpolates: the
//! sine table of [`crate::transforms::sin_cos`] (electrical angle) and the torque
//! feed-forward of [`crate::compensation`] (mechanical angle).
//!
//! An angle in radians becomes a signed fixed-point number of 2^20 units per revolution
//! (one float multiply and one float-to-integer conversion, which saturates and maps NaN
//! to 0 on the Cortex-M4F as in Rust); a grid of 2^b bins per revolution then takes the
//! bin from the unit's upper bits and the fraction within the bin from the lower ones.
//! Two's-complement wrapping makes the revolution periodic for free, negative angles
//! included, with no floor, no division and no branch. The range is ±2048 revolutions
//! (±12 868 rad), far beyond any angle the control core forms; the conversion truncates
//! toward zero, an error below one unit (6·10⁻⁶ rad).

use core::f32::consts::TAU;

/// Fixed-point angle resolution: 2^20 units per revolution. [1]
pub const UNITS_PER_REV_LOG2: u32 = 20;

/// Fixed-point units per radian. [1/rad]
const UNITS_PER_RAD: f32 = (1u32 << UNITS_PER_REV_LOG2) as f32 / TAU;

/// Position of `theta_rad` [rad] on a grid of 2^`bits` bins per revolution (`bits` at most
/// 16): the bin (0‥2^bits − 1, the revolution wrapped) and the fraction [0, 1) of the way
/// to the next bin.
#[inline(always)]
pub fn position(theta_rad: f32, bits: u32) -> (usize, f32) {
    let units = (theta_rad * UNITS_PER_RAD) as i32 as u32;
    let shift = UNITS_PER_REV_LOG2 - bits;
    let bin = ((units >> shift) & ((1 << bits) - 1)) as usize;
    let frac = (units & ((1 << shift) - 1)) as f32 * (1.0 / (1u32 << shift) as f32);
    (bin, frac)
}

/// sin x for |x| ≤ 2π by its Taylor series in f64 (to x³⁹/39!, far below an f64 ulp after
/// the reduction to [−π, π]), evaluable at compile time: the tables are built by the
/// compiler, bit-identical on host and target.
pub const fn const_sin(x: f64) -> f64 {
    let pi = core::f64::consts::PI;
    let mut x = x;
    if x > pi {
        x -= 2.0 * pi;
    } else if x < -pi {
        x += 2.0 * pi;
    }
    let x2 = x * x;
    let mut term = x;
    let mut sum = x;
    let mut n = 1u32;
    while n < 39 {
        term = -term * x2 / ((n + 1) * (n + 2)) as f64;
        sum += term;
        n += 2;
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_wrap_a_revolution_both_ways() {
        // A quarter turn on 256 bins is bin 64 exactly.
        assert_eq!(position(TAU / 4.0, 8), (64, 0.0));
        // Half a bin past bin 10, and the same a whole turn later and earlier.
        let x = (10.5 / 256.0) * TAU;
        for turns in [-3.0f32, 0.0, 1.0, 7.0] {
            let (bin, frac) = position(x + turns * TAU, 8);
            assert_eq!(bin, 10, "{turns} turns");
            assert!((frac - 0.5).abs() < 2e-3, "{turns} turns: {frac}");
        }
        // Just below zero is the last bin, near its end.
        let (bin, frac) = position(-1e-3, 9);
        assert_eq!(bin, 511);
        assert!(frac > 0.9, "{frac}");
        // NaN lands at 0 without a panic.
        assert_eq!(position(f32::NAN, 8), (0, 0.0));
    }

    #[test]
    fn the_compile_time_sine_is_libms() {
        for k in -100..=100 {
            let x = k as f64 * 0.0628;
            assert!((const_sin(x) - libm::sin(x)).abs() < 1e-14, "{x}");
        }
    }
}
