//! Stability margins of the loops with the commissioned gains, on the rig's true motor and
//! shaft: crossover, phase margin and gain margin of the open loop, found numerically on
//! the frequency axis (|L| falls and ∠L decreases monotonically for these loops).
//!
//! - Current loop (one axis, eq. 2 at standstill): L(s) = (Kp·s + Ki)/(s·(L·s + R_s)) ·
//!   e^{−s·1.5·T}, the 1.5 PWM periods being the computation delay (the voltage computed
//!   from one sample is applied over the next period) plus the half period of the
//!   zero-order hold.
//! - Speed loop (eq. 3–4 with the PI and active damping of [`firmware::speed_loop`]):
//!   L(s) = K_t·(Kp·s + Ki)/s · 1/(J·s + B + K_t·Ba) · 1/(1 + s/ω_c) · e^{−s·T_s}, with
//!   the closed current loop's first-order lag and one speed period T_s (half a period of
//!   hold plus half a period of measurement window).

use rustfft::num_complex::Complex64;
use serde::Serialize;

/// Margins of one open loop.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Margins {
    /// Gain crossover, |L(jω)| = 1. [rad/s]
    pub crossover_rad_s: f64,
    /// 180° + ∠L at the crossover. [°]
    pub phase_margin_deg: f64,
    /// −20·log₁₀|L| where ∠L = −180°. [dB]
    pub gain_margin_db: f64,
}

/// Margins of the open loop `l` over (1, 10⁶) rad/s.
pub fn margins(l: impl Fn(f64) -> Complex64) -> Margins {
    let (lo, hi) = (1.0f64, 1e6f64);
    // Bisection on log ω for |L| = 1 and for ∠L = −180° (phase unwrapped by continuity:
    // these loops' phase starts between −90° and −180° and falls).
    let solve = |f: &dyn Fn(f64) -> f64| {
        let (mut a, mut b) = (lo.ln(), hi.ln());
        for _ in 0..200 {
            let m = 0.5 * (a + b);
            if f(m.exp()) > 0.0 {
                a = m;
            } else {
                b = m;
            }
        }
        (0.5 * (a + b)).exp()
    };
    let phase = |w: f64| unwrapped_phase(&l, w);
    let wc = solve(&|w| l(w).norm() - 1.0);
    let w180 = solve(&|w| phase(w) + std::f64::consts::PI);
    Margins {
        crossover_rad_s: wc,
        phase_margin_deg: 180.0 + phase(wc).to_degrees(),
        gain_margin_db: -20.0 * l(w180).norm().log10(),
    }
}

/// ∠L(jω) followed continuously from ω = 1 rad/s in small steps. [rad]
fn unwrapped_phase(l: &impl Fn(f64) -> Complex64, w: f64) -> f64 {
    let steps = 400;
    let mut prev = l(1.0).arg();
    let mut acc = prev;
    for k in 1..=steps {
        let wk = (w.ln() * k as f64 / steps as f64).exp();
        let p = l(wk).arg();
        let mut d = p - prev;
        while d > std::f64::consts::PI {
            d -= std::f64::consts::TAU;
        }
        while d < -std::f64::consts::PI {
            d += std::f64::consts::TAU;
        }
        acc += d;
        prev = p;
    }
    acc
}

/// The current loop's open loop on an axis of inductance `l_h` [H] and resistance `r_ohm`
/// [Ω] with gains `kp` [V/A], `ki` [V/(A·s)] at PWM period `t_s` [s].
pub fn current_loop(l_h: f64, r_ohm: f64, kp: f64, ki: f64, t_s: f64) -> impl Fn(f64) -> Complex64 {
    move |w| {
        let s = Complex64::new(0.0, w);
        (s * kp + ki) / (s * (s * l_h + r_ohm)) * (-s * 1.5 * t_s).exp()
    }
}

/// The speed loop's open loop.
#[derive(Clone, Copy, Debug)]
pub struct SpeedPlant {
    /// Inertia J. [kg·m²]
    pub j: f64,
    /// Viscous friction B. [N·m·s]
    pub b: f64,
    /// Torque constant K_t. [N·m/A]
    pub k_t: f64,
    /// Closed current-loop bandwidth ω_c. [rad/s]
    pub omega_c: f64,
    /// Speed-loop period T_s. [s]
    pub t_s: f64,
}

/// L(jω) of the speed loop with gains `kp` [A/(rad/s)], `ki` [A/rad] and active damping
/// `ba` [A/(rad/s)] on `p`.
pub fn speed_loop(p: SpeedPlant, kp: f64, ki: f64, ba: f64) -> impl Fn(f64) -> Complex64 {
    move |w| {
        let s = Complex64::new(0.0, w);
        (s * kp + ki) * p.k_t / s / (s * p.j + p.b + p.k_t * ba) / (s / p.omega_c + 1.0)
            * (-s * p.t_s).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cancelled_current_loop_has_the_analytic_margins() {
        // Kp = L·ω_c, Ki = R·ω_c: L(s) = ω_c/s·e^{−sτ}, τ = 1.5·T. Crossover ω_c, phase
        // margin 90° − ω_c·τ, phase −180° at ω = π/(2τ) where |L| = 2ω_c·τ/π.
        let (wc, t) = (1100.0, 50e-6);
        let tau = 1.5 * t;
        let m = margins(current_loop(12e-3, 0.958, 12e-3 * wc, 0.958 * wc, t));
        assert!((m.crossover_rad_s - wc).abs() < 1e-3 * wc, "{m:?}");
        let pm = 90.0 - (wc * tau).to_degrees();
        assert!((m.phase_margin_deg - pm).abs() < 1e-3, "{m:?}");
        let gm = -20.0 * (2.0 * wc * tau / std::f64::consts::PI).log10();
        assert!((m.gain_margin_db - gm).abs() < 1e-3, "{m:?} vs {gm}");
    }
}
