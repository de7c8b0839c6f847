//! The rates one evaluation of the model yields for the exponential integrator
//! ([`Rates`]: what the linear blocks of [`super::blocks`] do not take exactly, see
//! [`super::explicit`]), and their field-by-field arithmetic for the extrapolation.

/// The model's rates at one state, except the linear blocks' own terms and the external
/// force and torque (constant over a step, added by the step).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Rates {
    /// The back-EMF per electrical speed over L_d and L_q, (ψ_q − ∂ψ_d/∂θ_e)/L_d and
    /// −(ψ_d + ∂ψ_q/∂θ_e)/L_q, at this angle (the winding series multiplies it by the speed
    /// as the speed changes within the step). [A/(rad/s)/s]
    pub(super) emf: [f64; 2],
    /// Electromagnetic torque. [N·m]
    pub(super) t_em: f64,
    /// Shaft torque except the electromagnetic and the external, with friction (zero while
    /// stuck). [N·m]
    pub(super) t_load: f64,
    /// Port A's pressure rate except the block's own terms (the inlet's −k_A·q and the
    /// piston's −k_A·A·v at the block's k_A) and the pump's geometric flow (integrated by
    /// the step from the shaft's speed): every other flow, and the block's error in its
    /// terms, −(β/V_1 − k_A)·(q + A·v). [Pa/s]
    pub(super) f_pa: f64,
    /// The absorber inlet's forcing, −p_gas/I. [m³/s²]
    pub(super) f_q: f64,
    /// Port B's pressure rate except the block's piston term k_B·A·v and the pump's
    /// geometric flow, with the block's error (β/V_2 − k_B)·A·v. [Pa/s]
    pub(super) f_pb: f64,
    /// The piston's acceleration except the block's terms A·(p_A − p_B)/m − B_p·v/m and the
    /// external force: spring, gravity, end stops, friction (zero while stuck). [m/s²]
    pub(super) f_v: f64,
    /// Flow into the fill accumulator. [m³/s]
    pub(super) q_fill: f64,
    /// Shaft and piston damping and stop losses (friction's are booked exactly by the
    /// step, its force being constant while the slip direction is). [W]
    pub(super) p_visc: f64,
    /// Leakage and valve losses (the absorber inlet's are the step's). [W]
    pub(super) p_hyd: f64,
    /// Net shaft torque except friction and the external torque. [N·m]
    pub(super) shaft_drive: f64,
    /// Net piston force except friction and the external force. [N]
    pub(super) piston_drive: f64,
}

impl Rates {
    /// `f` applied field by field to `self` and `o`.
    pub(super) fn map2(&self, o: &Rates, f: impl Fn(f64, f64) -> f64) -> Rates {
        Rates {
            emf: [f(self.emf[0], o.emf[0]), f(self.emf[1], o.emf[1])],
            t_em: f(self.t_em, o.t_em),
            t_load: f(self.t_load, o.t_load),
            f_pa: f(self.f_pa, o.f_pa),
            f_q: f(self.f_q, o.f_q),
            f_pb: f(self.f_pb, o.f_pb),
            f_v: f(self.f_v, o.f_v),
            q_fill: f(self.q_fill, o.q_fill),
            p_visc: f(self.p_visc, o.p_visc),
            p_hyd: f(self.p_hyd, o.p_hyd),
            shaft_drive: f(self.shaft_drive, o.shaft_drive),
            piston_drive: f(self.piston_drive, o.piston_drive),
        }
    }
}
