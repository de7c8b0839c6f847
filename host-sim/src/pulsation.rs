//! Steady-state pressure pulsation: peak-to-peak, the amplitude spectrum, and the dominant
//! line attributed to its physical cause by its order (cycles per shaft revolution): the
//! pump's piston ripple at 2z (odd z) or z (even z), cogging at LCM(slots, 2·p_n), flux
//! harmonics at 6·p_n and 12·p_n, the shaft itself at 1 (Section 4 of the paper).

use plant_model::pump::ripple_order;
use plant_model::Rig;
use rustfft::{num_complex::Complex, FftPlannerScalar};

/// A source of periodic pulsation, by order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Source {
    /// What causes it.
    pub cause: &'static str,
    /// Cycles per mechanical revolution. [1/rev]
    pub order: f64,
}

/// The orders at which the rig's low-speed effects appear.
pub fn sources(rig: &Rig) -> Vec<Source> {
    let p_n = rig.motor.pole_pairs as f64;
    vec![
        Source {
            cause: "shaft (1 per revolution)",
            order: 1.0,
        },
        Source {
            cause: "flux harmonics (6th electrical)",
            order: 6.0 * p_n,
        },
        Source {
            cause: "flux harmonics (12th electrical)",
            order: 12.0 * p_n,
        },
        Source {
            cause: "piston ripple",
            order: ripple_order(rig.pump.pistons) as f64,
        },
        Source {
            cause: "cogging",
            order: rig.motor.cogging_fundamental_order() as f64,
        },
    ]
}

/// Peak-to-peak of a series. [same unit]
pub fn peak_to_peak(x: &[f64]) -> f64 {
    let (lo, hi) = x
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    if x.is_empty() {
        0.0
    } else {
        hi - lo
    }
}

/// One-sided amplitude spectrum of a uniformly sampled series (mean and linear trend
/// removed, Hann window with its coherent gain corrected): (frequency [Hz], amplitude).
pub fn amplitude_spectrum(x: &[f64], dt_s: f64) -> Vec<(f64, f64)> {
    let n = x.len();
    if n < 4 {
        return Vec::new();
    }
    // Remove the best straight line so a slow drift does not leak into every bin.
    let nf = n as f64;
    let tm = (nf - 1.0) / 2.0;
    let xm = x.iter().sum::<f64>() / nf;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, v) in x.iter().enumerate() {
        let t = i as f64 - tm;
        sxy += t * (v - xm);
        sxx += t * t;
    }
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    let mut buf: Vec<Complex<f64>> = x
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / nf).cos();
            Complex::new((v - xm - slope * (i as f64 - tm)) * w, 0.0)
        })
        .collect();
    FftPlannerScalar::new()
        .plan_fft_forward(n)
        .process(&mut buf);
    let df = 1.0 / (nf * dt_s);
    buf.iter()
        .take(n / 2)
        .enumerate()
        .skip(1)
        .map(|(k, c)| (k as f64 * df, 4.0 * c.norm() / nf))
        .collect()
}

/// How far a line must stand above the median of its neighbourhood to be one. The
/// Hann-windowed amplitude of a noise bin is Rayleigh distributed, P(A > k·median) =
/// 2^(−k²); the strongest of N noise bins passes k with probability below N·2^(−k²), 1e-3
/// for 4.5 and the few thousand bins of a pulsation spectrum.
pub const LINE_OVER_FLOOR: f64 = 4.5;
/// Bins on each side of a candidate whose median is its noise floor (the two next to it,
/// where a Hann-windowed line leaks, left out).
const FLOOR_BINS: usize = 12;

/// The median amplitude of the bins around `k` (±[`FLOOR_BINS`], without k ± 2).
fn noise_floor(spectrum: &[(f64, f64)], k: usize) -> f64 {
    let lo = k.saturating_sub(FLOOR_BINS);
    let hi = (k + FLOOR_BINS + 1).min(spectrum.len());
    let mut around: Vec<f64> = (lo..hi)
        .filter(|j| j.abs_diff(k) > 2)
        .map(|j| spectrum[j].1)
        .collect();
    if around.is_empty() {
        return 0.0;
    }
    around.sort_by(f64::total_cmp);
    around[around.len() / 2]
}

/// The strongest spectral line above `min_hz` — a bin standing [`LINE_OVER_FLOOR`] times
/// above its neighbourhood's median — and the source whose order it matches (within ±8 %
/// of the order, or ±1.5 bins) at shaft speed `shaft_rev_per_s`. When no bin is a line the
/// strongest bin is returned without a source: the pulsation is broadband there (in closed
/// loop, the pressure loop following its transducer's noise within its bandwidth), and
/// naming the order a noise bump happens to fall on would be a false attribution.
pub fn dominant_line(
    spectrum: &[(f64, f64)],
    min_hz: f64,
    shaft_rev_per_s: f64,
    sources: &[Source],
) -> Option<(f64, f64, Option<Source>)> {
    let above = || {
        spectrum
            .iter()
            .enumerate()
            .filter(|(_, (f, _))| *f >= min_hz)
    };
    let line = above()
        .filter(|(k, (_, a))| *a > LINE_OVER_FLOOR * noise_floor(spectrum, *k))
        .max_by(|x, y| x.1 .1.total_cmp(&y.1 .1));
    let Some((_, &(f, a))) = line else {
        let (_, &(f, a)) = above().max_by(|x, y| x.1 .1.total_cmp(&y.1 .1))?;
        return Some((f, a, None));
    };
    let df = spectrum.first().map(|p| p.0).unwrap_or(0.0);
    let cause = sources
        .iter()
        .filter(|s| {
            let expected = s.order * shaft_rev_per_s;
            (f - expected).abs() <= (0.08 * expected).max(1.5 * df)
        })
        .min_by(|x, y| {
            (f - x.order * shaft_rev_per_s)
                .abs()
                .total_cmp(&(f - y.order * shaft_rev_per_s).abs())
        })
        .copied();
    Some((f, a, cause))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spectrum_recovers_a_known_sine_and_its_order() {
        // 3 Pa at 18 Hz plus 1 Pa at 72 Hz on a drifting mean, sampled at 1 kHz for 2 s.
        let dt = 1e-3;
        let x: Vec<f64> = (0..2000)
            .map(|i| {
                let t = i as f64 * dt;
                5e6 + 100.0 * t
                    + 3.0 * (2.0 * std::f64::consts::PI * 18.0 * t).sin()
                    + (2.0 * std::f64::consts::PI * 72.0 * t).sin()
            })
            .collect();
        let s = amplitude_spectrum(&x, dt);
        let rig = Rig::nominal();
        let (f, a, cause) = dominant_line(&s, 2.0, 1.0, &sources(&rig)).unwrap();
        assert!((f - 18.0).abs() < 0.6, "{f}");
        assert!((a - 3.0).abs() < 0.1, "{a}");
        assert_eq!(cause.unwrap().cause, "piston ripple");
    }

    /// Gaussian noise (Box–Muller on a xorshift) through a first-order low-pass at
    /// `corner_hz`, sampled at 2 kHz for 3 s, plus a sine of `amp` at `f_hz`.
    fn noise_and_sine(seed: u64, corner_hz: f64, f_hz: f64, amp: f64) -> Vec<f64> {
        let mut state = seed | 1;
        let mut unit = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let dt = 1.0 / 2000.0;
        let a = (-2.0 * std::f64::consts::PI * corner_hz * dt).exp();
        let mut y = 0.0;
        (0..6000)
            .map(|i| {
                let n = (-2.0 * (1.0 - unit()).ln()).sqrt()
                    * (2.0 * std::f64::consts::PI * unit()).cos();
                y = a * y + (1.0 - a) * 1000.0 * n;
                let t = i as f64 * dt;
                5e6 + y + amp * (2.0 * std::f64::consts::PI * f_hz * t).sin()
            })
            .collect()
    }

    #[test]
    fn broadband_noise_is_not_attributed_to_the_order_it_peaks_at() {
        // Noise below a 3 Hz corner (a pressure loop following its transducer) peaks
        // somewhere below 4 Hz, often within a bin or two of a 0.9 rev/s shaft's first
        // order: no line there, so no cause, for every seed.
        let rig = Rig::nominal();
        for seed in 1..=20 {
            let x = noise_and_sine(seed, 3.0, 0.0, 0.0);
            let s = amplitude_spectrum(&x, 1.0 / 2000.0);
            let (f, _, cause) = dominant_line(&s, 0.5, 0.9, &sources(&rig)).unwrap();
            assert!(cause.is_none(), "seed {seed}: {f} Hz named {cause:?}");
        }
        // The same noise with a real line at the shaft frequency, 5 times the noise's
        // amplitude per bin: named.
        let x = noise_and_sine(3, 3.0, 0.9, 300.0);
        let s = amplitude_spectrum(&x, 1.0 / 2000.0);
        let (f, _, cause) = dominant_line(&s, 0.5, 0.9, &sources(&rig)).unwrap();
        assert_eq!(cause.map(|c| c.order), Some(1.0), "{f} Hz");
    }
}
