//! Steady-state pressure pulsation: peak-to-peak, the amplitude spectrum, and the dominant
//! line attributed to its physical cause by its order (cycles per shaft revolution): the
//! pump's piston ripple at 2z (odd z) or z (even z), cogging at LCM(slots, 2·p_n), flux
//! harmonics at 6·p_n and 12·p_n, the shaft itself at 1 (Section 4 of the paper).

use plant_model::pump::ripple_order;
use plant_model::Rig;
use rustfft::{num_complex::Complex, FftPlanner};

/// A source of periodic pulsation, by order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Source {
    /// What causes it.
    pub cause: &'static str,
    /// Cycles per mechanical revolution.
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
    FftPlanner::new().plan_fft_forward(n).process(&mut buf);
    let df = 1.0 / (nf * dt_s);
    buf.iter()
        .take(n / 2)
        .enumerate()
        .skip(1)
        .map(|(k, c)| (k as f64 * df, 4.0 * c.norm() / nf))
        .collect()
}

/// The strongest spectral line above `min_hz`, and the source whose order it matches
/// (within ±8 % of the order, or ±1.5 bins) at shaft speed `shaft_rev_per_s`.
pub fn dominant_line(
    spectrum: &[(f64, f64)],
    min_hz: f64,
    shaft_rev_per_s: f64,
    sources: &[Source],
) -> Option<(f64, f64, Option<Source>)> {
    let &(f, a) = spectrum
        .iter()
        .filter(|(f, _)| *f >= min_hz)
        .max_by(|x, y| x.1.total_cmp(&y.1))?;
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
}
