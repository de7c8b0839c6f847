//! Clarke, Park and inverse Park transforms, amplitude-invariant (Section 3.1: the d-q model
//! of eq. 1–3 is written in these coordinates), and the one sin/cos path of the crate.
//!
//! Amplitude-invariant: a balanced set of amplitude I maps to an α-β vector of length I
//! (factor 2/3). The d axis is the rotor flux axis at electrical angle θ_e, q leads it by
//! 90°.
//!
//! Sin and cos go through [`sin_cos`] only: one table of 256 sine samples per revolution,
//! each with its slope to the next, built at compile time ([`SINE`]), linearly
//! interpolated at the angle's position on the fixed-point grid of
//! [`crate::angle_grid`]; the cosine is the same table a quarter turn on. Host and target
//! compute bit-identical numbers, with no floor, no polynomial and no call: about 15
//! instructions for the pair on a Cortex-M4F. Linear interpolation errs by at most
//! h²/8 = 7.5·10⁻⁵ (h = 2π/256), an angle error below 0.005° and a gain error of the
//! transform below 0.01 %.

use crate::angle_grid::{const_sin, position};

/// √3/2. [1]
pub const SQRT3_2: f32 = 0.866_025_4;
/// 1/√3. [1]
pub const INV_SQRT3: f32 = 0.577_350_26;

/// Stationary-frame two-axis vector. [A or V]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AlphaBeta {
    /// α component (phase-a axis).
    pub alpha: f32,
    /// β component (90° ahead of α).
    pub beta: f32,
}

/// Rotor-frame two-axis vector. [A or V]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dq {
    /// d component (rotor flux axis).
    pub d: f32,
    /// q component (torque axis).
    pub q: f32,
}

/// Sine and cosine of one angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SinCos {
    /// sin θ. [1]
    pub sin: f32,
    /// cos θ. [1]
    pub cos: f32,
}

/// Sine samples per revolution of [`SINE`] (a power of two). [1]
pub const SINE_BINS_LOG2: u32 = 8;
const SINE_BINS: usize = 1 << SINE_BINS_LOG2;
/// Bins in a quarter revolution: the cosine's offset into [`SINE`].
const QUARTER: usize = SINE_BINS / 4;

/// sin(2π·k/256) and its step to the next sample, for k = 0 … 319 (a revolution and a
/// quarter, so the cosine's lookup never wraps). The step is the difference of the two
/// rounded samples, so adjacent bins meet exactly. [1]
pub static SINE: [[f32; 2]; SINE_BINS + QUARTER] = {
    let mut t = [[0.0f32; 2]; SINE_BINS + QUARTER];
    let h = 2.0 * core::f64::consts::PI / SINE_BINS as f64;
    let mut k = 0;
    while k < SINE_BINS + QUARTER {
        let a = const_sin((k % SINE_BINS) as f64 * h) as f32;
        let b = const_sin(((k + 1) % SINE_BINS) as f64 * h) as f32;
        t[k] = [a, b - a];
        k += 1;
    }
    t
};

/// Sine and cosine of `theta` [rad] through the crate's single path: the interpolated
/// table [`SINE`] (any angle within ±12 868 rad, [`crate::angle_grid`]; NaN reads as 0).
#[inline]
pub fn sin_cos(theta: f32) -> SinCos {
    let (bin, frac) = position(theta, SINE_BINS_LOG2);
    // `bin` < 256 by its mask, so both lookups are in bounds and need no check.
    let [s, ds] = SINE[bin];
    let [c, dc] = SINE[bin + QUARTER];
    SinCos {
        sin: s + frac * ds,
        cos: c + frac * dc,
    }
}

/// Clarke transform of three phase quantities (amplitude-invariant). Uses all three
/// phases, so a common-mode error (an offset on all three) drops out.
#[inline]
pub fn clarke(a: f32, b: f32, c: f32) -> AlphaBeta {
    AlphaBeta {
        alpha: (2.0 * a - b - c) * (1.0 / 3.0),
        beta: (b - c) * INV_SQRT3,
    }
}

/// Inverse Clarke: the three phase quantities (zero-sequence free) of an α-β vector.
#[inline]
pub fn inverse_clarke(v: AlphaBeta) -> [f32; 3] {
    let half_a = -0.5 * v.alpha;
    let b = SQRT3_2 * v.beta;
    [v.alpha, half_a + b, half_a - b]
}

/// Park transform: stationary α-β to the rotor d-q frame at the angle of `sc`.
#[inline]
pub fn park(v: AlphaBeta, sc: SinCos) -> Dq {
    Dq {
        d: v.alpha * sc.cos + v.beta * sc.sin,
        q: -v.alpha * sc.sin + v.beta * sc.cos,
    }
}

/// Inverse Park transform: rotor d-q to stationary α-β at the angle of `sc`.
#[inline]
pub fn inverse_park(v: Dq, sc: SinCos) -> AlphaBeta {
    AlphaBeta {
        alpha: v.d * sc.cos - v.q * sc.sin,
        beta: v.d * sc.sin + v.q * sc.cos,
    }
}

/// Wraps an angle into [0, 2π). [rad]
#[inline]
pub fn wrap_2pi(theta: f32) -> f32 {
    let tau = core::f32::consts::TAU;
    let w = theta - tau * libm::floorf(theta * (1.0 / tau));
    // Rounding can land exactly on 2π.
    if w >= tau || w < 0.0 {
        0.0
    } else {
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f32::consts::PI;

    #[test]
    fn sin_cos_matches_libm_within_the_interpolation_bound() {
        // Linear interpolation between samples h apart errs by at most h²/8 (the second
        // derivative of sin is at most 1); the angle's truncation to the grid's unit
        // (2π/2^20) adds at most one unit times the slope, the f32 samples their rounding.
        // Within ±60 rad the product θ·units is an exact integer-valued f32 (< 2^24).
        let h = core::f64::consts::TAU / 256.0;
        let unit = core::f64::consts::TAU / (1u32 << 20) as f64;
        let bound = (h * h / 8.0 + unit) as f32 + 1e-6;
        let mut worst = 0f32;
        for k in -60_000..=60_000 {
            let x = k as f32 * 0.001;
            let sc = sin_cos(x);
            let (s, c) = (libm::sin(x as f64) as f32, libm::cos(x as f64) as f32);
            worst = worst.max((sc.sin - s).abs()).max((sc.cos - c).abs());
        }
        assert!(worst <= bound, "worst {worst}, bound {bound}");
        // The bound is attained mid-bin (it is not loose): half a bin past a sample at
        // the sine's peak the chord lies h²/8 below the arc.
        let x = core::f32::consts::FRAC_PI_2 + (h / 2.0) as f32;
        let err = libm::sinf(x) - sin_cos(x).sin;
        assert!(err > 0.8 * (h * h / 8.0) as f32, "{err}");
    }

    #[test]
    fn sin_cos_of_the_grid_points_are_the_samples() {
        for k in 0..256 {
            let x = k as f32 * core::f32::consts::TAU / 256.0;
            let sc = sin_cos(x);
            // An angle rounded just below a grid point reads the previous bin's end: one
            // unit of the grid (6·10⁻⁶ rad) times the slope at most.
            assert!((sc.sin - libm::sinf(x)).abs() < 8e-6, "{k}");
            assert!((sc.cos - libm::cosf(x)).abs() < 8e-6, "{k}");
        }
        // Non-finite angles read as angle 0 (no panic, finite output).
        for x in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let sc = sin_cos(x);
            assert!(sc.sin.is_finite() && sc.cos.is_finite());
        }
    }

    #[test]
    fn clarke_of_balanced_set_is_a_vector_of_the_amplitude() {
        // a = I cos φ, b = I cos(φ − 2π/3), c = I cos(φ + 2π/3) → (I cos φ, I sin φ).
        let amp = 7.5;
        for k in 0..36 {
            let phi = k as f32 * 2.0 * PI / 36.0;
            let a = amp * libm::cosf(phi);
            let b = amp * libm::cosf(phi - 2.0 * PI / 3.0);
            let c = amp * libm::cosf(phi + 2.0 * PI / 3.0);
            let v = clarke(a, b, c);
            assert!((v.alpha - amp * libm::cosf(phi)).abs() < 1e-5);
            assert!((v.beta - amp * libm::sinf(phi)).abs() < 1e-5);
        }
    }

    #[test]
    fn known_vectors() {
        // Only phase a carries +1, b and c −0.5: α = 1, β = 0.
        let v = clarke(1.0, -0.5, -0.5);
        assert!((v.alpha - 1.0).abs() < 1e-6 && v.beta.abs() < 1e-6);
        // b = +√3/2, c = −√3/2: pure β of 1.
        let v = clarke(0.0, 0.866_025_4, -0.866_025_4);
        assert!(v.alpha.abs() < 1e-6 && (v.beta - 1.0).abs() < 1e-6);
        // Common mode vanishes.
        let v = clarke(3.0, 3.0, 3.0);
        assert!(v.alpha.abs() < 1e-6 && v.beta.abs() < 1e-6);
        // At θ = 90° the d axis is β: a pure-β vector is pure d.
        let sc = SinCos { sin: 1.0, cos: 0.0 };
        let dq = park(
            AlphaBeta {
                alpha: 0.0,
                beta: 2.0,
            },
            sc,
        );
        assert!((dq.d - 2.0).abs() < 1e-6 && dq.q.abs() < 1e-6);
        // q leads d: at θ = 0, q is β.
        let sc = SinCos { sin: 0.0, cos: 1.0 };
        let ab = inverse_park(Dq { d: 0.0, q: 3.0 }, sc);
        assert!(ab.alpha.abs() < 1e-6 && (ab.beta - 3.0).abs() < 1e-6);
    }

    #[test]
    fn round_trips_are_identities() {
        for k in 0..100 {
            let theta = k as f32 * 0.37 - 10.0;
            let sc = sin_cos(theta);
            let dq = Dq {
                d: -3.0 + 0.1 * k as f32,
                q: 12.0 - 0.2 * k as f32,
            };
            // park ∘ inverse_park multiplies by sin² + cos², within the table's error.
            let back = park(inverse_park(dq, sc), sc);
            let norm = sc.sin * sc.sin + sc.cos * sc.cos;
            assert!((norm - 1.0).abs() < 2e-4);
            assert!((back.d - dq.d * norm).abs() < 1e-4, "{back:?} {dq:?}");
            assert!((back.q - dq.q * norm).abs() < 1e-4);
            // clarke ∘ inverse_clarke is exact.
            let ab = AlphaBeta {
                alpha: dq.d,
                beta: dq.q,
            };
            let [a, b, c] = inverse_clarke(ab);
            assert!((a + b + c).abs() < 1e-4);
            let ab2 = clarke(a, b, c);
            assert!((ab2.alpha - ab.alpha).abs() < 1e-5 && (ab2.beta - ab.beta).abs() < 1e-5);
        }
    }

    #[test]
    fn wrap_stays_in_range() {
        for x in [
            -7.0,
            -0.0,
            0.0,
            1.0,
            core::f32::consts::TAU,
            6.283_184,
            100.0,
            -1e-9,
        ] {
            let w = wrap_2pi(x);
            assert!((0.0..core::f32::consts::TAU).contains(&w), "{x} -> {w}");
        }
        assert!((wrap_2pi(-1.0) - (core::f32::consts::TAU - 1.0)).abs() < 1e-6);
    }
}
