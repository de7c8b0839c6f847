//! Speed modulation against the pump's kinematic flow ripple (eq. 20): once the table's
//! torques are cancelled the shaft turns evenly and the pump delivers D_p/2π·ω·f(θ), with
//! f(θ) its instantaneous displacement factor (mean 1). Turning the shaft at
//! ω(θ) = ω̄/f(θ) makes the delivered flow D_p/2π·ω̄ even. The speed loop's reference is
//! moved that way, and the torque the modulation takes, J·dω/dt = −J·ω̄²·f′(θ)/f(θ)³, is a
//! q-current feed-forward, so the loop need not chase it.
//!
//! # The shape, in closed form
//!
//! Piston i of z at shaft angle θ delivers while sin(θ + 2πi/z) > 0; the sum of eq. 20
//! over the delivering pistons is, between two pistons' changes of side, one cosine cap.
//! With n = 2z ripple cycles per revolution for odd z and n = z for even z, a = π/n:
//!
//! ```text
//!   s(θ) = a/sin(a) · cos u,   u = θ − φ_peak − 2a·round((θ − φ_peak)/2a) ∈ [−a, a]
//! ```
//!
//! mean 1, peak-to-peak a·tan(a/2) (the module docs of the plant's pump give the same
//! (π/2z)·tan(π/4z) and (π/z)·tan(π/2z)). The caps peak where the delivering pistons lie
//! symmetric about θ + 2πi/z = π/2: φ_peak = π/2 for odd z, π/2 + π/z for even z. A real
//! pump's ripple is larger than kinematic (port-plate timing, oil compression in the
//! bores): the drive scales the kinematic shape to the measured peak-to-peak ratio ρ,
//! f(θ) = 1 + ρ/(a·tan(a/2))·(s(θ) − 1), the pump's model in `plant-model` likewise, and
//! shifts it by the phase φ of the encoder's angle against the pump's (0 when the index
//! sits at the pump's piston 0).
//!
//! cos u and sin u are even and odd Taylor polynomials to u⁸ and u⁹ (|u| ≤ π/4 for
//! z ≥ 3: errors below 4·10⁻⁷), so host and target compute the same numbers without a
//! trigonometric call. It runs at the speed loop's rate, not in the current step.
//!
//! # Timing
//!
//! The speed measured at a speed-loop tick is the mean over the last speed period, half a
//! period back: the reference is looked up there. The acceleration current ordered at the
//! tick is held for a speed period and reaches the shaft after the closed current loop's
//! lag t_lead ([`super::Compensation::lead_s`]): it is looked up half a period plus
//! t_lead ahead. Both use the mean speed reference ω̄ (the pressure loop's output or the
//! speed setpoint) rather than the noisy measurement.
//!
//! # Bounds
//!
//! The modulation's peak-to-peak depth g·ρ (g = `compensation.scale`) must stay at or
//! below `compensation.max_flow_ratio`, refused naming the bound otherwise (the
//! controller's parameter check); the acceleration current is clamped to
//! ±`compensation.max_current_a` (it grows as ω̄²; at the holding's speeds it is a few
//! milliamperes).

use crate::commissioning::gains::torque_constant;
use crate::pi::saturate;
use core::f32::consts::PI;

pub use super::config::MIN_PISTONS;

/// Ripple cycles per revolution: 2z for odd z, z for even z. [1]
pub fn ripple_order(z: u32) -> u32 {
    if z % 2 == 1 {
        2 * z
    } else {
        z
    }
}

/// cos u by its Taylor polynomial to u⁸ (|u| ≤ π/4: error below 4·10⁻⁷). [1]
#[inline]
pub fn cos_small(u: f32) -> f32 {
    let u2 = u * u;
    1.0 - u2 / 2.0 * (1.0 - u2 / 12.0 * (1.0 - u2 / 30.0 * (1.0 - u2 / 56.0)))
}

/// sin u by its Taylor polynomial to u⁹ (|u| ≤ π/4: error below 10⁻⁸). [1]
#[inline]
pub fn sin_small(u: f32) -> f32 {
    let u2 = u * u;
    u * (1.0 - u2 / 6.0 * (1.0 - u2 / 20.0 * (1.0 - u2 / 42.0 * (1.0 - u2 / 72.0))))
}

/// The kinematic shape of the pump's flow for `z` pistons as the drive evaluates it
/// (mean 1): s(θ) at shaft angle `theta` [rad] with the pump's piston 0 at θ = 0. [1]
pub fn kinematic_shape(z: u32, theta: f32) -> f32 {
    let (gain, a, peak) = shape_constants(z);
    gain * cos_small(cap_offset(theta - peak, a))
}

/// For `z` ≥ [`MIN_PISTONS`]: a/sin a, the half-width a [rad] and the peak phase φ_peak
/// [rad] of the cosine caps.
fn shape_constants(z: u32) -> (f32, f32, f32) {
    let z = z.max(MIN_PISTONS);
    let a = PI / ripple_order(z) as f32;
    let peak = if z % 2 == 1 {
        PI / 2.0
    } else {
        PI / 2.0 + PI / z as f32
    };
    (a / sin_small(a), a, peak)
}

/// `x` [rad] less the nearest whole number of cap widths 2a: in [−a, a]. [rad]
#[inline]
fn cap_offset(x: f32, a: f32) -> f32 {
    let w = 2.0 * a;
    x - w * libm::floorf(x / w + 0.5)
}

/// The modulation's constants, derived from the live parameters.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FlowRipple {
    /// g·ρ/(a·tan(a/2))·a/sin a: the cap's cos u coefficient in f − 1 (0: off). [1]
    gain: f32,
    /// g·ρ/(a·tan(a/2)): the constant subtracted. [1]
    offset: f32,
    /// Half-width a of a cap. [rad]
    half_width: f32,
    /// φ_peak + φ. [rad]
    peak: f32,
    /// J/K_t. [A·s²/rad]
    inertia_a: f32,
    /// Lookup lag of the reference: half a speed period. [s]
    lag_s: f32,
    /// Lookup lead of the acceleration current: half a speed period plus t_lead. [s]
    lead_s: f32,
    /// Clamp of the acceleration current. [A]
    max_current_a: f32,
}

impl FlowRipple {
    /// Off.
    pub const OFF: FlowRipple = FlowRipple {
        gain: 0.0,
        offset: 0.0,
        half_width: 1.0,
        peak: 0.0,
        inertia_a: 0.0,
        lag_s: 0.0,
        lead_s: 0.0,
        max_current_a: 0.0,
    };

    /// From `cfg`, acting when `on`, with the current loop's lag `current_lead_s` [s].
    pub fn new(cfg: &crate::Config, on: bool, current_lead_s: f32) -> FlowRipple {
        let c = &cfg.compensation;
        if !(on && c.flow_pistons >= MIN_PISTONS && c.flow_ratio > 0.0) {
            return FlowRipple::OFF;
        }
        let (cap_gain, a, peak) = shape_constants(c.flow_pistons);
        let kinematic = a * sin_small(a / 2.0) / cos_small(a / 2.0);
        let r = c.scale * c.flow_ratio / kinematic;
        let kt = torque_constant(cfg.motor.pole_pairs as f32, cfg.motor.flux_linkage_wb);
        let half_period = 0.5 / cfg.rates.speed_loop_hz.max(1.0);
        FlowRipple {
            gain: r * cap_gain,
            offset: r,
            half_width: a,
            peak: peak + c.flow_phase_rad,
            inertia_a: if kt > 0.0 { c.inertia_kg_m2 / kt } else { 0.0 },
            lag_s: half_period,
            lead_s: half_period + current_lead_s,
            max_current_a: c.max_current_a,
        }
    }

    /// True when the modulation acts.
    pub fn is_active(&self) -> bool {
        self.gain != 0.0
    }

    /// f(θ) − 1 and f′(θ) [1/rad] at shaft angle `theta` [rad].
    #[inline]
    pub fn factor(&self, theta: f32) -> (f32, f32) {
        let u = cap_offset(theta - self.peak, self.half_width);
        (
            self.gain * cos_small(u) - self.offset,
            -self.gain * sin_small(u),
        )
    }

    /// The speed loop's modulated reference [rad/s] and the acceleration's q current [A]
    /// at the encoder's shaft angle `theta` [rad] for the mean reference `speed_ref`
    /// [rad/s]: (ω̄/f(θ − ω̄·lag), −J/K_t·ω̄²·f′/f³ at θ + ω̄·lead). Off: (ω̄, 0).
    #[inline]
    pub fn modulate(&self, theta: f32, speed_ref: f32) -> (f32, f32) {
        if !self.is_active() {
            return (speed_ref, 0.0);
        }
        let (d_ref, _) = self.factor(theta - speed_ref * self.lag_s);
        let (d, slope) = self.factor(theta + speed_ref * self.lead_s);
        let f = 1.0 + d;
        let i = -self.inertia_a * speed_ref * speed_ref * slope / (f * f * f);
        let lim = self.max_current_a;
        (speed_ref / (1.0 + d_ref), saturate(i, -lim, lim))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eq. 20 summed piston by piston: (π/z)·Σ max(0, sin(θ + 2πi/z)).
    fn eq20(z: u32, theta: f64) -> f64 {
        let zf = z as f64;
        (0..z)
            .map(|i| libm::sin(theta + 2.0 * core::f64::consts::PI * i as f64 / zf).max(0.0))
            .sum::<f64>()
            * core::f64::consts::PI
            / zf
    }

    #[test]
    fn the_closed_form_is_eq_20_summed_over_the_delivering_pistons() {
        for z in [3, 4, 5, 8, 9, 11] {
            for k in 0..2000 {
                let th = k as f64 * 0.0031416 - 0.7;
                let want = eq20(z, th);
                let got = kinematic_shape(z, th as f32) as f64;
                assert!((got - want).abs() < 2e-6, "z {z} θ {th}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn the_peak_to_peak_is_the_kinematic_ratio() {
        // (π/2z)·tan(π/4z) for z = 9: 1.5195 %; (π/z)·tan(π/2z) for z = 8: 7.81 %.
        let pp = |z: u32| {
            let v: Vec<f32> = (0..20_000)
                .map(|k| kinematic_shape(z, k as f32 * 3.1416e-4))
                .collect();
            v.iter().cloned().fold(f32::MIN, f32::max) - v.iter().cloned().fold(f32::MAX, f32::min)
        };
        let z9 = core::f64::consts::PI / 18.0 * libm::tan(core::f64::consts::PI / 36.0);
        let z8 = core::f64::consts::PI / 8.0 * libm::tan(core::f64::consts::PI / 16.0);
        assert!((pp(9) as f64 - z9).abs() < 1e-5, "{}", pp(9));
        assert!((pp(8) as f64 - z8).abs() < 1e-5, "{}", pp(8));
    }
}
