//! The right-hand side of the state equations: motor and inverter (eq. 1–3, 17–19), pump
//! and shaft (eq. 4, 9, 20), the hydraulic nodes with leakage, valves, absorber and fill
//! accumulator (eq. 9–12, 22–26), the piston (eq. 12), and the power flows the energy
//! balance integrates.

use super::actuator::Plant;
use super::inputs::{Drive, Inputs};
use super::state::{ix, AngleTerms, Aux, Vector};
use crate::accumulator::ATMOSPHERE_PA;
use crate::faults::PUMP_MANIFOLD_VOLUME_M3;
use crate::friction::Slip;

impl Plant {
    /// The pump manifold's pressure in state `x`. [Pa]
    #[inline]
    pub(super) fn pump_pressure(&self, x: &Vector) -> f64 {
        if self.faulted && self.faults.pump_port_blocked {
            x[ix::PP]
        } else {
            x[ix::PA]
        }
    }

    /// The right-hand side of the state equations.
    #[inline]
    pub(super) fn derivative(&self, x: &Vector, inputs: &Inputs) -> (Vector, Aux) {
        let at = self.angle_terms(x[ix::THETA]);
        if self.faulted {
            self.derivative_at::<true>(x, inputs, &at)
        } else {
            self.derivative_at::<false>(x, inputs, &at)
        }
    }

    /// The right-hand side with the shaft-angle terms `at` of `x` supplied.
    #[inline]
    pub(super) fn derivative_at<const FAULTED: bool>(
        &self,
        x: &Vector,
        inputs: &Inputs,
        at: &AngleTerms,
    ) -> (Vector, Aux) {
        let mut dx = [0.0; ix::N];
        let mut aux = Aux::default();
        let omega = x[ix::OMEGA];
        let (i_d, i_q) = (x[ix::ID], x[ix::IQ]);
        let flux = at.flux;

        // --- motor and inverter (eq. 1–3, 17–19)
        let el = self.electrical::<FAULTED>(x, inputs, at);
        dx[ix::ID] = el.did;
        dx[ix::IQ] = el.diq;
        let mut p_in = el.p_in;
        let t_em = self.motor.torque_nm(i_d, i_q, &flux);
        let t_cog = at.t_cog;
        dx[ix::E_CU] = 1.5 * self.motor.r_s_ohm * (i_d * i_d + i_q * i_q);

        // --- pump (eq. 9, 20) and shaft (eq. 4)
        let (p_a, p_b) = (x[ix::PA], x[ix::PB]);
        let blocked = FAULTED && self.faults.pump_port_blocked;
        let p_pump = if blocked { x[ix::PP] } else { p_a };
        let factor = at.factor;
        let t_pump = self.pump.load_torque(p_pump, p_b, factor);
        aux.shaft_drive =
            t_em + t_cog - t_pump - self.shaft_viscous * omega + inputs.external_torque_nm;
        let t_fric = self.shaft_friction.force(self.discrete.shaft);
        dx[ix::THETA] = omega;
        match inputs.drive {
            Drive::ShaftSpeed { .. } => {
                // The prescribed motion is supplied by the drive: its power is the input.
                p_in = (t_pump + self.shaft_viscous * omega + t_fric - t_cog) * omega;
            }
            _ => {
                if matches!(inputs.drive, Drive::Currents { .. }) {
                    p_in = t_em * omega + dx[ix::E_CU];
                }
                if self.discrete.shaft == Slip::Stuck && self.shaft_friction.is_active() {
                    dx[ix::THETA] = 0.0;
                } else {
                    dx[ix::OMEGA] = (aux.shaft_drive - t_fric) / self.inertia;
                }
            }
        }
        dx[ix::E_IN] = p_in;
        let mut p_mech = self.shaft_viscous * omega * omega + t_fric * omega;

        // --- hydraulics (eq. 9–12, 22–26)
        let p_fill = x[ix::FILL_PGAS] - ATMOSPHERE_PA;
        let q_geo = self.pump.geometric_flow(omega, factor);
        // The pump's manifold (pump, its leakage, check and relief valves) is port A's node
        // unless the pump's port is blocked ([`crate::faults`]).
        let q_int = self.pump.internal_leakage * (p_pump - p_b);
        let q_ext_a = (self.pump.external_leakage + self.pump.extra_leakage) * (p_pump - p_fill);
        let q_ext_b = self.pump.external_leakage * (p_b - p_fill);
        let q_cyl = self.cylinder.leakage * (p_a - p_b);
        let q_chk_a = self.check.flow(p_fill - p_pump);
        let q_chk_b = self.check.flow(p_fill - p_b);
        let q_rel_a = self.relief_a.flow(p_pump - p_fill);
        let q_rel_b = self.relief.flow(p_b - p_fill);
        let q_burst = if FAULTED {
            self.burst_outflow(p_a)
        } else {
            0.0
        };
        let (q_abs, abs_oil) = (x[ix::ABS_Q], x[ix::ABS_OIL]);
        let (xp, vp) = (x[ix::X], x[ix::V]);
        let (v1, v2) = self.cylinder.volumes(xp);
        let area = self.cylinder.area_m2;
        let net_b = -q_geo + q_int - q_ext_b + q_cyl + q_chk_b - q_rel_b + area * vp;
        if blocked {
            let net_pump = q_geo - q_int - q_ext_a + q_chk_a - q_rel_a;
            dx[ix::PP] = self.beta / PUMP_MANIFOLD_VOLUME_M3 * net_pump;
            dx[ix::PA] = self.beta / v1 * (-q_cyl - q_abs - area * vp - q_burst);
        } else {
            let net_a =
                q_geo - q_int - q_ext_a - q_cyl + q_chk_a - q_rel_a - q_abs - area * vp - q_burst;
            // The manifold's state follows port A's at each step's end (`project`).
            dx[ix::PA] = self.beta / v1 * net_a;
        }
        dx[ix::PB] = self.beta / v2 * net_b;
        dx[ix::FILL_OIL] = q_ext_a + q_ext_b + q_rel_a + q_rel_b - q_chk_a - q_chk_b;
        dx[ix::FILL_PGAS] =
            self.fill_gas
                .pressure_rate(x[ix::FILL_PGAS], x[ix::FILL_OIL], dx[ix::FILL_OIL]);
        let through = if blocked {
            q_int * (p_pump - p_b) + q_cyl * (p_a - p_b)
        } else {
            (q_int + q_cyl) * (p_a - p_b)
        };
        let mut p_hyd = through
            + q_ext_a * (p_pump - p_fill)
            + q_ext_b * (p_b - p_fill)
            + q_chk_a * (p_fill - p_pump)
            + q_chk_b * (p_fill - p_b)
            + q_rel_a * (p_pump - p_fill)
            + q_rel_b * (p_b - p_fill);
        if q_burst != 0.0 {
            p_hyd += q_burst * p_a;
        }
        if self.absorber.enabled {
            dx[ix::ABS_OIL] = q_abs;
            let p_gas = x[ix::ABS_PGAS] - ATMOSPHERE_PA;
            dx[ix::ABS_Q] = self.absorber.flow_derivative(p_a, p_gas, abs_oil, q_abs);
            dx[ix::ABS_PGAS] = self
                .absorber
                .gas
                .pressure_rate(x[ix::ABS_PGAS], abs_oil, q_abs);
            p_hyd += self.absorber.resistance_pa_s_m3 * q_abs * q_abs;
        }

        // --- piston (eq. 12)
        let c = &self.cylinder;
        aux.piston_drive = c.drive_force(p_a, p_b, xp, vp, inputs.external_force_n);
        dx[ix::X] = vp;
        if inputs.piston.is_none() && !c.blocked {
            let f_fric = self.piston_friction.force(self.discrete.piston);
            if self.discrete.piston == Slip::Stuck && self.piston_friction.is_active() {
                dx[ix::X] = 0.0;
            } else {
                dx[ix::V] = (aux.piston_drive - f_fric) / c.mass_kg;
            }
            // Stop contact: force minus its spring part is what the contact dissipates.
            let spring_part = -c.stop_k
                * if xp > c.half_stroke_m {
                    xp - c.half_stroke_m
                } else if xp < -c.half_stroke_m {
                    xp + c.half_stroke_m
                } else {
                    0.0
                };
            let stop = c.stop_force(xp, vp);
            p_mech += c.viscous * vp * vp + f_fric * vp - (stop - spring_part) * vp;
        } else {
            // Prescribed motion: the piston's force balance is supplied from outside.
            p_in += -aux.piston_drive * vp;
        }
        dx[ix::E_EXT] = -inputs.external_force_n * vp - inputs.external_torque_nm * x[ix::OMEGA];
        dx[ix::E_MECH] = p_mech;
        dx[ix::E_HYD] = p_hyd;

        // The pressure transducer's lag is filtered exactly after each step
        // ([`Plant::filter_pressure_sensor`]): its derivative stays zero here.
        dx[ix::E_IN] = p_in;
        (dx, aux)
    }
}
