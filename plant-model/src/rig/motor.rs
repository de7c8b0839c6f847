//! The drive side's parameters: the PMSM with its cogging (eq. 16) and flux harmonics
//! (eq. 17–19), the inverter, and the motor-plus-pump shaft (eq. 4).

/// Maximum number of cogging-torque harmonics (eq. 16 truncated).
pub const MAX_COGGING_HARMONICS: usize = 4;
/// Maximum number of permanent-magnet flux harmonics (eq. 17: orders 5, 7, 11, 13, …).
pub const MAX_FLUX_HARMONICS: usize = 4;

/// One term of the cogging torque series of eq. 16: `amplitude·sin(order·θ_m + phase)`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CoggingHarmonic {
    /// Amplitude. [N·m]
    pub amplitude_nm: f64,
    /// Cycles per mechanical revolution (a multiple of LCM(slots, poles) for slotting). [1]
    pub order: u32,
    /// Phase against the encoder's mechanical zero. [rad]
    pub phase_rad: f64,
}

/// One harmonic of the magnet flux linkage seen by phase a (eq. 17):
/// `amplitude·cos(order·θ_e + phase)`, phases b and c shifted by ∓2π/3 of the fundamental.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FluxHarmonic {
    /// Flux-linkage amplitude (signed). [Wb]
    pub amplitude_wb: f64,
    /// Electrical order: 6k ± 1 (5, 7, 11, 13, …). [1]
    pub order: u32,
    /// Phase. [rad]
    pub phase_rad: f64,
}

pub(super) const NO_COGGING: CoggingHarmonic = CoggingHarmonic {
    amplitude_nm: 0.0,
    order: 72,
    phase_rad: 0.0,
};
pub(super) const NO_FLUX_HARMONIC: FluxHarmonic = FluxHarmonic {
    amplitude_wb: 0.0,
    order: 5,
    phase_rad: 0.0,
};

/// PMSM parameters (eq. 1–7, 16–19).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MotorParams {
    /// Pole pairs p_n. [1]
    pub pole_pairs: u32,
    /// Stator resistance R_s. [Ω]
    pub r_s_ohm: f64,
    /// d-axis inductance L_d. [H]
    pub l_d_h: f64,
    /// q-axis inductance L_q. [H]
    pub l_q_h: f64,
    /// Permanent-magnet flux linkage ψ_f (fundamental, amplitude-invariant d-q). [Wb]
    pub psi_f_wb: f64,
    /// Stator slots N_s (sets the cogging fundamental LCM(N_s, 2·p_n)). [1]
    pub stator_slots: u32,
    /// Cogging torque series (eq. 16); zero amplitudes are off.
    pub cogging: [CoggingHarmonic; MAX_COGGING_HARMONICS],
    /// Flux-linkage harmonics (eq. 17); zero amplitudes are off.
    pub flux_harmonics: [FluxHarmonic; MAX_FLUX_HARMONICS],
}

impl MotorParams {
    /// Torque constant K_t = 1.5·p_n·ψ_f (eq. 5). [N·m/A]
    pub fn torque_constant_nm_per_a(&self) -> f64 {
        1.5 * self.pole_pairs as f64 * self.psi_f_wb
    }

    /// The cogging fundamental: cycles per mechanical revolution, LCM(N_s, 2·p_n) (eq. 16's N_cog).
    pub fn cogging_fundamental_order(&self) -> u32 {
        lcm(self.stator_slots, 2 * self.pole_pairs)
    }
}

/// Two-level voltage-source inverter, average model.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct InverterParams {
    /// DC-link voltage U_dc. [V]
    pub u_dc_v: f64,
    /// Switching (PWM) frequency, needed for the dead-time voltage error. [Hz]
    pub pwm_frequency_hz: f64,
    /// Dead time per switching edge pair; 0 is off. [s]
    pub dead_time_s: f64,
    /// Phase current below which the dead-time error fades linearly to zero (the ripple
    /// current makes the diode conduction interval depend on the current there). [A]
    pub dead_time_current_band_a: f64,
}

/// Motor-plus-pump shaft.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ShaftParams {
    /// Motor rotor inertia J_m (*assumed*). [kg·m²]
    pub motor_inertia_kg_m2: f64,
    /// Pump rotating-group inertia J_p (*assumed*). [kg·m²]
    pub pump_inertia_kg_m2: f64,
    /// Viscous friction D (eq. 4). [N·m·s/rad]
    pub viscous_nm_s: f64,
    /// Coulomb (sliding) friction torque; 0 is off. [N·m]
    pub coulomb_nm: f64,
    /// Static (breakaway) friction torque, ≥ Coulomb when on; 0 is off. [N·m]
    pub static_nm: f64,
}

impl ShaftParams {
    /// Total inertia J_L of eq. 4. [kg·m²]
    pub fn inertia_kg_m2(&self) -> f64 {
        self.motor_inertia_kg_m2 + self.pump_inertia_kg_m2
    }
}

fn gcd(mut a: u32, mut b: u32) -> u32 {
    while b != 0 {
        let t = a % b;
        a = b;
        b = t;
    }
    a
}

/// Least common multiple (0 if either is 0).
pub fn lcm(a: u32, b: u32) -> u32 {
    if a == 0 || b == 0 {
        0
    } else {
        a / gcd(a, b) * b
    }
}
