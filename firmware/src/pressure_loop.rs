//! The pressure loop (not in the paper's Table 1; the plant is Section 3.2–3.3's pump,
//! chamber and absorber, eq. 22–26): PI from pressure error to the speed reference, gain
//! scheduled on the hydraulic capacitance, with a setpoint ramp and limits.
//!
//! ## Plant seen by the loop
//!
//! With the speed loop closed, the pump delivers `Q = K_q·ω` with `K_q = D_p/2π`
//! (2.39e-7 m³/rad) into the high-pressure side, whose pressure obeys
//! `C(p)·dp/dt = K_q·ω − G·p`, where
//!
//! ```text
//! C(p) = V_oil/β + C_acc(p),  C_acc = 0 below the precharge p_0,
//! C_acc = V_0·(p_0,abs/p_abs)^(1/n) / (n·p_abs) above it (absolute pressures)
//! ```
//!
//! On the nominal rig V_oil/β = 6.9e-13 m³/Pa, while C_acc ranges from 1.5e-10 (p_0 = 2 MPa,
//! at 2 MPa) down to 1.5e-11 (p_0 = 13 MPa at 15 MPa): the loop gain of a fixed PI would
//! change two-hundred-fold. The leakage pole G/C (G ≈ 3e-13 m³/(s·Pa)) is below 0.5 rad/s
//! everywhere, so the plant is an integrator `K_q/(C(p)·s)` at the loop's frequencies.
//!
//! ## Design: gain scheduling from C(p)
//!
//! `Kp(p) = ω_c·C(p)/K_q`, `Ki(p) = ω_i·Kp(p)` with ω_c = 20 rad/s (3.2 Hz) and
//! ω_i = ω_c/4, evaluated at the filtered measured pressure every pressure-loop step (a
//! local linearisation: the loop gain is `ω_c·(1 + ω_i/s)/s` at every operating point).
//! Gains change bumplessly ([`crate::pi::Pi::set_gains`]). Closed loop of the ideal loop:
//! `s² + ω_c·s + ω_c·ω_i = 0`, ω_n = 10 rad/s, ζ = 1.0; phase margin 76° before the
//! lags below.
//!
//! Lags, and why ω_c = 20 rad/s:
//! - the closed speed loop (poles −67, −143 rad/s, zero −50 rad/s, see
//!   [`crate::speed_loop`]): 3° at 20 rad/s;
//! - the feedback low-pass at ω_f = 150 rad/s: 7.6°; the boxcar mean over the pressure
//!   period (anti-aliasing of the pump's flow ripple) and the 1 kHz hold: about 1.5 ms of
//!   delay, 1.7°;
//! - the absorber's oil column (inlet inertance I = 3.85e5 kg/m⁴): above
//!   ω_a = 1/√(I·C_acc) (21–60 Hz) the absorber decouples and the chamber alone
//!   (C = V_oil/β) is seen up to its resonance 1/√(I·V_oil/β) ≈ 310 Hz. The scheduled
//!   gain, sized for the whole capacitance, is 100–200× too large for the chamber alone, so
//!   the loop must be far below ω_a and roll off before the chamber resonance: ω_c is
//!   ω_a/7 at worst, and the speed loop and the 150 rad/s filter together attenuate the
//!   loop gain at 310 Hz by about 300.
//!
//! Promised margins (checked by this module's tests on the linearised loop, with the speed
//! loop, current loop, filter, delay and the absorber's inertance, for precharges 2..13 MPa
//! and pressures 1..15 MPa): every closed-loop pole has ζ ≥ [`PROMISED_DAMPING`] (0.8; computed worst 0.89) except the
//! chamber's resonance against the absorber's oil column (about 310 Hz, open-loop
//! ζ = (R/I)/(2ω_r) ≈ 0.02 on the nominal rig), which the controller cannot damp but must
//! not erode: it keeps at least [`PROMISED_RESONANCE_DAMPING_RATIO`] of its open-loop ζ. Step responses: with the speed reference in its
//! limits, overshoot ≤ 15 % and 2 % settling ≤ 0.8 s; larger steps in the absorber's range
//! are speed-limited (a 3→5 MPa step at p_0 = 2 MPa needs ~130 pump revolutions).
//!
//! Feed-forward: the leakage flow `G·p*/K_q` and the ramp flow `C(p*)·ṗ*/K_q`, so the
//! integrator only corrects model error and a ramp is followed without lag. The setpoint is
//! ramped at `ramp_pa_per_s` toward the commanded value.

use crate::config::{Config, Hydraulics};
use crate::pi::{saturate, Pi};

/// Damping ratio promised for every closed-loop pole except the absorber resonance. [1]
pub const PROMISED_DAMPING: f64 = 0.8;
/// Fraction of its open-loop damping ratio the chamber/oil-column resonance keeps in
/// closed loop (the loop must not erode the plant's own damping). [1]
pub const PROMISED_RESONANCE_DAMPING_RATIO: f64 = 0.9;

/// Atmospheric pressure: the gas law holds in absolute pressure, as in the plant model.
/// [Pa]
pub const ATMOSPHERE_PA: f32 = 101_325.0;

/// Hydraulic capacitance of the high-pressure side at gauge pressure `p` [Pa]:
/// oil compressibility plus the absorber's gas above its precharge. [m³/Pa]
pub fn capacitance(h: &Hydraulics, p: f32) -> f32 {
    let oil = h.oil_volume_m3 / h.bulk_modulus_pa;
    if h.absorber_volume_m3 <= 0.0 || p.is_nan() || p <= h.absorber_precharge_pa {
        return oil;
    }
    let pa = p + ATMOSPHERE_PA;
    let p0a = h.absorber_precharge_pa + ATMOSPHERE_PA;
    let n = h.polytropic_exponent;
    let gas = h.absorber_volume_m3 * libm::powf(p0a / pa, 1.0 / n);
    oil + gas / (n * pa)
}

/// Proportional and integral gains of the schedule at pressure `p`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PressureGains {
    /// Proportional gain. [(rad/s)/Pa]
    pub kp: f32,
    /// Integral gain. [(rad/s)/(Pa·s)]
    pub ki: f32,
}

/// Pressure PI with its schedule, ramp and feedback filter.
#[derive(Clone, Copy, Debug)]
pub struct PressureLoop {
    pi: Pi,
    hydraulics: Hydraulics,
    k_q: f32,
    bandwidth: f32,
    corner_ratio: f32,
    filter_alpha: f32,
    ramp_step: f32,
    ramp_rate: f32,
    target: f32,
    ramped: f32,
    filtered: f32,
}

impl PressureLoop {
    /// From a validated configuration.
    pub fn new(cfg: &Config) -> PressureLoop {
        let t = 1.0 / cfg.rates.pressure_loop_hz;
        let p = &cfg.pressure;
        let lim = cfg.speed.speed_limit_rad_s;
        let mut pl = PressureLoop {
            pi: Pi::new(0.0, 0.0, t, -lim, lim),
            hydraulics: cfg.hydraulics,
            k_q: cfg.hydraulics.pump_displacement_m3_per_rev / core::f32::consts::TAU,
            bandwidth: p.bandwidth_rad_s,
            corner_ratio: p.integral_corner_ratio,
            filter_alpha: 1.0 - libm::expf(-p.feedback_filter_rad_s * t),
            ramp_step: p.ramp_pa_per_s * t,
            ramp_rate: p.ramp_pa_per_s,
            target: 0.0,
            ramped: 0.0,
            filtered: 0.0,
        };
        let g = pl.gains_at(0.0);
        pl.pi = Pi::new(g.kp, g.ki, t, -lim, lim);
        pl
    }

    /// Takes changed design parameters, hydraulic assumptions and the speed limit from
    /// `cfg` keeping the integral, the filter and the ramp state; the schedule's gains
    /// follow at the next step through [`Pi::set_gains`] (bumpless).
    pub fn retune(&mut self, cfg: &Config) {
        let t = 1.0 / cfg.rates.pressure_loop_hz;
        let p = &cfg.pressure;
        let lim = cfg.speed.speed_limit_rad_s;
        self.pi.set_limits(-lim, lim);
        self.hydraulics = cfg.hydraulics;
        self.k_q = cfg.hydraulics.pump_displacement_m3_per_rev / core::f32::consts::TAU;
        self.bandwidth = p.bandwidth_rad_s;
        self.corner_ratio = p.integral_corner_ratio;
        self.filter_alpha = 1.0 - libm::expf(-p.feedback_filter_rad_s * t);
        self.ramp_step = p.ramp_pa_per_s * t;
        self.ramp_rate = p.ramp_pa_per_s;
    }

    /// The schedule: gains at gauge pressure `p` [Pa].
    pub fn gains_at(&self, p: f32) -> PressureGains {
        let kp = self.bandwidth * capacitance(&self.hydraulics, p) / self.k_q;
        PressureGains {
            kp,
            ki: kp * self.corner_ratio * self.bandwidth,
        }
    }

    /// Sets the commanded (target) pressure; the loop ramps toward it. [Pa]
    pub fn set_target(&mut self, p: f32) {
        self.target = p;
    }

    /// Ramped setpoint currently in use. [Pa]
    pub fn setpoint(&self) -> f32 {
        self.ramped
    }

    /// Filtered measured pressure. [Pa]
    pub fn filtered(&self) -> f32 {
        self.filtered
    }

    /// Starts the loop at measured pressure `p` [Pa] and speed reference `speed` [rad/s]
    /// without a bump: the ramp starts from `p`, the integral from `speed`.
    pub fn reset(&mut self, p: f32, speed: f32) {
        self.ramped = p;
        self.filtered = p;
        let g = self.gains_at(p);
        self.pi.set_gains(g.kp, g.ki);
        self.pi.reset(speed);
    }

    /// One pressure-loop step with the measured pressure `p_meas` (mean over the period)
    /// [Pa]; returns the speed reference [rad/s].
    #[inline]
    pub fn step(&mut self, p_meas: f32) -> f32 {
        if p_meas.is_finite() {
            self.filtered += self.filter_alpha * (p_meas - self.filtered);
        }
        let prev = self.ramped;
        let d = saturate(self.target - self.ramped, -self.ramp_step, self.ramp_step);
        self.ramped += d;
        let ramp_rate = if self.ramped != prev {
            if d > 0.0 {
                self.ramp_rate
            } else {
                -self.ramp_rate
            }
        } else {
            0.0
        };
        let ramp_rate = if d.abs() < self.ramp_step {
            0.0
        } else {
            ramp_rate
        };
        let g = self.gains_at(self.filtered);
        self.pi.set_gains(g.kp, g.ki);
        let c_ref = capacitance(&self.hydraulics, self.ramped);
        let ff = (self.hydraulics.leakage_m3_per_s_pa * self.ramped + c_ref * ramp_rate) / self.k_q;
        self.pi.step(self.ramped - self.filtered, ff)
    }
}

#[cfg(test)]
mod tests;
