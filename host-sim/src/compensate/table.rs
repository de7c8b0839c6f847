//! The feed-forward's table from its three channels written as angle-locked harmonics:
//! sampled on the drive's grid of [`BINS`] bins per revolution, each harmonic
//! pre-emphasised so that the drive's linear interpolation reproduces it, and quantised
//! to the record's i16 values with a power-of-two LSB per channel
//! ([`firmware::compensation::record`]).
//!
//! Linear interpolation between samples of e^{jkθ} taken every 2π/N returns the order k
//! multiplied by sinc²(πk/N) (the triangle kernel's transform; plus images at N ± k, far
//! above anything the shaft passes): 0.937 at the cogging's 72nd order on 512 bins. Each
//! harmonic is therefore written 1/sinc²(πk/N) larger, orders up to N/4 only (beyond, the
//! images come close and the correction grows past 1.6).

use firmware::compensation::{Channel, Exponent, Table, BINS, CHANNELS, MAX_EXPONENT};
use rustfft::num_complex::Complex64;
use std::f64::consts::PI;

/// Highest order a channel may carry. [cycles per revolution]
pub const MAX_ORDER: u32 = (BINS / 4) as u32;

/// One angle-locked component: the value Re(amplitude·e^{j·order·θ}). [the channel's unit]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Harmonic {
    /// Cycles per mechanical revolution (0: a constant, taken as its real part).
    pub order: u32,
    /// Complex amplitude.
    pub amplitude: Complex64,
}

/// The three channels as sums of harmonics, in the channels' units (A, A/Pa, A/A).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Channels {
    /// Per channel ([`Channel::ALL`] order), the harmonics.
    pub harmonics: [Vec<Harmonic>; CHANNELS],
}

impl Channels {
    /// Adds `h` to `channel`.
    pub fn add(&mut self, channel: Channel, h: Harmonic) {
        self.harmonics[channel as usize].push(h);
    }

    /// The channel's value at shaft angle `theta` [rad], as written (no pre-emphasis).
    pub fn value(&self, channel: Channel, theta: f64) -> f64 {
        self.harmonics[channel as usize]
            .iter()
            .map(|h| (h.amplitude * Complex64::from_polar(1.0, h.order as f64 * theta)).re)
            .sum()
    }
}

/// The gain of the drive's linear interpolation at `order`: sinc²(π·order/N). [1]
pub fn interpolation_gain(order: u32) -> f64 {
    let x = PI * order as f64 / BINS as f64;
    if x == 0.0 {
        1.0
    } else {
        (x.sin() / x).powi(2)
    }
}

/// Samples of `harmonics` on the drive's grid, each order pre-emphasised; orders above
/// [`MAX_ORDER`] are dropped.
pub fn samples(harmonics: &[Harmonic]) -> Vec<f64> {
    (0..BINS)
        .map(|b| {
            let th = 2.0 * PI * b as f64 / BINS as f64;
            harmonics
                .iter()
                .filter(|h| h.order <= MAX_ORDER)
                .map(|h| {
                    let z = h.amplitude / interpolation_gain(h.order);
                    (z * Complex64::from_polar(1.0, h.order as f64 * th)).re
                })
                .sum()
        })
        .collect()
}

/// The LSB exponent e (LSB 2^−e) that fits `peak` into an i16 with the most resolution:
/// 2^−e·32767 ≥ peak. [1]
pub fn exponent_for(peak: f64) -> Exponent {
    if peak.is_nan() || peak <= 0.0 {
        return 0;
    }
    let e = (32_767.0 / peak).log2().floor();
    e.clamp(0.0, MAX_EXPONENT as f64) as Exponent
}

/// The table for per-channel samples `columns` (each [`BINS`] values in the channel's
/// unit); `None` when a value does not fit an i16 even at LSB 1.
pub fn quantise(columns: &[Vec<f64>; CHANNELS]) -> Option<Table> {
    let exponents: [Exponent; CHANNELS] = core::array::from_fn(|c| {
        exponent_for(columns[c].iter().fold(0.0f64, |m, v| m.max(v.abs())))
    });
    let mut raw = Box::new([[0i16; CHANNELS]; BINS]);
    for (c, col) in columns.iter().enumerate() {
        let scale = 2f64.powi(exponents[c] as i32);
        for (b, v) in col.iter().enumerate().take(BINS) {
            let q = (v * scale).round();
            if !(-32_768.0..=32_767.0).contains(&q) {
                return None;
            }
            raw[b][c] = q as i16;
        }
    }
    Table::from_raw(exponents, &raw)
}

/// The table of `channels`: sampled, pre-emphasised, quantised.
pub fn build(channels: &Channels) -> Option<Table> {
    let columns: [Vec<f64>; CHANNELS] = core::array::from_fn(|c| samples(&channels.harmonics[c]));
    quantise(&columns)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_drive_reproduces_a_pre_emphasised_line_at_its_amplitude() {
        // A 72/rev line of 0.05 A: the drive's lookup (linear interpolation) of the table
        // has, at order 72, the amplitude and phase written (lock-in over a fine grid).
        let mut ch = Channels::default();
        let a = Complex64::from_polar(0.05, 0.7);
        ch.add(
            Channel::Constant,
            Harmonic {
                order: 72,
                amplitude: a,
            },
        );
        let t = build(&ch).unwrap();
        let n = 20_000;
        let mut z = Complex64::new(0.0, 0.0);
        for i in 0..n {
            let th = 2.0 * PI * i as f64 / n as f64;
            let v = t.at(th as f32)[0] as f64;
            z += v * Complex64::from_polar(1.0, -72.0 * th);
        }
        let z = z * (2.0 / n as f64);
        assert!((z - a).norm() < 2e-4 * 0.05 * 10.0, "{z} vs {a}");
        // Without the pre-emphasis the drive would give sinc²(π·72/512) = 0.937 of it.
        assert!((interpolation_gain(72) - 0.9366).abs() < 1e-3);
    }

    #[test]
    fn exponents_use_the_i16_range() {
        assert_eq!(exponent_for(0.05), 19); // 0.05·2^19 = 26 214 ≤ 32 767 < 0.05·2^20
        assert_eq!(exponent_for(0.0), 0);
        assert_eq!(exponent_for(1e5), 0);
    }
}
