//! Pressure loop: the hydraulic capacitance the pump works into, identified from a pressure
//! step with the cylinder blocked, and the pressure loop's gain schedule corrected for it.
//!
//! ## Identification (paper eq. 22–26; `firmware::pressure_loop`)
//!
//! With the cylinder blocked the pump's delivery `K_q·ω` (`K_q = D_p/2π`) is stored in the
//! oil and the absorber's gas, or leaks: `C(p)·dp/dt = K_q·ω − G·p` with
//! `C(p) = C_oil + C_acc(p)`. Integrated from the log's first sample `t_a` (no
//! differentiation of a noisy pressure), the stored volume is
//!
//! ```text
//! K_q·∫ω dt − V_0·(g(p_a) − g(p)) = C_oil·(p − p_a) + G·∫p dt,
//! g(p) = ((p_0 + p_atm)/(p + p_atm))^(1/n) above the precharge p_0, 1 below
//! ```
//!
//! (`V_0·g` is the gas volume of the polytropic law, eq. 23–24, absolute pressures). For a
//! given precharge `p_0` this is linear in `(C_oil, G)` and solved by least squares; `p_0`
//! itself minimises the residual: a scan over `[0, p_max]` brackets it and Brent's method
//! (`argmin`) refines it. The shell volume `V_0` and exponent `n` are the rig's (the
//! nameplate; the precharge is what drifts — and `V_0` and `p_0` are not separable when the
//! whole log is above the precharge). When the absorber took no oil in the log (the fitted
//! precharge at the log's highest pressure) only a lower bound is known: the precharge is
//! above every pressure the log reached.
//!
//! ## Proposal
//!
//! The pressure loop schedules `Kp(p) = ω_c·C(p)/K_q`, `Ki = ω_i·Kp` from the capacitance
//! it *assumes*; the loop gain is right when the assumption is. So the proposal first
//! corrects the assumed precharge to the identified one (the parameter that moves the
//! capacitance about sixty-fold), keeps the documented `ω_c`, `ω_i/ω_c`, and changes those
//! only as far as the closed-loop replay on the identified plant needs to meet the target
//! ([`super::candidates`]). The equivalent gains reported are the schedule's at the step's
//! final setpoint.

use super::candidates::{self, Candidate, Design};
use super::fit::{least_squares, Fit};
use super::gains::Gains;
use super::predict::StepSpec;
use super::step::{centred_mean, Signal, Step, Target};
use crate::bench_log::BenchLog;
use argmin::core::{CostFunction, Executor};
use argmin::solver::brent::BrentOpt;
use firmware::config::{Config, Hydraulics};
use firmware::pressure_loop::{capacitance, PressureLoop, ATMOSPHERE_PA};
use plant_model::Rig;

/// Crossovers tried, as multiples of the configured `ω_c`. [1]
const BANDWIDTH_FACTORS: [f64; 5] = [1.0, 0.75, 1.25, 0.5, 1.5];
/// Integral corners tried, as multiples of the configured `ω_i/ω_c`. [1]
const CORNER_FACTORS: [f64; 4] = [1.0, 0.6, 0.4, 1.4];
/// Points of the precharge scan over `[0, p_max]`.
const SCAN_POINTS: usize = 48;
/// Most rows the identification uses (the log is decimated evenly beyond).
const MAX_ROWS: usize = 4000;
/// Largest piston travel over the log for the cylinder to count as blocked. [m]
const BLOCKED_TRAVEL_M: f64 = 1e-4;

/// The high-pressure side as identified from the log.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HighSide {
    /// Oil capacitance `V_oil/β`. [m³/Pa]
    pub oil_capacitance_m3_per_pa: f64,
    /// Leakage conductance G. [(m³/s)/Pa]
    pub leakage_m3_per_s_pa: f64,
    /// Absorber precharge (gauge); a lower bound when `precharge_is_lower_bound`. [Pa]
    pub precharge_pa: f64,
    /// The absorber took no oil in the log: its precharge is above `precharge_pa`, the
    /// log's highest pressure.
    pub precharge_is_lower_bound: bool,
    /// Highest (smoothed) pressure of the log. [Pa]
    pub max_pressure_pa: f64,
    /// Fit of the stored-volume balance: `100·(1 − ‖r‖/‖b − mean b‖)`. [%]
    pub fit_percent: f64,
}

/// The log's samples the balance is written on.
struct Balance {
    /// Pressure (smoothed). [Pa]
    p: Vec<f64>,
    /// `K_q·∫ω dt` since the first sample. [m³]
    pumped: Vec<f64>,
    /// `∫p dt` since the first sample. [Pa·s]
    int_p: Vec<f64>,
    /// Absorber shell volume (0: none). [m³]
    v0: f64,
    /// Polytropic exponent. [1]
    n: f64,
}

impl Balance {
    /// Gas volume fraction `V_gas/V_0` at gauge pressure `p` for precharge `p0`.
    fn gas_fraction(&self, p: f64, p0: f64) -> f64 {
        if p <= p0 {
            1.0
        } else {
            ((p0 + ATMOSPHERE_PA as f64) / (p + ATMOSPHERE_PA as f64)).powf(1.0 / self.n)
        }
    }

    /// Least-squares `(C_oil, G)` for precharge `p0`.
    fn fit(&self, p0: f64) -> Result<Fit, String> {
        let pa = self.p[0];
        let g_a = self.gas_fraction(pa, p0);
        let mut rows = Vec::with_capacity(2 * self.p.len());
        let mut rhs = Vec::with_capacity(self.p.len());
        for k in 1..self.p.len() {
            rows.extend_from_slice(&[self.p[k] - pa, self.int_p[k]]);
            rhs.push(self.pumped[k] - self.v0 * (g_a - self.gas_fraction(self.p[k], p0)));
        }
        least_squares(rhs.len(), 2, &rows, &rhs)
    }
}

/// The balance's residual as a function of the precharge, for `argmin`.
struct PrechargeCost<'a>(&'a Balance);

impl CostFunction for PrechargeCost<'_> {
    type Param = f64;
    type Output = f64;

    fn cost(&self, p0: &f64) -> Result<f64, argmin::core::Error> {
        Ok(self.0.fit(*p0).map_or(f64::INFINITY, |f| f.residual_ss))
    }
}

/// Fits [`HighSide`] over the whole log (the hold before the step shows the leakage, the
/// step the capacitance), with the pump and the absorber's shell from `rig`.
pub fn identify(rig: &Rig, log: &BenchLog) -> Result<HighSide, String> {
    if let Some(x) = &log.x_m {
        let (lo, hi) = x
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(*v), b.max(*v))
            });
        if hi - lo > BLOCKED_TRAVEL_M {
            return Err(format!(
                "the piston moved {:.1} mm during the log (x_m): the pressure loop is \
                 identified with the cylinder blocked",
                (hi - lo) * 1e3
            ));
        }
    }
    let k_q = rig.pump.displacement_m3_per_rev / std::f64::consts::TAU;
    let t = &log.t_s;
    let p_smooth = centred_mean(t, &log.p_pa, Signal::Pressure.smoothing_s());
    let stride = log.len().div_ceil(MAX_ROWS).max(1);
    let (mut p, mut pumped, mut int_p) = (Vec::new(), Vec::new(), Vec::new());
    let (mut vol, mut ip) = (0.0, 0.0);
    for k in 0..log.len() {
        if k > 0 {
            let dt = t[k] - t[k - 1];
            vol += k_q * 0.5 * dt * (log.speed_rad_s[k] + log.speed_rad_s[k - 1]);
            ip += 0.5 * dt * (p_smooth[k] + p_smooth[k - 1]);
        }
        if k % stride == 0 {
            p.push(p_smooth[k]);
            pumped.push(vol);
            int_p.push(ip);
        }
    }
    let balance = Balance {
        p,
        pumped,
        int_p,
        v0: if rig.absorber.enabled {
            rig.absorber.shell_volume_m3
        } else {
            0.0
        },
        n: rig.absorber.polytropic_exponent,
    };
    let p_max = balance.p.iter().copied().fold(0.0, f64::max);
    let (p0, lower_bound) = if balance.v0 > 0.0 {
        fit_precharge(&balance, p_max)?
    } else {
        (p_max, true)
    };
    let fit = balance.fit(p0)?;
    let high = HighSide {
        oil_capacitance_m3_per_pa: fit.x[0],
        leakage_m3_per_s_pa: fit.x[1],
        precharge_pa: p0,
        precharge_is_lower_bound: lower_bound,
        max_pressure_pa: p_max,
        fit_percent: fit.fit_percent,
    };
    if !(high.oil_capacitance_m3_per_pa.is_finite() && high.oil_capacitance_m3_per_pa > 0.0) {
        return Err(format!(
            "the pressure log gives no positive oil capacitance (fit: {:.3e} m³/Pa): its \
             speed and pressure do not follow C·dp/dt = K_q·ω − G·p with the cylinder blocked",
            high.oil_capacitance_m3_per_pa
        ));
    }
    Ok(high)
}

/// The precharge minimising the balance's residual, and whether it is only a lower bound.
fn fit_precharge(balance: &Balance, p_max: f64) -> Result<(f64, bool), String> {
    let step = p_max / (SCAN_POINTS - 1) as f64;
    let scan: Vec<(f64, f64)> = (0..SCAN_POINTS)
        .map(|i| {
            let p0 = i as f64 * step;
            (p0, balance.fit(p0).map_or(f64::INFINITY, |f| f.residual_ss))
        })
        .collect();
    let best = scan
        .iter()
        .enumerate()
        .min_by(|a, b| a.1 .1.total_cmp(&b.1 .1))
        .map_or(0, |(i, _)| i);
    let lo = scan[best.saturating_sub(1)].0;
    let hi = scan[(best + 1).min(SCAN_POINTS - 1)].0;
    let p0 = if hi > lo {
        let solver = BrentOpt::new(lo, hi).set_tolerance(1e-8, 10.0);
        let res = Executor::new(PrechargeCost(balance), solver)
            .configure(|s| s.max_iters(100))
            .run()
            .map_err(|e| format!("precharge fit: {e}"))?;
        res.state().best_param.unwrap_or(scan[best].0)
    } else {
        scan[best].0
    };
    // Within a scan step of the top: the gas never compressed, the precharge is above.
    if p0 >= p_max - step {
        Ok((p_max, true))
    } else {
        Ok((p0, false))
    }
}

/// The controller's hydraulics with the identified high side.
pub fn identified_hydraulics(assumed: &Hydraulics, high: &HighSide) -> Hydraulics {
    Hydraulics {
        oil_volume_m3: (high.oil_capacitance_m3_per_pa * assumed.bulk_modulus_pa as f64) as f32,
        absorber_precharge_pa: high.precharge_pa as f32,
        leakage_m3_per_s_pa: high.leakage_m3_per_s_pa.max(0.0) as f32,
        ..*assumed
    }
}

/// Capacitance of `h` at gauge pressure `p`. [m³/Pa]
pub fn capacitance_at(h: &Hydraulics, p: f64) -> f64 {
    capacitance(h, p as f32) as f64
}

/// The schedule's gains of `config` at gauge pressure `p`.
pub fn gains_at(config: &Config, p: f64) -> Gains {
    let g = PressureLoop::new(config).gains_at(p as f32);
    Gains {
        kp: g.kp as f64,
        ki: g.ki as f64,
    }
}

/// The rig with the identified high side: oil volume, precharge and leakage (the rig's
/// three leakage paths scaled together).
pub fn identified_rig(rig: &Rig, high: &HighSide) -> Rig {
    let mut r = rig.clone();
    r.cylinder.chamber_a_volume_m3 = high.oil_capacitance_m3_per_pa * rig.oil.bulk_modulus_pa;
    // The identification and the step's replay hold the piston blocked at mid-stroke, where
    // the stroke does not matter; an oil volume below the half-stroke's swept volume is kept
    // simulatable by a shorter stroke (the model refuses a chamber that would vanish at its
    // end stop).
    let half_stroke_fits = 0.5 * r.cylinder.chamber_a_volume_m3 / r.cylinder.area_m2;
    if r.cylinder.half_stroke_m >= half_stroke_fits {
        r.cylinder.half_stroke_m = half_stroke_fits;
    }
    r.absorber.precharge_pa = high.precharge_pa;
    let g0 = rig.pump.internal_leakage_m3_s_pa
        + rig.pump.external_leakage_m3_s_pa
        + rig.cylinder.internal_leakage_m3_s_pa;
    if g0 > 0.0 {
        let f = high.leakage_m3_per_s_pa.max(0.0) / g0;
        r.pump.internal_leakage_m3_s_pa *= f;
        r.pump.external_leakage_m3_s_pa *= f;
        r.cylinder.internal_leakage_m3_s_pa *= f;
    }
    r
}

/// The configuration assuming precharge `p0` [Pa] with crossover `bandwidth` [rad/s] and
/// integral corner ratio `corner` [1].
pub fn with_schedule(config: &Config, p0: f64, bandwidth: f64, corner: f64) -> Config {
    let mut c = *config;
    c.hydraulics.absorber_precharge_pa = p0 as f32;
    c.pressure.bandwidth_rad_s = bandwidth as f32;
    c.pressure.integral_corner_ratio = corner as f32;
    c
}

/// Designs the proposal: the precharge corrected, then the documented `(ω_c, ω_i/ω_c)` or
/// the nearest grid point whose replay on the identified plant meets `target`.
pub fn propose(
    rig: &Rig,
    config: &Config,
    high: &HighSide,
    spec: &StepSpec,
    target: &Target,
) -> Result<Candidate, String> {
    let w0 = config.pressure.bandwidth_rad_s as f64;
    let r0 = config.pressure.integral_corner_ratio as f64;
    let designs = BANDWIDTH_FACTORS
        .iter()
        .flat_map(|fw| {
            CORNER_FACTORS
                .iter()
                .map(move |fr| (w0 * fw, (r0 * fr).min(1.0)))
        })
        .map(|(w, r)| {
            let c = with_schedule(config, high.precharge_pa, w, r);
            Design {
                point: (w, r),
                config: c,
                gains: gains_at(&c, spec.to),
            }
        })
        .filter(|d| d.config.validate().is_ok())
        .collect();
    let tried = candidates::replay(&identified_rig(rig, high), spec, designs);
    candidates::choose(tried, (w0, r0), target)
        .ok_or_else(|| "no pressure-loop design could be simulated".to_string())
}

/// The longest time the speed reference stayed at its limit in the step's direction
/// during the step. [s]
pub fn longest_at_speed_limit(log: &BenchLog, step: &Step, limit: f64) -> f64 {
    let Some(w_ref) = &log.speed_ref_rad_s else {
        return 0.0;
    };
    let sign = (step.to - step.from).signum();
    let (mut longest, mut since) = (0.0_f64, None);
    let window = step.start..step.end;
    for (w, t) in w_ref[window.clone()].iter().zip(&log.t_s[window]) {
        if sign * w >= 0.99 * limit {
            let s = *since.get_or_insert(*t);
            longest = longest.max(t - s);
        } else {
            since = None;
        }
    }
    longest
}
