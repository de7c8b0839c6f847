//! The motor's electrical side in one evaluation: the inverter's pole voltages (ideal, with
//! dead time, or through the free-wheeling diodes with the bridge off), their d-q voltages
//! and the winding currents' derivatives (eq. 1–3, 17–19), a line confinement's when a
//! fault leaves one line.

use super::actuator::Plant;
use super::inputs::{Drive, Inputs};
use super::state::{ix, AngleTerms, Vector};
use crate::inverter::{dq_to_abc, pole_to_dq};

/// The inverter-driven part of one evaluation.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Electrical {
    pub(super) u_d: f64,
    pub(super) u_q: f64,
    pub(super) did: f64,
    pub(super) diq: f64,
    /// Electrical power into the motor terminals. [W]
    pub(super) p_in: f64,
}

impl Plant {
    /// The inverter's d-q voltages and the current derivatives (eq. 2) driven by them; zero
    /// unless the inverter drives and the currents are alive. The phase currents are formed
    /// only when the pole voltages depend on them (dead time, free-wheeling diodes).
    #[inline]
    pub(super) fn electrical<const FAULTED: bool>(
        &self,
        x: &Vector,
        inputs: &Inputs,
        at: &AngleTerms,
    ) -> Electrical {
        let Drive::Inverter { duties, enabled } = inputs.drive else {
            return Electrical::default();
        };
        let line = if FAULTED {
            self.line_mode(enabled)
        } else {
            None
        };
        // Died out stays out, unless a short keeps the circuit closed.
        let shorted = FAULTED && self.short_closes_circuit(line);
        if !enabled && self.discrete.extinguished && !shorted {
            return Electrical::default();
        }
        let (i_d, i_q) = (x[ix::ID], x[ix::IQ]);
        let (s_e, c_e) = (at.rot_e.sin, at.rot_e.cos);
        let v_pole = if enabled && !self.inverter.has_dead_time() && line.is_none() {
            self.inverter.pole_voltages_ideal(&duties)
        } else {
            let i_abc = dq_to_abc(i_d, i_q, s_e, c_e);
            if enabled {
                self.inverter.pole_voltages(&duties, &i_abc)
            } else {
                // Free-wheeling diodes: a motor-bound current through the lower diode (pole
                // at 0 V), a returning one through the upper (U_dc).
                let u = self.inverter.u_dc_v;
                let pole = |i: f64| if i > 0.0 { 0.0 } else { u };
                let mut v = [pole(i_abc[0]), pole(i_abc[1]), pole(i_abc[2])];
                self.pin_shorted_pole(&mut v);
                v
            }
        };
        if let Some(line) = line {
            let (did, diq, v_n, i) = self.line_electrical(x, line, v_pole, at.rot_e, &at.flux);
            let n = line.idle_phase().line_direction();
            let (c, s) = crate::faults::rotor_projections(n, at.rot_e);
            return Electrical {
                u_d: v_n * c,
                u_q: v_n * s,
                did,
                diq,
                p_in: 1.5 * v_n * i,
            };
        }
        let (u_d, u_q) = pole_to_dq(&v_pole, s_e, c_e);
        let omega_e = self.motor.pole_pairs * x[ix::OMEGA];
        let (did, diq) = self
            .motor
            .current_derivatives(u_d, u_q, i_d, i_q, omega_e, &at.flux);
        Electrical {
            u_d,
            u_q,
            did,
            diq,
            p_in: 1.5 * (u_d * i_d + u_q * i_q),
        }
    }
}
