//! What the controller and the commissioning sequence exchange each period: the
//! measurements the sequence reads ([`Input`]), what it asks the controller to do
//! ([`Action`]), and what it identified ([`CommissioningResult`]).

use super::gains::{CurrentGains, SpeedGains};
use crate::supervisor::FaultCode;
use crate::transforms::Dq;

/// What the controller gives the sequence each period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Input {
    /// Phase currents of this sample. [A]
    pub i_abc: [f32; 3],
    /// The d-q voltage commanded in the previous period (applied since). [V]
    pub u_dq_prev: Dq,
    /// Encoder electrical angle without any offset, p_n·2π·count/N. [rad]
    pub theta_e_raw: f32,
    /// Unwrapped encoder position. [counts]
    pub position_counts: i64,
    /// Shaft speed, low-pass filtered but updated every period (the speed observer's
    /// integrator: under constant acceleration it lags by a constant, which cancels in the
    /// acceleration measurement). [rad/s]
    pub speed_rad_s: f32,
}

/// What the controller does this period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Bridge off.
    Off,
    /// Current loop to `i_ref` [A] at the electrical angle `theta_e` [rad].
    Current {
        /// Angle of the d-q frame. [rad]
        theta_e: f32,
        /// The frame is the rotor's (encoder angle), so the speed-voltage decoupling
        /// applies; false for a forced angle, where the frame does not turn with the shaft
        /// and ω_e·(L_d·i_d + ψ_f) fed forward would push a q-current in phase with the
        /// speed: negative damping of the locked rotor.
        rotor_frame: bool,
        /// Current reference. [A]
        i_ref: Dq,
    },
    /// Open-loop voltage `u` [V] at `theta_e` [rad].
    Voltage {
        /// Angle of the d-q frame. [rad]
        theta_e: f32,
        /// Voltage. [V]
        u: Dq,
    },
    /// Speed loop to `rad_s` [rad/s] (i_d = 0) at the electrical angle `theta_e` [rad].
    Speed {
        /// Angle of the d-q frame. [rad]
        theta_e: f32,
        /// Speed reference. [rad/s]
        rad_s: f32,
    },
    /// Finished: the result is in [`Commissioning::result`].
    ///
    /// [`Commissioning::result`]: super::sequence::Commissioning::result
    Done,
    /// Failed with a fault code (13, 14 or 15).
    Fault(FaultCode),
}

/// What commissioning identified (SI) and the gains derived from it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommissioningResult {
    /// Stator resistance R_s. [Ω]
    pub stator_resistance_ohm: f32,
    /// d-axis inductance L_d. [H]
    pub d_inductance_h: f32,
    /// q-axis inductance L_q. [H]
    pub q_inductance_h: f32,
    /// Magnet flux linkage ψ_f. [Wb]
    pub flux_linkage_wb: f32,
    /// Encoder offset: θ_e = p_n·θ_count − offset, in [0, 2π). [rad]
    pub encoder_offset_rad: f32,
    /// Shaft inertia (motor and pump). [kg·m²]
    pub inertia_kg_m2: f32,
    /// Current-loop gains for the configured bandwidth.
    pub current_gains: CurrentGains,
    /// Speed-loop gains for the configured natural frequency and damping.
    pub speed_gains: SpeedGains,
    /// Time the sequence took (from its first sample, current offsets excluded). [s]
    pub duration_s: f32,
}
