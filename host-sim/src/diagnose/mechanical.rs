//! The mechanical parity relation: the shaft's torque balance (eq. 3–4, 16–21) read both
//! ways from the logged signals.
//!
//! ```text
//!   T_e(i_d, i_q, θ) + T_cog(θ) = J·dω/dt + D/2π·s(θ)·(p − p_low) + B·ω + T_c·sgn(ω) + U(θ)
//! ```
//!
//! with T_e the plant motor's torque (eq. 3 with its flux harmonics, eq. 17–19), T_cog its
//! cogging (eq. 16), s(θ) the plant pump's displacement factor (eq. 20) and U the
//! unexplained torque lines the angle-locked effects were fitted as ([`TorqueLine`]).
//!
//! - The q current the model needs ([`Mechanics::needed_current`]): solved for i_q with the
//!   logged speed's derivative, pressure and angle; compared with the logged `iq_a`, a
//!   torque the model lacks shows directly as current. A current-sensor offset is the
//!   difference between the measured current and the one that flowed, so it shows here too.
//! - The speed ([`Mechanics::speed`]): the balance integrated from the logged currents over
//!   short windows re-started from the logged speed (multiple shooting), so a torque error
//!   shows as a slope within each window and never as a drift.
//!
//! The shaft's acceleration is the quadratic Savitzky–Golay second derivative of the logged
//! angle over ±[`SAVGOL_HALF_WIDTH_S`] (fitted at the logged times where the rows are
//! uneven, [`super::uneven_derivative`]), or without the angle the central difference over
//! ±[`RATE_HALF_WIDTH_S`] of the logged speed: one encoder count over one log interval is a
//! speed step far larger than the current's noise.

use crate::bench_log::BenchLog;
use crate::diagnose::facts::{rows_spanning, LogFacts};
use crate::diagnose::uneven_derivative::second_derivative_at_times;
use plant_model::motor::{Motor, Phasor};
use plant_model::pump::Pump;
use plant_model::rig::{MotorParams, PumpParams};
use plant_model::Rig;
use rustfft::num_complex::Complex64;
use std::f64::consts::PI;
use std::ops::Range;

/// Time on each side of the central differences that give speed and acceleration (five
/// rows of a 1 kHz log): a span in time, so a faster log's encoder quantisation is not
/// differentiated over a shorter interval. [s]
pub const RATE_HALF_WIDTH_S: f64 = 5e-3;

/// Half-width of the Savitzky–Golay window of the shaft's acceleration (three rows of a
/// 1 kHz log). [s]
pub const SAVGOL_HALF_WIDTH_S: f64 = 3e-3;

/// Speed over which the Coulomb torque's sign fades in (a smooth sgn). [rad/s]
pub const COULOMB_FADE_RAD_S: f64 = 0.5;

/// What an angle-locked line's amplitude multiplies, row by row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LineScale {
    /// Nothing: a torque in N·m (cogging, a current offset's image through K_t).
    Constant,
    /// The electromagnetic torque K_t·i_q (flux harmonics, eq. 19) at the q current's
    /// moving mean: the amplitude is fitted per unit of the steady windows' mean torque,
    /// and the ripple's product with the current's own line at its order (a mean torque
    /// the calibrated friction already holds) is left out.
    Electromagnetic,
    /// The pump's pressure difference times this factor (its torque ripple, eq. 20). [m³/rad]
    PressureDifference(f64),
}

/// A line of unexplained torque U = Re(Z·x·e^{jkθ}): the logged current's torque less the
/// torque the shaft's motion and load account for. A torque the model lacks is −U on the
/// shaft; a current-sensor offset's image is U/K_t in the measured current.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorqueLine {
    /// Cycles per mechanical revolution. [1]
    pub order: u32,
    /// Complex amplitude per unit of the scale. [N·m or 1]
    pub amplitude: Complex64,
    /// What scales it.
    pub scale: LineScale,
}

/// The mechanical model's parameters (SI).
#[derive(Clone, Debug)]
pub struct MechanicalParams {
    /// The motor: ψ_f, L_d, L_q, the rig's cogging and flux harmonics (eq. 3, 16–19).
    pub motor: MotorParams,
    /// Shaft inertia J (motor and pump). [kg·m²]
    pub inertia_kg_m2: f64,
    /// Viscous friction B. [N·m·s]
    pub viscous_nm_s: f64,
    /// Coulomb friction T_c. [N·m]
    pub coulomb_nm: f64,
    /// The pump (displacement and ripple, eq. 20).
    pub pump: PumpParams,
    /// Unexplained torque lines (the angle-locked effects fitted).
    pub lines: Vec<TorqueLine>,
}

impl MechanicalParams {
    /// The rig file's values.
    pub fn nominal(rig: &Rig) -> MechanicalParams {
        MechanicalParams {
            motor: rig.motor.clone(),
            inertia_kg_m2: rig.shaft.inertia_kg_m2(),
            viscous_nm_s: rig.shaft.viscous_nm_s,
            coulomb_nm: rig.shaft.coulomb_nm,
            pump: rig.pump.clone(),
            lines: Vec::new(),
        }
    }
}

/// Speed and acceleration from the angle (or the logged speed), computed once per log.
///
/// Every fit of the mechanical relation reads these at every row, so they are kept for
/// the whole diagnosis: as single-precision values (a relative rounding of 6e-8, far below
/// any sensor's noise), and the speed not at all when it is the logged one, so that the
/// shaft's motion costs 28 bytes a row beside the log's own columns.
#[derive(Clone, Debug)]
pub struct ShaftMotion {
    /// The speed the logged angle gives, when the angle is logged (otherwise the logged
    /// speed is the shaft's). [rad/s]
    speed_from_angle: Option<Vec<f32>>,
    /// Acceleration. [rad/s²]
    accel_rad_s2: Vec<f32>,
    /// The q current's moving mean ([`MEAN_CURRENT_HALF_WIDTH_S`]), which scales the flux
    /// harmonics' torque line. [A]
    iq_mean_a: Vec<f32>,
    /// The Coulomb friction's sign, faded through zero speed: tanh(ω/[`COULOMB_FADE_RAD_S`])
    /// at the shaft's speed, computed once for every fit that scales it. [1]
    coulomb_shape: Vec<f32>,
    /// The unit phasors of the shaft angle θ and of the electrical angle p_n·θ at every row
    /// as (cos θ, sin θ, cos p_n·θ, sin p_n·θ): the cogging torque, the flux harmonics and
    /// the pump's ripple are evaluated at them in every fit. [1]
    rotation: Vec<[f32; 4]>,
    /// How the acceleration was read: what it keeps of a line ([`ShaftMotion::accel_gain`]).
    pub accel_filter: AccelFilter,
}

/// The filter the acceleration was read through.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AccelFilter {
    /// The angle's quadratic Savitzky–Golay second derivative over ±`half` rows `period`
    /// apart. [rows, s]
    SavitzkyGolay { half: usize, period: f64 },
    /// The central difference over ±`half` rows of a speed. [rows, s]
    Central { half: usize, period: f64 },
}

/// Central difference of `y` against `t` over ±`h` rows, clipped at the ends.
pub fn central_rate(t: &[f64], y: &[f64], h: usize) -> Vec<f64> {
    let n = t.len().min(y.len());
    (0..n)
        .map(|k| {
            let lo = k.saturating_sub(h);
            let hi = (k + h).min(n - 1);
            if hi > lo {
                (y[hi] - y[lo]) / (t[hi] - t[lo])
            } else {
                0.0
            }
        })
        .collect()
}

/// The second derivative of `y` by a quadratic Savitzky–Golay fit over ±`m` rows (at
/// least 1; uniform sampling at `period` assumed; the ends repeat their neighbour's). The
/// fitted quadratic's curvature is 2·Σ c_j·y_j / (Σ c_j²·period²) with c_j = j² − ⟨j²⟩;
/// over ±3 rows it is flat to about a tenth of the sampling rate, so the shaft's
/// oscillation at the angle-locked orders keeps its acceleration, while the encoder's
/// quantisation is amplified 4.6 times less than by a second difference.
pub fn savgol_second_derivative(y: &[f64], period: f64, m: usize) -> Vec<f64> {
    let m = m.max(1);
    let n = y.len();
    let mut out = vec![0.0; n];
    if n < 2 * m + 1 {
        return out;
    }
    let mean_j2 = (m * (m + 1)) as f64 / 3.0;
    let c: Vec<f64> = (0..=2 * m)
        .map(|i| {
            let j = i as f64 - m as f64;
            j * j - mean_j2
        })
        .collect();
    let scale = 2.0 / (c.iter().map(|c| c * c).sum::<f64>() * period * period);
    for k in m..n - m {
        out[k] = scale
            * c.iter()
                .zip(&y[k - m..=k + m])
                .map(|(c, y)| c * y)
                .sum::<f64>();
    }
    for k in 0..m {
        out[k] = out[m];
        out[n - 1 - k] = out[n - 1 - m];
    }
    out
}

impl ShaftMotion {
    /// The shaft's motion in `log` on a motor of `pole_pairs`, its acceleration keeping the
    /// angle-locked orders ([`savgol_second_derivative`]).
    pub fn of(log: &BenchLog, facts: &LogFacts, pole_pairs: u32) -> ShaftMotion {
        let h = rows_spanning(RATE_HALF_WIDTH_S, facts.period_s, 1);
        let period = facts.period_s;
        let central = AccelFilter::Central { half: h, period };
        let (speed, accel, accel_filter) = if facts.angle.is_logged() {
            let speed = central_rate(&log.t_s, &facts.theta_rad, h);
            let m = rows_spanning(SAVGOL_HALF_WIDTH_S, period, 1);
            // Uneven rows: the same quadratic fitted at the logged times, its response taken
            // as the even filter's at the median period.
            let accel = if facts.uniform {
                savgol_second_derivative(&facts.theta_rad, period, m)
            } else {
                second_derivative_at_times(&log.t_s, &facts.theta_rad, m as f64 * period)
            };
            (
                Some(speed),
                accel,
                AccelFilter::SavitzkyGolay { half: m, period },
            )
        } else {
            let accel = central_rate(&log.t_s, &log.speed_rad_s, h);
            (None, accel, central)
        };
        let coulomb_shape = speed
            .as_deref()
            .unwrap_or(&log.speed_rad_s)
            .iter()
            .map(|w| (w / COULOMB_FADE_RAD_S).tanh() as f32)
            .collect();
        let pp = pole_pairs as f64;
        let rotation = facts
            .theta_rad
            .iter()
            .map(|th| {
                let (m, e) = (Phasor::of(*th), Phasor::of(pp * th));
                [m.cos as f32, m.sin as f32, e.cos as f32, e.sin as f32]
            })
            .collect();
        let single = |v: &[f64]| v.iter().map(|x| *x as f32).collect::<Vec<f32>>();
        ShaftMotion {
            coulomb_shape,
            rotation,
            speed_from_angle: speed.map(|s| single(&s)),
            accel_rad_s2: single(&accel),
            iq_mean_a: single(&mean_current(&log.iq_a, facts.period_s)),
            accel_filter,
        }
    }

    /// The shaft's speed at row `k` of `log` (the log the motion was read from). [rad/s]
    #[inline]
    pub fn speed_at(&self, log: &BenchLog, k: usize) -> f64 {
        match &self.speed_from_angle {
            Some(s) => s[k] as f64,
            None => log.speed_rad_s[k],
        }
    }

    /// The shaft's acceleration at row `k`. [rad/s²]
    #[inline]
    pub fn accel_at(&self, k: usize) -> f64 {
        self.accel_rad_s2[k] as f64
    }

    /// The q current's moving mean at row `k`. [A]
    #[inline]
    pub fn iq_mean_at(&self, k: usize) -> f64 {
        self.iq_mean_a[k] as f64
    }

    /// The Coulomb friction's faded sign at row `k`. [1]
    #[inline]
    pub fn coulomb_shape_at(&self, k: usize) -> f64 {
        self.coulomb_shape[k] as f64
    }

    /// The unit phasors of the shaft angle and of the electrical angle at row `k`. [1]
    #[inline]
    pub fn rotation_at(&self, k: usize) -> [Phasor; 2] {
        let [mc, ms, ec, es] = self.rotation[k].map(|x| x as f64);
        [Phasor { cos: mc, sin: ms }, Phasor { cos: ec, sin: es }]
    }

    /// The fraction of a shaft oscillation's acceleration at angular frequency `w` that
    /// [`ShaftMotion::accel_rad_s2`] keeps: the filter's response to cos(w·t) over −w², 1 for
    /// slow motion, falling towards and past the log's Nyquist rate. A torque line the
    /// acceleration cannot follow is balanced by an oscillation it does not see: the
    /// torque balance may only carry the share of the line the acceleration keeps. [1]
    pub fn accel_gain(&self, w: f64) -> f64 {
        let w = w.abs();
        if w == 0.0 {
            return 1.0;
        }
        match self.accel_filter {
            AccelFilter::SavitzkyGolay { half, period } => {
                let m = half.max(1) as i64;
                let mean_j2 = (m * (m + 1)) as f64 / 3.0;
                let (mut num, mut den) = (0.0, 0.0);
                for j in -m..=m {
                    let c = (j * j) as f64 - mean_j2;
                    num += c * (j as f64 * w * period).cos();
                    den += c * c;
                }
                -2.0 * num / (den * period * period) / (w * w)
            }
            AccelFilter::Central { half, period } => {
                // A central difference of a central difference of the angle.
                let x = w * half.max(1) as f64 * period;
                let g = x.sin() / x;
                g * g
            }
        }
    }
}

/// A prepared mechanical model.
pub struct Mechanics {
    params: MechanicalParams,
    motor: Motor,
    pump: Pump,
}

impl Mechanics {
    /// Prepares `params`.
    pub fn new(params: MechanicalParams) -> Mechanics {
        Mechanics {
            motor: Motor::new(&params.motor),
            pump: Pump::new(&params.pump),
            params,
        }
    }

    /// The parameters.
    pub fn params(&self) -> &MechanicalParams {
        &self.params
    }

    /// Electromagnetic torque at row `k` as (∂T/∂i_q, the rest) with the logged i_d, so the
    /// torque is slope·i_q + rest (eq. 3 with the flux harmonics, plus cogging). [N·m/A, N·m]
    #[inline]
    fn torque_terms(&self, log: &BenchLog, rot: [Phasor; 2], k: usize) -> (f64, f64) {
        let [mechanical, electrical] = rot;
        let flux = self.motor.magnet_flux_at(electrical);
        let id = log.id_a[k];
        let rest = self.motor.torque_nm(id, 0.0, &flux);
        let slope = self.motor.torque_nm(id, 1.0, &flux) - rest;
        (slope, rest + self.motor.cogging_torque_at(mechanical))
    }

    /// Load torque at row `k` from the logged pressures and angle, the shaft at `speed` with
    /// the Coulomb friction's faded sign `shape`: pump, viscous and Coulomb friction. [N·m]
    #[inline]
    fn load_torque(
        &self,
        log: &BenchLog,
        facts: &LogFacts,
        k: usize,
        rot: Phasor,
        speed: f64,
        shape: f64,
    ) -> f64 {
        let m = &self.params;
        let factor = if m.pump.piston_ripple {
            self.pump.displacement_factor_at(facts.theta_rad[k], rot)
        } else {
            1.0
        };
        self.pump
            .load_torque(log.p_pa[k], facts.p_low(log).at(k), factor)
            + m.viscous_nm_s * speed
            + m.coulomb_nm * shape
    }

    /// The unexplained torque lines at row `k` (electromagnetic torque `t_em`), each the
    /// share of it the acceleration's filter keeps at the line's frequency. [N·m]
    #[inline]
    fn line_torque(
        &self,
        log: &BenchLog,
        facts: &LogFacts,
        motion: &ShaftMotion,
        k: usize,
        t_em: f64,
    ) -> f64 {
        let theta = facts.theta_rad[k];
        let w = motion.speed_at(log, k);
        self.params
            .lines
            .iter()
            .map(|l| {
                let x = match l.scale {
                    LineScale::Constant => 1.0,
                    LineScale::Electromagnetic => t_em,
                    LineScale::PressureDifference(f) => f * (log.p_pa[k] - facts.p_low(log).at(k)),
                };
                let kept = motion.accel_gain(l.order as f64 * w).clamp(0.0, 1.0);
                kept * x * (l.amplitude * Complex64::from_polar(1.0, l.order as f64 * theta)).re
            })
            .sum()
    }

    /// The q current the model needs at every row in `rows`, written into `out`. [A]
    pub fn needed_current(
        &self,
        log: &BenchLog,
        facts: &LogFacts,
        motion: &ShaftMotion,
        rows: Range<usize>,
        out: &mut [f64],
    ) {
        let j = self.params.inertia_kg_m2;
        let base = rows.start;
        for k in rows {
            let w = motion.speed_at(log, k);
            let rot = motion.rotation_at(k);
            let shape = motion.coulomb_shape_at(k);
            let need = self.load_torque(log, facts, k, rot[0], w, shape) + j * motion.accel_at(k);
            let (slope, rest) = self.torque_terms(log, rot, k);
            let slope = if slope.abs() > 1e-9 { slope } else { 1e-9 };
            let t_mean = slope * motion.iq_mean_at(k) + rest;
            out[k - base] = (need - rest + self.line_torque(log, facts, motion, k, t_mean)) / slope;
        }
    }

    /// The speed over each of `windows`, integrated from the logged currents and re-started
    /// from the shaft's speed at each window's first row, written into `out`. [rad/s]
    pub fn speed(
        &self,
        log: &BenchLog,
        facts: &LogFacts,
        motion: &ShaftMotion,
        windows: &[Range<usize>],
        out: &mut [f64],
    ) {
        let t = &log.t_s;
        let j = self.params.inertia_kg_m2.max(1e-12);
        for win in windows {
            let mut w = motion.speed_at(log, win.start);
            out[win.start] = w;
            for k in win.start..win.end - 1 {
                let rot = motion.rotation_at(k);
                let (slope, rest) = self.torque_terms(log, rot, k);
                let t_em = slope * log.iq_a[k] + rest;
                let drive = t_em
                    - self.line_torque(log, facts, motion, k, slope * motion.iq_mean_at(k) + rest)
                    - self.load_torque(log, facts, k, rot[0], w, (w / COULOMB_FADE_RAD_S).tanh());
                w += (t[k + 1] - t[k]) * drive / j;
                out[k + 1] = w;
            }
        }
    }
}

/// The q current's moving mean over ±[`MEAN_CURRENT_HALF_WIDTH_S`] of rows `period` [s]
/// apart. [A]
fn mean_current(iq: &[f64], period: f64) -> Vec<f64> {
    let half = (MEAN_CURRENT_HALF_WIDTH_S / period.max(f64::MIN_POSITIVE)).round() as usize;
    let mut prefix = vec![0.0; iq.len() + 1];
    for (k, i) in iq.iter().enumerate() {
        prefix[k + 1] = prefix[k] + i;
    }
    (0..iq.len())
        .map(|k| {
            let lo = k.saturating_sub(half);
            let hi = (k + half + 1).min(iq.len());
            (prefix[hi] - prefix[lo]) / (hi - lo) as f64
        })
        .collect()
}

/// Half width of the q current's moving mean that scales the flux harmonics' torque line:
/// several periods of the 6·p_n line at the lowest speeds a steady window is read at. [s]
pub const MEAN_CURRENT_HALF_WIDTH_S: f64 = 0.025;

/// Mean over a revolution of the pump's torque ripple at its fundamental order per unit
/// peak-to-peak ratio: the amplitude of (s(θ) − 1)'s line at 2z (odd z) or z for a ripple
/// of peak-to-peak 1. [1]
pub fn ripple_fundamental_per_ratio(rig: &Rig, pistons: u32) -> f64 {
    let mut pp = rig.pump.clone();
    pp.pistons = pistons.max(1);
    pp.piston_ripple = true;
    pp.ripple_amplitude_ratio = 1.0;
    let pump = Pump::new(&pp);
    let order = plant_model::pump::ripple_order(pistons.max(1)) as f64;
    let n = 4096;
    let (mut c, mut s) = (0.0, 0.0);
    for j in 0..n {
        let th = 2.0 * PI * j as f64 / n as f64;
        let y = pump.displacement_factor(th) - 1.0;
        c += y * (order * th).cos();
        s += y * (order * th).sin();
    }
    2.0 * (c * c + s * s).sqrt() / n as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn savitzky_golay_is_exact_on_a_parabola_and_quieter_over_a_wider_window() {
        // y = 3·t² has y'' = 6 at any half-width; over ±m rows white noise of unit variance
        // gives y'' a variance of 4/(Σ c_j²·h⁴), Σ c_j² = m(m+1)(2m+1)(2m+3)(2m−1)/45.
        let h = 1e-4;
        let y: Vec<f64> = (0..400).map(|k| 3.0 * (k as f64 * h).powi(2)).collect();
        for m in [1, 3, 30] {
            let d = savgol_second_derivative(&y, h, m);
            assert!(
                d.iter().all(|v| (v - 6.0).abs() < 1e-6),
                "m = {m}: {}",
                d[200]
            );
        }
        let noise = crate::diagnose::test_noise::gaussian(200_000, 5);
        for m in [3usize, 30] {
            let d = savgol_second_derivative(&noise, h, m);
            let var =
                d[m..d.len() - m].iter().map(|v| v * v).sum::<f64>() / (d.len() - 2 * m) as f64;
            let mf = m as f64;
            let sum_c2 =
                mf * (mf + 1.0) * (2.0 * mf + 1.0) * (2.0 * mf + 3.0) * (2.0 * mf - 1.0) / 45.0;
            let expected = 4.0 / (sum_c2 * h.powi(4));
            assert!(
                (var / expected - 1.0).abs() < 0.05,
                "m = {m}: {var} against {expected}"
            );
        }
    }

    #[test]
    fn the_kinematic_ripples_fundamental_is_that_of_a_periodic_parabola() {
        // For odd z the shape is a cosine cap over π/z, nearly a parabola between cusps: a
        // periodic parabola's fundamental is 4/π² ≈ 0.405 of its peak-to-peak.
        let r = ripple_fundamental_per_ratio(&Rig::nominal(), 9);
        assert!((r - 4.0 / (PI * PI)).abs() < 0.01, "{r}");
    }

    #[test]
    fn a_steady_hold_needs_the_pumps_torque_over_the_torque_constant() {
        // 5 MPa across the pump at a constant 5 rad/s: i_q = (D/2π·Δp + B·ω)/K_t.
        let rig = Rig::nominal();
        let n = 200;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let mut log = crate::bench_log::BenchLog {
            metadata: Vec::new(),
            t_s: t.clone(),
            p_ref_pa: vec![5.5e6; n],
            p_pa: vec![5.5e6; n],
            speed_rad_s: vec![5.0; n],
            iq_a: vec![1.0; n],
            id_a: vec![0.0; n],
            theta_m_rad: Some(t.iter().map(|t| 5.0 * t).collect()),
            x_m: None,
            p_low_pa: Some(vec![0.5e6; n]),
            speed_ref_rad_s: None,
            iq_ref_a: None,
            ud_v: None,
            uq_v: None,
            udc_v: None,
            oil_temp_c: None,
        };
        log.metadata.clear();
        let facts = LogFacts::of(&log, &rig);
        let motion = ShaftMotion::of(&log, &facts, rig.motor.pole_pairs);
        let mech = Mechanics::new(MechanicalParams::nominal(&rig));
        let mut out = vec![0.0; n];
        mech.needed_current(&log, &facts, &motion, 0..n, &mut out);
        let kt = 1.5 * 4.0 * 0.1827;
        let expected = (1.5e-6 / (2.0 * PI) * 5e6 + 3.035e-4 * 5.0) / kt;
        assert!(
            (out[100] - expected).abs() < 1e-9,
            "{} vs {expected}",
            out[100]
        );
    }
}
