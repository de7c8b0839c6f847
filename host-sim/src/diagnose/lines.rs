//! Angle-locked lines: least squares on sin/cos of k·θ (lock-in) over each steady-rotation
//! window, for the orders the catalogue's periodic effects live at and their neighbours,
//! whose lines measure the noise floor a line must stand above.
//!
//! Per window and order k the signals' complex amplitudes Z (y ≈ Re(Z·e^{jkθ})) give the
//! torque line the shaft balance leaves unexplained (eq. 4 at one order, the speed steady):
//!
//! ```text
//!   T_k = K_t·I_q,k + J·(k·ω̄)²·Θ_k − D/2π·P_k
//! ```
//!
//! with I_q,k, Θ_k, P_k the lines of the q current, the detrended angle and the pressure:
//! the angle's line is the shaft's oscillation, J·(kω̄)² turns it into the torque that
//! accelerated it, and the pump's torque follows the pressure's line. A torque effect
//! (cogging, flux harmonics, the pump's torque ripple, the torque a current-sensor offset
//! hides) leaves T_k; a voltage disturbance (dead time) moves current and angle together
//! and leaves T_k near zero while the d current shows its line.

use crate::bench_log::BenchLog;
use crate::diagnose::count_lines::{rms_over_shifts, rounding_errors};
use crate::diagnose::facts::LogFacts;
use crate::diagnose::lock_in::lock_in;
use crate::diagnose::steady::SteadyWindow;
use plant_model::inverter::{dq_to_abc, pole_to_dq, Inverter};
use plant_model::Rig;
use rustfft::num_complex::Complex64;

/// Neighbouring orders on each side of a line whose amplitudes measure its noise floor.
pub const NEIGHBOURS: u32 = 4;

/// The lines of one steady window.
#[derive(Clone, Debug)]
pub struct WindowLines {
    /// The window.
    pub window: SteadyWindow,
    /// Mean q current. [A]
    pub iq_mean_a: f64,
    /// Mean d current. [A]
    pub id_mean_a: f64,
    /// Mean pressure difference across the pump. [Pa]
    pub dp_mean_pa: f64,
    /// Per analysed order: the lines.
    pub orders: Vec<OrderLines>,
}

/// The lines at one order in one window.
#[derive(Clone, Debug)]
pub struct OrderLines {
    /// Cycles per revolution.
    pub order: u32,
    /// q current. [A]
    pub iq: Complex64,
    /// d current. [A]
    pub id: Complex64,
    /// Detrended angle. [rad]
    pub theta: Complex64,
    /// RMS of the angle line the encoder's counts alone leave at this order
    /// ([`super::count_lines`]); zero where the angle lies on no count lattice. [rad]
    pub theta_counts: f64,
    /// Pressure. [Pa]
    pub p: Complex64,
    /// Unexplained torque T_k. [N·m]
    pub torque: Complex64,
    /// Commanded d and q voltages, when logged. [V]
    pub voltages: Option<[Complex64; 2]>,
    /// The d and q lines of the dead-time voltage the logged currents make, per fade band
    /// of [`DEAD_TIME_BANDS_A`] at [`REFERENCE_DEAD_TIME_S`] (empty without the angle). [V]
    pub dead_time_voltages: Vec<[Complex64; 2]>,
}

impl WindowLines {
    /// The lines at `order`, if analysed.
    pub fn at(&self, order: u32) -> Option<&OrderLines> {
        self.orders.iter().find(|o| o.order == order)
    }

    /// Noise variance per real component of a line of `value` at `order` (mean of |Z|²/2
    /// over the neighbouring orders that are not themselves candidates). [unit²]
    pub fn floor(
        &self,
        order: u32,
        candidates: &[u32],
        value: impl Fn(&OrderLines) -> Complex64,
    ) -> f64 {
        let mut sum = 0.0;
        let mut n = 0usize;
        for d in 1..=NEIGHBOURS {
            for k in [order.saturating_sub(d), order + d] {
                if k == 0 || candidates.contains(&k) {
                    continue;
                }
                if let Some(o) = self.at(k) {
                    sum += value(o).norm_sqr() / 2.0;
                    n += 1;
                }
            }
        }
        if n == 0 {
            f64::INFINITY
        } else {
            (sum / n as f64).max(f64::MIN_POSITIVE)
        }
    }
}

/// Dead time the dead-time voltage lines are computed for (they scale with it). [s]
pub const REFERENCE_DEAD_TIME_S: f64 = 1e-6;

/// Current bands of the dead-time error's fade tried (the rig contract does not give it). [A]
pub const DEAD_TIME_BANDS_A: [f64; 7] = [0.01, 0.05, 0.1, 0.2, 0.3, 0.5, 0.8];

/// The d and q dead-time voltage over `rows` per fade band of [`DEAD_TIME_BANDS_A`], at
/// [`REFERENCE_DEAD_TIME_S`]: the logged d-q currents turned into phase currents at the
/// electrical angle p_n·θ, each leg's error −t_d·f_pwm·U_dc·sat(i/band) (the plant's
/// [`Inverter`]) turned back into d-q. Read from the currents that flowed, not from their
/// mean: the current line the dead time causes moves the phase currents' zero crossings,
/// and with them the voltage it makes. The logged DC link is used where present. [V]
pub fn dead_time_voltage(
    log: &BenchLog,
    facts: &LogFacts,
    rig: &Rig,
    rows: std::ops::Range<usize>,
) -> Vec<(Vec<f64>, Vec<f64>)> {
    let pp = rig.motor.pole_pairs as f64;
    DEAD_TIME_BANDS_A
        .iter()
        .map(|&band| {
            let mut p = rig.inverter.clone();
            p.dead_time_s = REFERENCE_DEAD_TIME_S;
            p.dead_time_current_band_a = band;
            let mut inv = Inverter::new(&p);
            let (mut d, mut q) = (
                Vec::with_capacity(rows.len()),
                Vec::with_capacity(rows.len()),
            );
            for k in rows.clone() {
                if let Some(u) = log.udc_v.as_deref() {
                    inv.set_u_dc(u[k]);
                }
                let (s, c) = (pp * facts.theta_rad[k]).sin_cos();
                let i = dq_to_abc(log.id_a[k], log.iq_a[k], s, c);
                let (ud, uq) = pole_to_dq(&inv.pole_voltages(&[0.0; 3], &i), s, c);
                d.push(ud);
                q.push(uq);
            }
            (d, q)
        })
        .collect()
}

/// The orders to analyse: each candidate and its neighbours, without order 0 and above the
/// window's Nyquist order.
fn analysed_orders(candidates: &[u32], max_order: u32) -> Vec<u32> {
    let mut v: Vec<u32> = candidates
        .iter()
        .flat_map(|&k| k.saturating_sub(NEIGHBOURS)..=k + NEIGHBOURS)
        .filter(|k| *k > 0 && *k <= max_order)
        .collect();
    v.sort_unstable();
    v.dedup();
    v
}

/// The lines of every steady window at `candidates` (and their neighbours), with the
/// shaft's torque constant, inertia and displacement `kt`, `j`, `d_per_rad` (D/2π).
pub fn window_lines(
    log: &BenchLog,
    facts: &LogFacts,
    rig: &Rig,
    candidates: &[u32],
    kt: f64,
    j: f64,
    d_per_rad: f64,
) -> Vec<WindowLines> {
    let t = &log.t_s;
    let theta = &facts.theta_rad;
    facts
        .steady
        .iter()
        .filter_map(|w| {
            let rows = w.rows.clone();
            // Highest order whose line stays below a third of the sampling rate.
            let w_abs = w.speed_rad_s.abs().max(1e-9);
            let max_order = ((2.0 * std::f64::consts::PI / facts.period_s) / 3.0 / w_abs) as u32;
            let orders = analysed_orders(candidates, max_order);
            if orders.is_empty() {
                return None;
            }
            let trend: Vec<f64> = {
                // The angle less its straight line: the shaft's oscillation about the mean
                // rotation.
                let (a, b) = (theta[rows.start], theta[rows.end - 1]);
                let (ta, tb) = (t[rows.start], t[rows.end - 1]);
                rows.clone()
                    .map(|k| theta[k] - (a + (b - a) * (t[k] - ta) / (tb - ta)))
                    .collect()
            };
            let mut signals: Vec<(&[f64], usize)> = vec![
                (&log.iq_a, 0),
                (&log.id_a, 0),
                (&trend, rows.start),
                (&log.p_pa, 0),
            ];
            let voltages = log.ud_v.as_deref().zip(log.uq_v.as_deref());
            if let Some((ud, uq)) = voltages {
                signals.extend([(ud, 0), (uq, 0)]);
            }
            // The inverter's dead-time voltage the logged currents make, per fade band
            // ([`dead_time_voltage`]): only where the angle places the phases.
            let dead_time = if facts.angle.is_logged() {
                dead_time_voltage(log, facts, rig, rows.clone())
            } else {
                Vec::new()
            };
            let first_dead = signals.len();
            for (d, q) in &dead_time {
                signals.extend([(d.as_slice(), rows.start), (q.as_slice(), rows.start)]);
            }
            // The encoder's rounding (`count_lines`), read in the same fit.
            let rounding = facts
                .angle_count_rad
                .and_then(|q| rounding_errors(t, theta, rows.clone(), q))
                .unwrap_or_default();
            let first_rounding = signals.len();
            signals.extend(rounding.iter().map(|e| (e.as_slice(), rows.start)));
            let z = lock_in(t, theta, rows.clone(), &orders, &signals)?;
            let counts = if rounding.is_empty() {
                vec![0.0; orders.len()]
            } else {
                rms_over_shifts(&z[first_rounding..])
            };
            let lines = orders
                .iter()
                .enumerate()
                .map(|(m, &order)| {
                    let (iq, id, th, p) = (z[0][m], z[1][m], z[2][m], z[3][m]);
                    let wk = order as f64 * w_abs;
                    OrderLines {
                        order,
                        iq,
                        id,
                        theta: th,
                        theta_counts: counts[m],
                        p,
                        torque: iq * kt + th * (j * wk * wk) - p * d_per_rad,
                        voltages: voltages.map(|_| [z[4][m], z[5][m]]),
                        dead_time_voltages: (0..dead_time.len())
                            .map(|b| [z[first_dead + 2 * b][m], z[first_dead + 2 * b + 1][m]])
                            .collect(),
                    }
                })
                .collect();
            let mean = |y: &[f64]| y[rows.clone()].iter().sum::<f64>() / rows.len() as f64;
            Some(WindowLines {
                window: w.clone(),
                iq_mean_a: mean(&log.iq_a),
                id_mean_a: mean(&log.id_a),
                dp_mean_pa: mean(&log.p_pa) - {
                    let low = facts.p_low(log);
                    rows.clone().map(|k| low.at(k)).sum::<f64>() / rows.len() as f64
                },
                orders: lines,
            })
        })
        .collect()
}
