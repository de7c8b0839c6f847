//! Order spectrum of a residual against the shaft angle: the residual resampled at equal
//! angle steps over the whole revolutions the log covers, then its amplitude spectrum
//! (`rustfft`), so a line at order k is a disturbance k times per revolution whatever the
//! speed did. This separates the angle-locked effects: a phase-current offset at p_n
//! (1st electrical), 5th/7th flux harmonics at 6·p_n, cogging at LCM(slots, 2·p_n), piston
//! ripple at z or 2z (eq. 16–21).

use rustfft::{num_complex::Complex, FftPlannerScalar};
use std::f64::consts::PI;

/// Samples per revolution of the resampled residual (orders up to half of it are seen).
pub const SAMPLES_PER_REV: usize = 512;

/// A residual's order spectrum.
#[derive(Clone, Debug, PartialEq)]
pub struct OrderSpectrum {
    /// Whole revolutions analysed. [1]
    pub revolutions: usize,
    /// Amplitude (peak) of order k at index k, k = 0 … SAMPLES_PER_REV/2. [signal unit]
    pub amplitude: Vec<f64>,
}

impl OrderSpectrum {
    /// Amplitude at order `k` (0 beyond the range). [signal unit]
    pub fn at(&self, k: u32) -> f64 {
        self.amplitude.get(k as usize).copied().unwrap_or(0.0)
    }

    /// The strongest order in `lo..=hi`.
    pub fn strongest(&self, lo: u32, hi: u32) -> Option<(u32, f64)> {
        (lo..=hi)
            .map(|k| (k, self.at(k)))
            .filter(|(_, a)| *a > 0.0)
            .max_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Median line amplitude over `lo..=hi`: the floor a line must stand above. [unit]
    pub fn floor(&self, lo: u32, hi: u32) -> f64 {
        let mut v: Vec<f64> = (lo..=hi).map(|k| self.at(k)).collect();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(0.0)
    }
}

/// The order spectrum of `residual` sampled at the unwrapped shaft angles `theta`; `None`
/// when the shaft turned less than two revolutions one way or went back by more than a
/// tenth of a revolution (then angle is not a time base).
pub fn order_spectrum(theta: &[f64], residual: &[f64]) -> Option<OrderSpectrum> {
    let n = theta.len().min(residual.len());
    if n < 4 {
        return None;
    }
    let (theta, residual) = (&theta[..n], &residual[..n]);
    let sign = if theta[n - 1] >= theta[0] { 1.0 } else { -1.0 };
    // The angle turned since the first row, forward (read row by row, not copied).
    let a = |i: usize| sign * (theta[i] - theta[0]);
    let mut peak = f64::NEG_INFINITY;
    for x in (0..n).map(a) {
        if x < peak - 0.2 * PI {
            return None;
        }
        peak = peak.max(x);
    }
    let revolutions = (a(n - 1) / (2.0 * PI)).floor() as usize;
    if revolutions < 2 {
        return None;
    }
    let m = revolutions * SAMPLES_PER_REV;
    let mut buf = Vec::with_capacity(m);
    let mut j = 0;
    for i in 0..m {
        let target = 2.0 * PI * i as f64 / SAMPLES_PER_REV as f64;
        // The angle is monotonic up to small reversals: advance to the bracketing pair.
        while j + 2 < n && a(j + 1) < target {
            j += 1;
        }
        let (a0, a1) = (a(j), a(j + 1));
        let f = if a1 > a0 {
            ((target - a0) / (a1 - a0)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        buf.push(Complex::new(
            residual[j] + f * (residual[j + 1] - residual[j]),
            0.0,
        ));
    }
    let mean = buf.iter().map(|c| c.re).sum::<f64>() / m as f64;
    for c in &mut buf {
        c.re -= mean;
    }
    FftPlannerScalar::new()
        .plan_fft_forward(m)
        .process(&mut buf);
    let amplitude = (0..=SAMPLES_PER_REV / 2)
        .map(|k| {
            let bin = k * revolutions;
            buf.get(bin).map_or(0.0, |c| 2.0 * c.norm() / m as f64)
        })
        .collect();
    Some(OrderSpectrum {
        revolutions,
        amplitude,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_locked_to_the_angle_shows_at_its_order_whatever_the_speed() {
        // Shaft accelerating from 2 to 12 rad/s over 5 s; residual 0.3·cos(72θ + 1).
        let n = 20_000;
        let theta: Vec<f64> = (0..n)
            .map(|k| {
                let t = 5.0 * k as f64 / n as f64;
                2.0 * t + t * t
            })
            .collect();
        let r: Vec<f64> = theta.iter().map(|a| 0.3 * (72.0 * a + 1.0).cos()).collect();
        let s = order_spectrum(&theta, &r).unwrap();
        assert!((s.at(72) - 0.3).abs() < 0.01, "{}", s.at(72));
        assert_eq!(s.strongest(1, 200).unwrap().0, 72);
        assert!(s.at(24) < 0.01);
    }

    #[test]
    fn no_spectrum_when_the_shaft_barely_turns() {
        let theta: Vec<f64> = (0..1000).map(|k| k as f64 * 1e-3).collect();
        assert!(order_spectrum(&theta, &theta).is_none());
    }
}
