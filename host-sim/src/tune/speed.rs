//! Speed loop: the shaft identified from a speed step, and speed-PI gains designed for it.
//!
//! ## Identification (paper eq. 4–5, 9)
//!
//! The shaft obeys `J·dω/dt = T_e − K_q·(p − p_low) − B·ω − T_0` with the motor torque
//! `T_e = 1.5·p_n·(ψ_f·i_q + (L_d − L_q)·i_d·i_q)` (eq. 5, from the logged currents and the
//! rig's motor), the pump's torque `K_q·Δp` (eq. 9, `K_q = D_p/2π`; the low side taken at
//! 0 Pa gauge when `p_low_pa` is not logged), viscous friction `B` and a constant load `T_0`.
//! Integrated from the step's start `t_a` (no differentiation of a quantised speed):
//!
//! ```text
//! J·(ω(t) − ω(t_a)) + B·∫ω dt + T_0·(t − t_a) = ∫(T_e − K_q·Δp) dt
//! ```
//!
//! is linear in `(J, B, T_0)` and solved by least squares (SVD, `nalgebra`) over the step's
//! window.
//!
//! ## Design
//!
//! With an ideal current loop the speed loop `i_q* = Kp·e + Ki·∫e − Ba·ω` closes to
//! `J·s² + (B + K_t·(Kp + Ba))·s + K_t·Ki = 0` (see `firmware::speed_loop`). The firmware's
//! design (Table 1 gains on the rig's J, B) has natural frequency ω₀ and damping ζ₀; the
//! proposal places the identified shaft's poles at `(ω, ζ)`:
//!
//! ```text
//! Kp = (2·ζ·ω·J − B)/K_t − Ba,   Ki = ω²·J/K_t
//! ```
//!
//! starting from `(ω₀, ζ₀)` — the documented design transferred to the shaft actually
//! there — and, when the closed-loop replay on the identified shaft misses the target, the
//! nearest `(ω, ζ)` of a fixed grid around it that meets it (more damping for less
//! overshoot, more bandwidth for a shorter settling).

use super::candidates::{self, Candidate, Design};
use super::fit::least_squares;
use super::gains::Gains;
use super::predict::StepSpec;
use super::step::{Step, Target};
use crate::bench_log::BenchLog;
use firmware::config::Config;
use plant_model::Rig;

/// Damping ratios tried, as multiples of the design's ζ₀. [1]
const ZETA_FACTORS: [f64; 6] = [1.0, 1.2, 1.4, 1.7, 2.0, 2.5];
/// Natural frequencies tried, as multiples of the design's ω₀. [1]
const OMEGA_FACTORS: [f64; 5] = [1.0, 1.3, 0.77, 1.7, 0.6];

/// The shaft as identified from the log.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shaft {
    /// Total inertia J (motor + pump). [kg·m²]
    pub inertia_kg_m2: f64,
    /// Viscous friction B. [N·m·s]
    pub viscous_nm_s: f64,
    /// Constant load torque T_0. [N·m]
    pub load_nm: f64,
    /// How much of the integrated torque balance the fit explains:
    /// `100·(1 − ‖r‖/‖b − mean b‖)`. [%]
    pub fit_percent: f64,
}

/// Fits [`Shaft`] over the samples `step.start..step.end` of `log` (torque constant and
/// displacement from `rig`).
pub fn identify(rig: &Rig, log: &BenchLog, step: &Step) -> Result<Shaft, String> {
    let m = &rig.motor;
    let k_q = rig.pump.displacement_m3_per_rev / std::f64::consts::TAU;
    let (a, b) = (step.start, step.end);
    if b - a < 20 {
        return Err(format!(
            "the speed step's window has {} samples; at least 20 are needed",
            b - a
        ));
    }
    let t = &log.t_s;
    let w = &log.speed_rad_s;
    let torque = |k: usize| {
        let te = 1.5
            * m.pole_pairs as f64
            * (m.psi_f_wb * log.iq_a[k] + (m.l_d_h - m.l_q_h) * log.id_a[k] * log.iq_a[k]);
        let p_low = log.p_low_pa.as_ref().map_or(0.0, |c| c[k]);
        te - k_q * (log.p_pa[k] - p_low)
    };
    let n = b - a - 1;
    let mut rows = Vec::with_capacity(3 * n);
    let mut rhs = Vec::with_capacity(n);
    let (mut int_w, mut int_t) = (0.0, 0.0);
    let mut prev_torque = torque(a);
    for k in a + 1..b {
        let dt = t[k] - t[k - 1];
        let tk = torque(k);
        int_w += 0.5 * dt * (w[k] + w[k - 1]);
        int_t += 0.5 * dt * (tk + prev_torque);
        prev_torque = tk;
        rows.extend_from_slice(&[w[k] - w[a], int_w, t[k] - t[a]]);
        rhs.push(int_t);
    }
    let theta = least_squares(n, 3, &rows, &rhs)?;
    let shaft = Shaft {
        inertia_kg_m2: theta.x[0],
        viscous_nm_s: theta.x[1],
        load_nm: theta.x[2],
        fit_percent: theta.fit_percent,
    };
    if !(shaft.inertia_kg_m2.is_finite() && shaft.inertia_kg_m2 > 0.0) {
        return Err(format!(
            "the speed step gives no positive inertia (fit: J = {:.3e} kg·m²): the log's \
             current and speed do not follow J·dω/dt = T_e − load",
            shaft.inertia_kg_m2
        ));
    }
    Ok(shaft)
}

/// Samples of the log between the speed's 10 % and 90 % crossings of the step: the
/// acceleration the inertia is identified from. A handful cannot resolve it (the torque
/// integral of a sub-sample current pulse is not known).
pub fn rise_samples(log: &BenchLog, step: &Step) -> usize {
    let size = step.to - step.from;
    let frac = |k: usize| (log.speed_rad_s[k] - step.from) / size;
    let window = step.start..step.end;
    let first = |level: f64| window.clone().find(|&k| frac(k) >= level);
    match (first(0.1), first(0.9)) {
        (Some(a), Some(b)) if b >= a => b - a,
        _ => 0,
    }
}

/// Samples of acceleration below which the identified inertia is flagged as uncertain.
pub const MIN_RISE_SAMPLES: usize = 10;

/// Natural frequency [rad/s] and damping ratio [1] of the speed loop `config` closes on a
/// shaft of inertia `j` and viscous friction `b`, with torque constant `k_t`.
pub fn poles(config: &Config, k_t: f64, j: f64, b: f64) -> (f64, f64) {
    let s = &config.speed;
    let omega = (k_t * s.ki as f64 / j).sqrt();
    let zeta = (b + k_t * (s.kp + s.active_damping) as f64) / (2.0 * j * omega);
    (omega, zeta)
}

/// The gains placing the loop's poles at `(omega, zeta)` on `shaft`.
pub fn gains_for(config: &Config, k_t: f64, shaft: &Shaft, omega: f64, zeta: f64) -> Gains {
    let j = shaft.inertia_kg_m2;
    Gains {
        kp: (2.0 * zeta * omega * j - shaft.viscous_nm_s.max(0.0)) / k_t
            - config.speed.active_damping as f64,
        ki: omega * omega * j / k_t,
    }
}

/// The rig with the identified shaft (inertia split between motor and pump as the rig
/// splits it; negative fitted friction taken as none).
pub fn identified_rig(rig: &Rig, shaft: &Shaft) -> Rig {
    let mut r = rig.clone();
    let j0 = rig.shaft.inertia_kg_m2();
    let motor_share = rig.shaft.motor_inertia_kg_m2 / j0;
    r.shaft.motor_inertia_kg_m2 = shaft.inertia_kg_m2 * motor_share;
    r.shaft.pump_inertia_kg_m2 = shaft.inertia_kg_m2 * (1.0 - motor_share);
    r.shaft.viscous_nm_s = shaft.viscous_nm_s.max(0.0);
    r
}

/// The configuration with speed gains `g`.
pub fn with_gains(config: &Config, g: &Gains) -> Config {
    let mut c = *config;
    c.speed.kp = g.kp as f32;
    c.speed.ki = g.ki as f32;
    c
}

/// Designs the proposal: the documented design's `(ω₀, ζ₀)` on the identified shaft, or
/// the nearest grid point whose replay on the identified shaft meets `target`.
pub fn propose(
    rig: &Rig,
    config: &Config,
    shaft: &Shaft,
    spec: &StepSpec,
    target: &Target,
) -> Result<Candidate, String> {
    let k_t = rig.motor.torque_constant_nm_per_a();
    let (w0, z0) = poles(
        config,
        k_t,
        rig.shaft.inertia_kg_m2(),
        rig.shaft.viscous_nm_s,
    );
    let designs = OMEGA_FACTORS
        .iter()
        .flat_map(|fw| ZETA_FACTORS.iter().map(move |fz| (w0 * fw, z0 * fz)))
        .filter_map(|(w, z)| {
            let gains = gains_for(config, k_t, shaft, w, z);
            (gains.kp > 0.0 && gains.ki >= 0.0).then(|| Design {
                point: (w, z),
                config: with_gains(config, &gains),
                gains,
            })
        })
        .collect();
    let tried = candidates::replay(&identified_rig(rig, shaft), spec, designs);
    candidates::choose(tried, (w0, z0), target)
        .ok_or_else(|| "no speed-loop design could be simulated".to_string())
}
