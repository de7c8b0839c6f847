//! Time-domain signatures of the baseline's residual r = measured − simulated, one signal
//! at a time: what kind of model error the log shows before any candidate is fitted, the
//! evidence the order spectrum ([`super::spectrum`]) cannot give.
//!
//! - Whiteness: the Ljung–Box statistic Q = N(N+2)·Σₖ ρₖ²/(N−k) over the first
//!   [`WHITENESS_LAGS`] autocorrelations, against χ² with as many degrees of freedom
//!   (Ljung & Box 1978). A nominal model that explains the log leaves white noise; a
//!   missing effect leaves structure.
//! - Correlation of the residual with the logged speed, pressure and q current: a missing
//!   leakage or a wrong absorber grows with pressure (eq. 9–11), a friction or a current
//!   offset follows the speed or the current.
//! - Lag: the shift of the simulated signal that best matches the measured one about the
//!   model's fastest change — a transducer lag or a dead time delays the measurement
//!   against the model.
//! - Stick–slip: the residual's RMS near standstill over its RMS while the shaft runs, the
//!   mark of a breakaway friction (Section 5.3) the model lacks.

use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Autocorrelation lags the whiteness test sums over. [1]
pub const WHITENESS_LAGS: usize = 20;

/// Largest shift the lag search tries: under half the period of the payload's 40–45 Hz
/// oil-spring resonance, which a free-payload log rings at, so that a whole period of
/// shift cannot pass for a lag. [s]
pub const MAX_LAG_S: f64 = 0.01;

/// Length of the window after the model's fastest change the lag is sought over. [s]
pub const LAG_WINDOW_S: f64 = 0.1;

/// Below this shaft speed the shaft counts as standing still. [rad/s]
pub const STANDSTILL_RAD_S: f64 = 1.0;

/// Fewest rows on each side (standing, running) for the stick–slip ratio. [1]
const MIN_SIDE_ROWS: usize = 20;

/// The signatures of one signal's residual.
#[derive(Clone, Debug, PartialEq)]
pub struct ResidualSignature {
    /// The signal (bench-log column name).
    pub signal: &'static str,
    /// RMS of the residual. [signal's unit]
    pub rms: f64,
    /// Ljung–Box Q over [`WHITENESS_LAGS`] lags. [1]
    pub ljung_box_q: f64,
    /// Probability that white residuals give a Q this large. [1]
    pub white_p: f64,
    /// Correlation coefficient of the residual with the logged shaft speed. [1]
    pub corr_speed: f64,
    /// Correlation coefficient of the residual with the logged pressure. [1]
    pub corr_pressure: f64,
    /// Correlation coefficient of the residual with the logged q current. [1]
    pub corr_current: f64,
    /// Shift of the simulated signal that best matches the measured one; positive when the
    /// measurement lags the model. [s]
    pub lag_s: f64,
    /// Residual RMS with the shaft below [`STANDSTILL_RAD_S`] over its RMS above; `None`
    /// when the shaft never stands or never runs. [1]
    pub standstill_ratio: Option<f64>,
}

/// The operating point the residual is correlated with, row for row (the model's, where
/// it predicts the signal: a residual correlates with its own measurement through the
/// noise alone).
pub struct Regressors<'a> {
    /// Shaft speed; also what decides standstill. [rad/s]
    pub speed_rad_s: &'a [f64],
    /// Pressure. [Pa]
    pub p_pa: &'a [f64],
    /// q current. [A]
    pub iq_a: &'a [f64],
}

/// The signatures of `measured − simulated` for `signal`, sampled every `dt_s` [s];
/// `None` when fewer rows than twice [`WHITENESS_LAGS`] or lengths differ.
pub fn residual_signature(
    signal: &'static str,
    dt_s: f64,
    measured: &[f64],
    simulated: &[f64],
    with: &Regressors,
) -> Option<ResidualSignature> {
    let n = measured.len();
    let lengths = [
        simulated.len(),
        with.speed_rad_s.len(),
        with.p_pa.len(),
        with.iq_a.len(),
    ];
    if n < 2 * WHITENESS_LAGS || lengths.iter().any(|l| *l != n) || dt_s.is_nan() || dt_s <= 0.0 {
        return None;
    }
    let r = super::fit_score::residual(measured, simulated);
    let rms = (r.iter().map(|x| x * x).sum::<f64>() / n as f64).sqrt();
    let q = ljung_box(&r, WHITENESS_LAGS);
    let white_p = ChiSquared::new(WHITENESS_LAGS as f64)
        .map(|c| c.sf(q))
        .unwrap_or(f64::NAN);
    let max_shift = ((MAX_LAG_S / dt_s).round() as usize).min(n / 4);
    Some(ResidualSignature {
        signal,
        rms,
        ljung_box_q: q,
        white_p,
        corr_speed: correlation(&r, with.speed_rad_s),
        corr_pressure: correlation(&r, with.p_pa),
        corr_current: correlation(&r, with.iq_a),
        lag_s: transient_lag(measured, simulated, max_shift, dt_s),
        standstill_ratio: standstill_ratio(&r, with.speed_rad_s),
    })
}

impl ResidualSignature {
    /// One phrase on the signature that bears on `effect`, for its evidence line.
    pub fn phrase_for(&self, effect: &str) -> String {
        let s = self.signal;
        match effect {
            "pressure_sensor_lag" | "dead_time" => format!(
                "baseline {s} residual: the measurement lags the model by {:.1} ms",
                1e3 * self.lag_s
            ),
            "shaft_friction" | "cylinder_friction" => match self.standstill_ratio {
                Some(k) => format!(
                    "baseline {s} residual: {k:.1}× its running RMS near standstill, \
                     correlation {:+.2} with speed",
                    self.corr_speed
                ),
                None => format!(
                    "baseline {s} residual: correlation {:+.2} with speed",
                    self.corr_speed
                ),
            },
            "extra_leakage" | "accumulator_precharge" | "entrained_air" => format!(
                "baseline {s} residual: correlation {:+.2} with pressure",
                self.corr_pressure
            ),
            "current_sensor_offset" => format!(
                "baseline {s} residual: correlation {:+.2} with the q current",
                self.corr_current
            ),
            _ => self.whiteness_phrase(),
        }
    }

    /// Whether the residual is white, in words.
    pub fn whiteness_phrase(&self) -> String {
        format!(
            "baseline {} residual {} (Ljung–Box Q = {:.0} over {WHITENESS_LAGS} lags, p = {:.2})",
            self.signal,
            if self.white_p >= 0.01 {
                "white"
            } else {
                "not white"
            },
            self.ljung_box_q,
            self.white_p
        )
    }
}

/// Ljung–Box Q of `r` over lags 1..=h (the mean removed first). [1]
fn ljung_box(r: &[f64], h: usize) -> f64 {
    let n = r.len();
    let mean = r.iter().sum::<f64>() / n as f64;
    let c0: f64 = r.iter().map(|x| (x - mean).powi(2)).sum();
    if c0 <= 0.0 {
        return 0.0;
    }
    let nf = n as f64;
    (1..=h.min(n - 1))
        .map(|k| {
            let ck: f64 = r
                .iter()
                .zip(&r[k..])
                .map(|(a, b)| (a - mean) * (b - mean))
                .sum();
            let rho = ck / c0;
            rho * rho / (nf - k as f64)
        })
        .sum::<f64>()
        * nf
        * (nf + 2.0)
}

/// Pearson correlation of `a` and `b`; 0 when either is constant. [1]
fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    if n == 0 {
        return 0.0;
    }
    let ma = a[..n].iter().sum::<f64>() / n as f64;
    let mb = b[..n].iter().sum::<f64>() / n as f64;
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a[..n].iter().zip(&b[..n]) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma).powi(2);
        sbb += (y - mb).powi(2);
    }
    if saa <= 0.0 || sbb <= 0.0 {
        0.0
    } else {
        sab / (saa * sbb).sqrt()
    }
}

/// The shift s in −max..=max (rows) that best correlates measured[k] with
/// simulated[k − s] over the rows both cover (Pearson: a level offset between model and
/// measurement does not move it); positive when the measurement lags.
fn best_shift(measured: &[f64], simulated: &[f64], max: usize) -> i64 {
    let n = measured.len() as i64;
    let max = max as i64;
    let score = |s: i64| {
        let lo = s.max(0) as usize;
        let hi = (n + s).min(n) as usize;
        if hi <= lo + 2 {
            return f64::NEG_INFINITY;
        }
        let shifted = &simulated[(lo as i64 - s) as usize..(hi as i64 - s) as usize];
        correlation(&measured[lo..hi], shifted)
    };
    (-max..=max)
        .map(|s| (s, score(s)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(0, |(s, _)| s)
}

/// The lag over the window about the model's fastest change (from twice [`MAX_LAG_S`] before it
/// to [`LAG_WINDOW_S`] after): a lag shows where the signal moves, and over a short window
/// a slightly wrong resonance or rate in the model (the rig's tolerances) has no time to
/// drift out of phase. [s]
fn transient_lag(measured: &[f64], simulated: &[f64], max_shift: usize, dt_s: f64) -> f64 {
    let n = measured.len();
    let Some(k) = (1..n).max_by(|&a, &b| {
        let da = (simulated[a] - simulated[a - 1]).abs();
        let db = (simulated[b] - simulated[b - 1]).abs();
        da.total_cmp(&db)
    }) else {
        return 0.0;
    };
    let lo = k.saturating_sub(2 * max_shift);
    let hi = (k + (LAG_WINDOW_S / dt_s).round() as usize + max_shift).min(n);
    best_shift(&measured[lo..hi], &simulated[lo..hi], max_shift) as f64 * dt_s
}

/// RMS of `r` where |speed| < [`STANDSTILL_RAD_S`] over its RMS elsewhere.
fn standstill_ratio(r: &[f64], speed: &[f64]) -> Option<f64> {
    let (mut still, mut ns, mut running, mut nr) = (0.0, 0usize, 0.0, 0usize);
    for (x, w) in r.iter().zip(speed) {
        if w.abs() < STANDSTILL_RAD_S {
            still += x * x;
            ns += 1;
        } else {
            running += x * x;
            nr += 1;
        }
    }
    if ns < MIN_SIDE_ROWS || nr < MIN_SIDE_ROWS || running <= 0.0 {
        return None;
    }
    Some(((still / ns as f64) / (running / nr as f64)).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::test_noise::gaussian;

    fn flat(n: usize) -> Vec<f64> {
        vec![0.0; n]
    }

    fn signature_of(measured: &[f64], simulated: &[f64]) -> ResidualSignature {
        let n = measured.len();
        let (w, p, i) = (flat(n), flat(n), flat(n));
        residual_signature(
            "p_pa",
            1e-3,
            measured,
            simulated,
            &Regressors {
                speed_rad_s: &w,
                p_pa: &p,
                iq_a: &i,
            },
        )
        .expect("enough rows")
    }

    #[test]
    fn white_noise_is_white_and_an_ar1_residual_is_not() {
        let n = 2000;
        let e = gaussian(n, 3);
        let white = signature_of(&e, &flat(n));
        // Q of white noise is χ²(20): mean 20, 99th percentile 37.6.
        assert!(white.ljung_box_q < 37.6, "{}", white.ljung_box_q);
        assert!(white.white_p > 0.01, "{}", white.white_p);
        // AR(1) with φ = 0.5: ρₖ = 0.5ᵏ, so Q ≈ N·Σ 0.25ᵏ = N/3 ≈ 667.
        let mut ar = vec![0.0; n];
        for k in 1..n {
            ar[k] = 0.5 * ar[k - 1] + e[k];
        }
        let coloured = signature_of(&ar, &flat(n));
        assert!(
            (coloured.ljung_box_q - n as f64 / 3.0).abs() < 0.2 * n as f64 / 3.0,
            "{}",
            coloured.ljung_box_q
        );
        assert!(coloured.white_p < 1e-6, "{}", coloured.white_p);
    }

    #[test]
    fn a_delayed_measurement_shows_its_delay() {
        // A 3 Hz sine measured 7 ms late at 1 kHz.
        let model: Vec<f64> = (0..1000)
            .map(|k| (std::f64::consts::TAU * 3.0 * k as f64 * 1e-3).sin())
            .collect();
        let measured: Vec<f64> = (0..1000)
            .map(|k| (std::f64::consts::TAU * 3.0 * (k as f64 - 7.0) * 1e-3).sin())
            .collect();
        let s = signature_of(&measured, &model);
        assert!((s.lag_s - 7e-3).abs() < 1e-9, "{}", s.lag_s);
        let early = signature_of(&model, &measured);
        assert!((early.lag_s + 7e-3).abs() < 1e-9, "{}", early.lag_s);
    }

    #[test]
    fn correlations_and_stick_slip_follow_their_regressors() {
        let n = 1000;
        let e = gaussian(n, 5);
        let iq = gaussian(n, 9);
        // Speed: standing for the first 200 rows, then running at 30 rad/s.
        let speed: Vec<f64> = (0..n).map(|k| if k < 200 { 0.0 } else { 30.0 }).collect();
        // Pressure ramping 1 → 5 MPa.
        let p: Vec<f64> = (0..n).map(|k| 1e6 + 4e3 * k as f64).collect();
        let with = Regressors {
            speed_rad_s: &speed,
            p_pa: &p,
            iq_a: &iq,
        };
        let mean_p = p.iter().sum::<f64>() / n as f64;
        // 1e-3 of the pressure's swing (±2000) over unit noise: correlation
        // 1155/√(1155² + 1) with pressure; an independent current's stays within a few
        // 1/√N = 0.03.
        let leak: Vec<f64> = (0..n).map(|k| 1e-3 * (p[k] - mean_p) + e[k]).collect();
        let s = residual_signature("p_pa", 1e-3, &leak, &flat(n), &with).expect("rows");
        assert!(s.corr_pressure > 0.99, "{}", s.corr_pressure);
        assert!(s.corr_current.abs() < 0.15, "{}", s.corr_current);
        // Noise five times larger while standing: the ratio is 5 within sampling error
        // (≈ 5 % on 200 rows).
        let stick: Vec<f64> = (0..n)
            .map(|k| e[k] * if k < 200 { 5.0 } else { 1.0 })
            .collect();
        let s = residual_signature("p_pa", 1e-3, &stick, &flat(n), &with).expect("rows");
        let ratio = s.standstill_ratio.expect("both sides");
        assert!((ratio - 5.0).abs() < 1.0, "{ratio}");
    }
}
