//! Position-tracking observer (a type-2 phase-locked loop) on the encoder angle: the
//! low-speed speed estimate of the speed loop.
//!
//! ## Why
//!
//! The plain count difference over one 2 kHz speed period (M method) has a quantum of
//! 2π/N·f_s = 1.26 rad/s with N = 10 000 counts/rev. In the paper's low-speed pressure
//! holding (Section 5, the shaft at ≈ 5.7 rad/s) it flips between 5.03 and 6.28 rad/s
//! (0.63 rad/s rms), which Kp = 0.14 A/(rad/s) turns into ≈ 0.09 A rms of q-current noise:
//! an artefact of the controller, seen as pressure pulsation.
//!
//! ## What
//!
//! Run at the current-loop rate on the unwrapped count (the measurement, quantised to one
//! count q = 2π/N):
//!
//! ```text
//! e  = θ − θ̂                  angle error            [counts]
//! ω_i += K_i·T·e               speed integrator       [counts/s]
//! ω̂  = ω_i + K_p·e             speed estimate         [counts/s]
//! θ̂  += ω̂·T                    angle estimate         [counts]
//! ```
//!
//! with K_p = 2ζω_n, K_i = ω_n², critically damped (ζ = 1: the error dynamics
//! s² + 2ω_n·s + ω_n² have a double real pole, no ringing after a disturbance, and the
//! smallest worst-case error among the usual damping choices). In continuous time
//! (ω_n·T = 0.05 at the defaults, so the forward-Euler loop is close to it):
//!
//! ```text
//! θ̂/θ = (2ω_n·s + ω_n²)/(s + ω_n)²      ω_i/ω = ω_n²/(s + ω_n)²
//! ```
//!
//! θ̂ follows a constant speed without error and a constant acceleration a with the
//! constant angle lag a/ω_n²; the integrator ω_i is a second-order low-pass of the speed
//! (ramp lag 2/ω_n).
//!
//! ## What the speed loop uses
//!
//! The speed loop takes the *mean speed of the estimated angle over its period*,
//! (θ̂(t) − θ̂(t − T_s))/T_s — the M method applied to θ̂ instead of the raw count. Since θ̂
//! tracks constant speed and acceleration with no or constant error, this keeps the speed
//! loop's measurement model (the mean over the last period, 0.25 ms behind) unchanged at
//! the frequencies of the speed loop: at its ≈ 200 rad/s crossover θ̂/θ adds −0.8° and
//! +0.3 dB. The integrator alone (ω_i) would average better but lags ramps by 2/ω_n = 2 ms
//! (−23° at 200 rad/s), a real change to the speed loop's phase margin.
//!
//! ## Bandwidth (`speed.observer_bandwidth_rad_s`, default ω_n = 1000 rad/s)
//!
//! Five times the speed loop's crossover (≈ 200 rad/s) and seven times its fastest pole
//! (−143 rad/s), so the loop does not see it; low enough that θ̂ averages the encoder's
//! count edges (at 5.7 rad/s an edge every 0.11 ms, about 18 edges within 2/ω_n).
//! Noise with the count's quantisation modelled as white, variance q²/12 per sample
//! (Widrow): the estimated angle has the noise bandwidth
//! (1/2π)∫|θ̂/θ|²dω = ω_n·(4ζ² + 1)/(4ζ) = 1.25·ω_n, and since |1 − e^{−jωT_s}| ≤ 2 the
//! speed loop's estimate has at most
//!
//! ```text
//! σ_ω ≤ (q/√12)·(2/T_s)·√(T·1.25·ω_n) = 0.18 rad/s rms
//! ```
//!
//! (the constant-speed simulation in the tests gives 0.05 rad/s at 5.7 rad/s), against
//! 0.63 rad/s rms and the 1.26 rad/s quantum of the raw count difference. Lag: none for
//! constant speed, and for a constant acceleration a the angle lag a/ω_n² (e.g. 41 µrad at
//! 41 000 rad/s², the 30 A limit on the bare shaft) which cancels in the difference over
//! a period; the estimate's step response settles in ≈ 6/ω_n = 6 ms to 2 %.
//!
//! The current loop keeps the raw encoder angle: its quantum is p_n·q = 2.5 mrad electrical,
//! while θ̂'s lag at the largest acceleration, p_n·a/ω_n² = 0.16 rad electrical, would
//! misalign the current vector by 9°.
//!
//! ## Cost
//!
//! Per current-loop call: one i64 subtraction, an i64→f32 conversion of a small number,
//! five f32 multiply/adds and the renormalisation of the fraction (a float→int conversion
//! and one compare): about 25–30 Thumb-2 instructions on the M4F (FPU, no libm calls).
//!
//! The angle estimate is kept as whole counts (i64) plus a fraction in [−0.5, 0.5) so it
//! keeps full resolution however far the shaft has turned.

use crate::pi::saturate;

/// Damping ratio of the error dynamics (critically damped). [1]
pub const DAMPING: f32 = 1.0;

/// Largest angle error the observer integrates per sample. Far beyond anything a
/// plausible encoder (a few tens of counts per sample) produces; keeps a corrupted
/// position from putting a huge float into the state. [counts]
const MAX_ERROR_COUNTS: f32 = (1u32 << 20) as f32;

/// An estimated angle: whole counts plus a fraction.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EstimatedAngle {
    /// Whole part. [counts]
    pub whole: i64,
    /// Fractional part, in [−0.5, 0.5) after an observer step. [counts]
    pub frac: f32,
}

impl EstimatedAngle {
    /// The angle travelled since `earlier`, saturated to ±2²⁴ counts (a corrupted
    /// position gives a large but finite number). [counts]
    #[inline]
    pub fn counts_since(&self, earlier: &EstimatedAngle) -> f32 {
        let whole = self
            .whole
            .wrapping_sub(earlier.whole)
            .clamp(-1 << 24, 1 << 24);
        // Through i32 (exact after the clamp): a single vcvt on the M4F, no __aeabi_l2f.
        whole as i32 as f32 + (self.frac - earlier.frac)
    }
}

/// The observer's state and its discrete-time gains.
#[derive(Clone, Copy, Debug)]
pub struct SpeedObserver {
    kp: f32,
    ki_t: f32,
    t: f32,
    rad_per_count: f32,
    angle: EstimatedAngle,
    speed_i: f32,
    speed: f32,
}

impl SpeedObserver {
    /// For the bandwidth `bandwidth_rad_s` = ω_n [rad/s], sampled at `sample_hz` [Hz], on
    /// an encoder of `counts_per_rev` [counts]. Expects validated values; a zero rate is
    /// replaced by 1 Hz so nothing divides by zero.
    pub fn new(bandwidth_rad_s: f32, sample_hz: f32, counts_per_rev: u32) -> SpeedObserver {
        let t = 1.0 / sample_hz.max(1.0);
        let wn = bandwidth_rad_s.max(0.0);
        SpeedObserver {
            kp: 2.0 * DAMPING * wn,
            ki_t: wn * wn * t,
            t,
            rad_per_count: core::f32::consts::TAU / counts_per_rev.max(1) as f32,
            angle: EstimatedAngle::default(),
            speed_i: 0.0,
            speed: 0.0,
        }
    }

    /// Changes the bandwidth ω_n [rad/s] keeping the angle and speed estimates, so the
    /// estimate does not jump.
    pub fn set_bandwidth(&mut self, bandwidth_rad_s: f32) {
        let wn = bandwidth_rad_s.max(0.0);
        self.kp = 2.0 * DAMPING * wn;
        self.ki_t = wn * wn * self.t;
    }

    /// Restarts at rest at `position`. [counts]
    pub fn reset(&mut self, position: i64) {
        self.angle = EstimatedAngle {
            whole: position,
            frac: 0.0,
        };
        self.speed_i = 0.0;
        self.speed = 0.0;
    }

    /// One correction with the unwrapped encoder `position` [counts].
    #[inline]
    pub fn update(&mut self, position: i64) {
        let diff = position.wrapping_sub(self.angle.whole);
        // Comparison saturation (no f32::clamp panic path or fmaxf call on the M4F).
        let e = saturate(
            // Through i32: i64 → f32 is a library call (__aeabi_l2f) on the M4F, i32 → f32
            // one vcvt; the clamp makes the narrowing exact.
            diff.clamp(-(1 << 24), 1 << 24) as i32 as f32 - self.angle.frac,
            -MAX_ERROR_COUNTS,
            MAX_ERROR_COUNTS,
        );
        self.speed_i += self.ki_t * e;
        self.speed = self.speed_i + self.kp * e;
        self.advance();
    }

    /// One prediction without a measurement (the sample was implausible): the angle moves
    /// on at the integrator's speed.
    #[inline]
    pub fn coast(&mut self) {
        self.speed = self.speed_i;
        self.advance();
    }

    #[inline]
    fn advance(&mut self) {
        let frac = self.angle.frac + self.speed * self.t;
        // Round to the nearest whole count without libm: `as` truncates toward zero and
        // saturates (NaN → 0), so floor(x + 0.5) is the truncation corrected downward.
        let x = frac + 0.5;
        let mut k = x as i32;
        if (k as f32) > x {
            // Saturating: x below i32::MIN (a diverged, unvalidated loop) must not panic.
            k = k.saturating_sub(1);
        }
        self.angle.whole = self.angle.whole.wrapping_add(k as i64);
        self.angle.frac = frac - k as f32;
        if !self.angle.frac.is_finite() {
            // Only a non-finite state gets here; restart from the whole count.
            self.angle.frac = 0.0;
            self.speed_i = 0.0;
            self.speed = 0.0;
        }
    }

    /// The estimated angle. [counts]
    pub fn angle(&self) -> EstimatedAngle {
        self.angle
    }

    /// Instantaneous speed estimate ω̂ = ω_i + K_p·e (the rate of θ̂; it carries K_p times
    /// the quantisation noise). [rad/s]
    pub fn speed_rad_s(&self) -> f32 {
        self.speed * self.rad_per_count
    }

    /// The integrator's speed ω_i: the speed through the low-pass ω_n²/(s + ω_n)². [rad/s]
    pub fn filtered_speed_rad_s(&self) -> f32 {
        self.speed_i * self.rad_per_count
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f32::consts::TAU;

    /// Floor of a non-negative angle in counts, as the encoder reports it.
    fn count(theta_counts: f64) -> i64 {
        theta_counts.floor() as i64
    }

    #[test]
    fn speed_step_follows_the_critically_damped_response() {
        // θ = ω₀·t from rest: E(s) = ω₀/(s + ω_n)², so e(t) = ω₀·t·e^{−ω_n t} (peak
        // ω₀/(e·ω_n) at 1/ω_n), and ω_i(t) = ω₀·(1 − e^{−x}(1 + x)), x = ω_n·t. The
        // forward-Euler loop deviates by O(ω_n·T) = 5 % of the peak at 20 kHz; ω₀ is large
        // enough that one count of quantisation is 0.3 % of it.
        let (wn, fs) = (1000.0f64, 20_000.0f64);
        let t_s = 1.0 / fs;
        let w0 = 1.0e6; // [counts/s]
        let mut o = SpeedObserver::new(wn as f32, fs as f32, 10_000);
        let peak = w0 / (core::f64::consts::E * wn);
        let mut worst_e = 0.0f64;
        let mut worst_w = 0.0f64;
        let mut seen_peak = 0.0f64;
        for k in 0..(0.02 * fs) as usize {
            let t = k as f64 * t_s;
            let theta = w0 * t;
            // The error this sample corrects (before the update).
            let e = theta.floor() - (o.angle().whole as f64 + o.angle().frac as f64);
            o.update(count(theta));
            let e_an = w0 * t * (-wn * t).exp();
            worst_e = worst_e.max((e - e_an).abs());
            seen_peak = seen_peak.max(e);
            // The integrator after the update stands for the continuous one at t + T.
            let x = wn * (t + t_s);
            let wi_an = w0 * (1.0 - (-x).exp() * (1.0 + x));
            let wi = o.filtered_speed_rad_s() as f64 / (TAU as f64 / 10_000.0);
            worst_w = worst_w.max((wi - wi_an).abs());
        }
        assert!(
            (seen_peak - peak).abs() < 0.05 * peak,
            "peak error {seen_peak} counts, analytic {peak}"
        );
        assert!(
            worst_e < wn * t_s * peak + 1.0,
            "angle error off by {worst_e} counts"
        );
        assert!(worst_w < 0.01 * w0, "integrator off by {worst_w} counts/s");
        // Settled: the speed estimate is the step.
        assert!((o.speed_rad_s() as f64 / (TAU as f64 / 10_000.0) - w0).abs() < 1e-3 * w0);
    }

    #[test]
    fn speed_ramp_is_tracked_with_the_designed_lags() {
        // θ = a·t²/2: steady angle lag a/ω_n² (E = a/(s·(s + ω_n)²)), the integrator lags
        // the speed by 2a/ω_n, and the rate of θ̂ has no lag (type 2).
        let (wn, fs) = (1000.0f64, 20_000.0f64);
        let t_s = 1.0 / fs;
        let a = 4.0e6; // [counts/s²] = 2513 rad/s² at 10 000 counts/rev
        let mut o = SpeedObserver::new(wn as f32, fs as f32, 10_000);
        let rad = TAU as f64 / 10_000.0;
        let n = (0.03 * fs) as usize;
        let mut lag = 0.0;
        for k in 0..n {
            let t = k as f64 * t_s;
            let theta = 0.5 * a * t * t;
            let est = o.angle().whole as f64 + o.angle().frac as f64;
            lag = theta - est;
            o.update(count(theta));
            if k + 1 == n {
                let w = a * (t + t_s);
                let wi = o.filtered_speed_rad_s() as f64 / rad;
                let lag_wi = w - wi;
                assert!(
                    (lag_wi - 2.0 * a / wn).abs() < 0.05 * 2.0 * a / wn,
                    "integrator lags {lag_wi} counts/s, design 2a/ω_n = {}",
                    2.0 * a / wn
                );
            }
        }
        // Half a count of quantisation on average; Euler moves it by O(ω_n·T).
        let design = a / (wn * wn);
        assert!(
            (lag - 0.5 - design).abs() < 0.1 * design,
            "angle lag {lag} counts, design a/ω_n² = {design} (+0.5 quantisation)"
        );
        // Rate of θ̂ over a window of m samples: the true mean speed over it, one sample
        // ahead (θ̂ after an update predicts the next sample), with no lag. The count's
        // quantisation leaves σ = (1/√12)·√(1.25·ω_n·T) = 0.072 counts on θ̂ (white-noise
        // model, see the module docs); the window's two ends allow 4·√2·σ.
        let m = 200usize;
        let mut o2 = o;
        let start = o2.angle();
        for k in n..n + m {
            let t = k as f64 * t_s;
            o2.update(count(0.5 * a * t * t));
        }
        let mean_speed = o2.angle().counts_since(&start) as f64 / (m as f64 * t_s);
        let true_mean = 0.5 * a * t_s * ((n + m) as f64).powi(2) / m as f64
            - 0.5 * a * t_s * (n as f64).powi(2) / m as f64;
        let sigma = (1.25 * wn * t_s / 12.0).sqrt();
        let tol = 4.0 * 2f64.sqrt() * sigma / (m as f64 * t_s);
        assert!(
            (mean_speed - true_mean).abs() < tol,
            "mean rate of θ̂ {mean_speed} counts/s vs the true mean {true_mean} ± {tol}"
        );
    }

    /// Rms of the M-method speed over one speed period of `div` samples: on the raw count
    /// (`raw`) or on the observer's angle.
    fn constant_speed_rms(w_rad_s: f64, raw: bool) -> (f64, f64) {
        let (fs, div, n) = (20_000.0f64, 10usize, 10_000u32);
        let rad = TAU as f64 / n as f64;
        let mut o = SpeedObserver::new(1000.0, fs as f32, n);
        let theta0 = 1234.3; // [counts], arbitrary phase
        o.reset(count(theta0));
        let mut last_est = o.angle();
        let mut last_raw = count(theta0);
        let (mut sum, mut sum2, mut m) = (0.0f64, 0.0f64, 0usize);
        for k in 0..(2.0 * fs) as usize {
            let p = count(theta0 + w_rad_s / rad * k as f64 / fs);
            o.update(p);
            if k % div == 0 {
                let counts = if raw {
                    (p - last_raw) as f64
                } else {
                    o.angle().counts_since(&last_est) as f64
                };
                last_raw = p;
                last_est = o.angle();
                // Skip the observer's start-up (0.1 s ≫ 6/ω_n).
                if k as f64 > 0.1 * fs {
                    let w = counts * rad * fs / div as f64;
                    sum += w;
                    sum2 += w * w;
                    m += 1;
                }
            }
        }
        let mean = sum / m as f64;
        (mean, (sum2 / m as f64 - mean * mean).max(0.0).sqrt())
    }

    #[test]
    fn low_speed_ripple_is_far_below_the_count_quantum() {
        // The paper's low-speed holding speed, 10 000 counts/rev, 20 kHz, 2 kHz speed loop.
        let w = 5.7;
        let q = TAU as f64 / 10_000.0;
        let (fs, t_s, wn) = (20_000.0f64, 1.0 / 2_000.0f64, 1000.0f64);
        // Raw count difference: the quantum q/T_s and, at a fractional count rate p, an
        // rms of quantum·√(p(1 − p)) (two values, taken with probability p and 1 − p).
        let quantum = q / t_s;
        let per_period = w / q * t_s;
        let p = per_period - per_period.floor();
        let raw_rms_expected = quantum * (p * (1.0 - p)).sqrt();
        let (raw_mean, raw_rms) = constant_speed_rms(w, true);
        assert!((quantum - 1.2566).abs() < 1e-3);
        assert!((raw_rms - raw_rms_expected).abs() < 0.02 * raw_rms_expected);
        assert!((raw_mean - w).abs() < 0.01);
        // Observer: count quantisation as white noise q²/12 per sample through θ̂/θ (noise
        // bandwidth 1.25·ω_n for ζ = 1) and the difference over T_s (|1 − e^{−jωT_s}| ≤ 2).
        let bound = q / 12f64.sqrt() * (2.0 / t_s) * (1.25 * wn / fs).sqrt();
        let (mean, rms) = constant_speed_rms(w, false);
        println!(
            "5.7 rad/s: raw count difference rms {raw_rms:.3} rad/s (quantum {quantum:.3}), \
             observer rms {rms:.4} rad/s (bound {bound:.3}), mean {mean:.4}"
        );
        assert!((bound - 0.181).abs() < 0.001, "{bound}");
        assert!(
            rms < bound,
            "observer ripple {rms} rad/s rms, bound {bound}"
        );
        assert!(rms < 0.1 * raw_rms && rms < 0.05 * quantum);
        assert!((mean - w).abs() < 0.01, "observer mean {mean} rad/s");
    }

    #[test]
    fn coasting_keeps_the_speed_and_corrupt_positions_stay_finite() {
        let mut o = SpeedObserver::new(1000.0, 20_000.0, 10_000);
        // 20 counts per sample = 400 000 counts/s.
        for k in 0..2_000i64 {
            o.update(20 * k);
        }
        let before = o.angle();
        let w = o.speed_rad_s();
        for _ in 0..10 {
            o.coast();
        }
        assert!((o.angle().counts_since(&before) - 200.0).abs() < 0.5);
        assert!((o.speed_rad_s() - w).abs() < 1e-3 * w);
        o.update(i64::MAX);
        o.update(i64::MIN);
        for _ in 0..100 {
            o.update(0);
        }
        assert!(o.speed_rad_s().is_finite() && o.angle().frac.is_finite());
    }
}
