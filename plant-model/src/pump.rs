//! Fixed-displacement axial piston pump: eq. 9–10 (mean flow and leakage) and eq. 20
//! (instantaneous kinematic flow as the sum over the pistons on the delivery side).
//!
//! Piston i of z, at shaft angle θ, moves with velocity ∝ sin(θ + 2π·i/z); it delivers while
//! that is positive (half a turn). The geometric flow is therefore
//! `D_p/(2π)·ω·s(θ)` with the normalised shape s(θ) = (π/z)·Σ_delivering sin(θ + 2π·i/z),
//! whose mean over a revolution is 1. The sum over the m delivering pistons is a finite
//! geometric series, evaluated in closed form (one sine per call) but still exactly eq. 20 —
//! not its Fourier approximation (eq. 21). For odd z the ripple repeats 2z times per
//! revolution with peak-to-peak (π/2z)·tan(π/4z) of the mean (1.52 % for z = 9); for even z,
//! z times with (π/z)·tan(π/2z) (7.8 % for z = 8).
//!
//! The same instantaneous displacement sets the hydraulic torque on the shaft,
//! `D_p/(2π)·s(θ)·(p_A − p_B)`, so shaft power and hydraulic power balance exactly. The
//! ripple can be scaled to a measured peak-to-peak ratio (port-plate timing and oil
//! compression in the bores make real ripple larger than kinematic) keeping its shape.
//! Leakage: internal C_ip·(p_A − p_B) from port to port, external C_ep·(p_x − p_case) from
//! each port to the case, which drains to the fill accumulator (eq. 9 with p_r the case
//! pressure).

use crate::motor::Phasor;
use crate::rig::PumpParams;
use core::f64::consts::PI;

/// The pump's equations, precomputed.
#[derive(Clone, Debug)]
pub struct Pump {
    /// D_p/(2π). [m³/rad]
    pub displacement_m3_per_rad: f64,
    /// z. [1]
    pub pistons: u32,
    /// Angular pitch 2π/z. [rad]
    pitch: f64,
    /// sin(m·pitch/2)/sin(pitch/2)·π/z for m = ⌈z/2⌉ − 1 … ⌈z/2⌉ + 1 pistons delivering.
    series_gain: [f64; 3],
    /// Phasors of (m − 1)·pitch/2 for the same three m.
    series_phase: [Phasor; 3],
    /// Phasors of −j·pitch, j = 0 … MAX_PISTONS − 1, to reduce the shaft angle to [0, pitch).
    back_by_pitch: [Phasor; MAX_PISTONS],
    m_base: u32,
    /// Scale of the ripple about the mean (0: ideal flow, 1: kinematic). [1]
    ripple_scale: f64,
    /// C_ip. [(m³/s)/Pa]
    pub internal_leakage: f64,
    /// C_ep. [(m³/s)/Pa]
    pub external_leakage: f64,
    /// Extra port-A-to-case leakage. [(m³/s)/Pa]
    pub extra_leakage: f64,
}

/// Largest piston count the model takes (validation allows up to this).
pub const MAX_PISTONS: usize = 31;

/// Peak-to-peak kinematic flow ripple over mean flow for `z` pistons (the closed form
/// quoted in the module docs).
pub fn kinematic_ripple_ratio(z: u32) -> f64 {
    let z = z as f64;
    if (z as u32) % 2 == 1 {
        PI / (2.0 * z) * libm::tan(PI / (4.0 * z))
    } else {
        PI / z * libm::tan(PI / (2.0 * z))
    }
}

/// Ripple cycles per shaft revolution: 2z for odd z, z for even z.
pub fn ripple_order(z: u32) -> u32 {
    if z % 2 == 1 {
        2 * z
    } else {
        z
    }
}

impl Pump {
    /// From validated parameters.
    pub fn new(p: &PumpParams) -> Pump {
        let z = p.pistons as f64;
        let pitch = 2.0 * PI / z;
        let m_base = p.pistons.div_ceil(2).saturating_sub(1);
        let mut series_gain = [0.0; 3];
        let mut series_phase = [Phasor::of(0.0); 3];
        for (k, (g, ph)) in series_gain.iter_mut().zip(&mut series_phase).enumerate() {
            let m = (m_base + k as u32) as f64;
            *g = PI / z * libm::sin(m * pitch / 2.0) / libm::sin(pitch / 2.0);
            *ph = Phasor::of((m - 1.0) * pitch / 2.0);
        }
        let mut back_by_pitch = [Phasor::of(0.0); MAX_PISTONS];
        for (j, b) in back_by_pitch.iter_mut().enumerate() {
            *b = Phasor::of(-(j as f64) * pitch);
        }
        let ripple_scale = if !p.piston_ripple {
            0.0
        } else if p.ripple_amplitude_ratio > 0.0 {
            p.ripple_amplitude_ratio / kinematic_ripple_ratio(p.pistons)
        } else {
            1.0
        };
        Pump {
            displacement_m3_per_rad: p.displacement_m3_per_rev / (2.0 * PI),
            pistons: p.pistons,
            pitch,
            series_gain,
            series_phase,
            back_by_pitch,
            m_base,
            ripple_scale,
            internal_leakage: p.internal_leakage_m3_s_pa,
            external_leakage: p.external_leakage_m3_s_pa,
            extra_leakage: p.extra_leakage_m3_s_pa,
        }
    }

    /// The kinematic shape s(θ) of eq. 20 (mean 1 over a revolution). [1]
    pub fn kinematic_shape(&self, theta: f64) -> f64 {
        self.kinematic_shape_at(theta, Phasor::of(theta))
    }

    /// The kinematic shape at shaft angle `theta` whose phasor is `rot` (no trigonometric
    /// call: the angle is reduced by a whole number of pitches through a phasor table). [1]
    #[inline]
    pub fn kinematic_shape_at(&self, theta: f64, rot: Phasor) -> f64 {
        // Smallest piston angle φ0 in [0, pitch); pistons at φ0 + j·pitch deliver while < π.
        let turns = libm::floor(theta / self.pitch);
        let phi0 = (theta - turns * self.pitch).clamp(0.0, self.pitch);
        // `turns` is a whole number: its residue in integers (saturating far beyond any
        // reachable angle, where any index in range would do).
        let j = (turns as i64).rem_euclid(i64::from(self.pistons.max(1))) as usize;
        // m = ⌈(π − φ0)/pitch⌉ pistons deliver; (π − φ0)/pitch lies in [z/2 − 1, z/2], so
        // m − m_base (floored at 0) is 1 exactly when the ratio exceeds m_base, else 0.
        let k = usize::from((PI - phi0) / self.pitch > self.m_base as f64);
        let (Some(gain), Some(phase), Some(back)) = (
            self.series_gain.get(k),
            self.series_phase.get(k),
            self.back_by_pitch.get(j),
        ) else {
            return 1.0;
        };
        gain * (rot * *back * *phase).sin
    }

    /// Instantaneous displacement factor 1 + scale·(s(θ) − 1) applied to flow and torque. [1]
    pub fn displacement_factor(&self, theta: f64) -> f64 {
        self.displacement_factor_at(theta, Phasor::of(theta))
    }

    /// [`Pump::displacement_factor`] with the shaft-angle phasor supplied. [1]
    #[inline]
    pub fn displacement_factor_at(&self, theta: f64, rot: Phasor) -> f64 {
        if self.ripple_scale == 0.0 {
            1.0
        } else {
            1.0 + self.ripple_scale * (self.kinematic_shape_at(theta, rot) - 1.0)
        }
    }

    /// Geometric flow from port B to port A at speed `omega` with displacement factor
    /// `factor`. [m³/s]
    #[inline]
    pub fn geometric_flow(&self, omega: f64, factor: f64) -> f64 {
        self.displacement_m3_per_rad * factor * omega
    }

    /// Hydraulic load torque on the shaft. [N·m]
    #[inline]
    pub fn load_torque(&self, p_a: f64, p_b: f64, factor: f64) -> f64 {
        self.displacement_m3_per_rad * factor * (p_a - p_b)
    }
}
