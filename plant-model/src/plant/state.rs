//! What the plant holds between steps besides its parameters: the continuous state vector
//! and its indices, the discrete stick/slip and extinction state, the drives the stick/slip
//! decisions read, and the shaft-angle terms kept for the present state (rotor phasors,
//! magnet flux with its harmonics, cogging torque, the pump's displacement factor).

use crate::friction::Slip;
use crate::motor::{MagnetFlux, Phasor};

/// State indices.
pub(super) mod ix {
    pub const ID: usize = 0;
    pub const IQ: usize = 1;
    pub const THETA: usize = 2;
    pub const OMEGA: usize = 3;
    pub const PA: usize = 4;
    pub const PB: usize = 5;
    pub const X: usize = 6;
    pub const V: usize = 7;
    pub const ABS_OIL: usize = 8;
    pub const ABS_Q: usize = 9;
    pub const FILL_OIL: usize = 10;
    pub const P_SENSOR: usize = 11;
    pub const E_IN: usize = 12;
    pub const E_CU: usize = 13;
    pub const E_MECH: usize = 14;
    pub const E_HYD: usize = 15;
    pub const E_EXT: usize = 16;
    /// Absolute gas pressure of the absorber.
    pub const ABS_PGAS: usize = 17;
    /// Absolute gas pressure of the fill accumulator.
    pub const FILL_PGAS: usize = 18;
    /// Pressure of the pump's manifold: port A's while the port is open, a node of its own
    /// while it is blocked ([`crate::faults`]).
    pub const PP: usize = 19;
    pub const N: usize = 20;
}

/// The continuous state, indexed by [`ix`].
pub(super) type Vector = [f64; ix::N];

/// Discrete state held over a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Discrete {
    pub(super) shaft: Slip,
    pub(super) piston: Slip,
    /// Bridge off and currents died out.
    pub(super) extinguished: bool,
}

/// The drives of the two friction-bearing bodies in one evaluation (what the stick/slip
/// decisions need).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Aux {
    /// Net shaft torque except friction. [N·m]
    pub(super) shaft_drive: f64,
    /// Net piston force except friction. [N]
    pub(super) piston_drive: f64,
}

/// Everything of a derivative evaluation that depends on the shaft angle alone: the rotor
/// phasors, the magnet flux with its harmonics, the cogging torque and the pump's
/// displacement factor. Kept for the present state so that `sample`, `observe`, the
/// projection and the next step's first RK4 stage share one evaluation.
#[derive(Clone, Copy, Debug)]
pub(super) struct AngleTerms {
    /// The shaft angle these belong to. [rad]
    pub(super) theta: f64,
    pub(super) rot_m: Phasor,
    pub(super) rot_e: Phasor,
    pub(super) flux: MagnetFlux,
    /// Cogging torque. [N·m]
    pub(super) t_cog: f64,
    /// Pump displacement factor. [1]
    pub(super) factor: f64,
}

/// The shaft-angle phasor of the present state, carried from step to step by rotation
/// through the step's angle increment (no `sincos`), re-derived from the angle itself every
/// [`ROTOR_RESYNC_STEPS`] steps so rounding cannot accumulate (≈ 1e-16 rad per rotation).
#[derive(Clone, Copy, Debug)]
pub(super) struct RotorPhasor {
    /// The shaft angle. [rad]
    pub(super) theta: f64,
    pub(super) phasor: Phasor,
    pub(super) rotations: u32,
}

impl RotorPhasor {
    /// The phasor computed afresh from the angle (one `sincos`).
    pub(super) fn at(theta: f64) -> RotorPhasor {
        RotorPhasor {
            theta,
            phasor: Phasor::of(theta),
            rotations: 0,
        }
    }
}

/// Steps carried by rotation before the rotor phasor is computed afresh.
pub(super) const ROTOR_RESYNC_STEPS: u32 = 1024;
