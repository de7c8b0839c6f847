//! The explicit part of the exponential integrator: one evaluation of the model's equations
//! at a state, split into what the linear blocks ([`super::blocks`]) take exactly and the
//! rest, which the step extrapolates linearly from this evaluation and the previous one.
//! The same equations as `Plant::derivative_at` without faults: eq. 2's back-EMF of the
//! flux harmonics (eq. 17–19), the shaft (eq. 4) with the pump's torque (eq. 9, 20),
//! the nodes (eq. 9–12, 22–26) and the piston (eq. 12).

use super::super::actuator::Plant;
use super::super::state::{ix, AngleTerms, Vector};
use super::rates::Rates;
use crate::accumulator::ATMOSPHERE_PA;
use crate::friction::Slip;

impl Plant {
    /// The rates at state `x` with its shaft-angle terms `at`, the bridge `enabled` or off
    /// with the currents died out, for the block built at β/V_1 = `k[0]`, β/V_2 = `k[1]`.
    pub(super) fn exp_rates(
        &self,
        x: &Vector,
        at: &AngleTerms,
        enabled: bool,
        k: [f64; 2],
    ) -> Rates {
        let mut g = Rates::default();
        let omega = x[ix::OMEGA];
        let (i_d, i_q) = (x[ix::ID], x[ix::IQ]);
        let m = &self.motor;
        let flux = &at.flux;
        if enabled {
            g.emf = [
                (flux.q_wb - flux.d_slope_wb) / m.l_d_h,
                -(flux.d_wb + flux.q_slope_wb) / m.l_q_h,
            ];
            g.t_em = m.torque_nm(i_d, i_q, flux);
        }

        // --- shaft (eq. 4) and pump torque (eq. 9, 20)
        let (p_a, p_b) = (x[ix::PA], x[ix::PB]);
        let factor = at.factor;
        let t_pump = self.pump.load_torque(p_a, p_b, factor);
        let passive = at.t_cog - t_pump - self.shaft_viscous * omega;
        g.shaft_drive = g.t_em + passive;
        let t_fric = self.shaft_friction.force(self.discrete.shaft);
        if !(self.discrete.shaft == Slip::Stuck && self.shaft_friction.is_active()) {
            g.t_load = passive - t_fric;
        }
        g.p_visc = self.shaft_viscous * omega * omega;

        // --- nodes (eq. 9–12, 22–26)
        let pump = &self.pump;
        let p_fill = x[ix::FILL_PGAS] - ATMOSPHERE_PA;
        let q_int = pump.internal_leakage * (p_a - p_b);
        let q_ext_a = (pump.external_leakage + pump.extra_leakage) * (p_a - p_fill);
        let q_ext_b = pump.external_leakage * (p_b - p_fill);
        let q_cyl = self.cylinder.leakage * (p_a - p_b);
        let q_chk_a = self.check.flow(p_fill - p_a);
        let q_chk_b = self.check.flow(p_fill - p_b);
        let q_rel_a = self.relief_a.flow(p_a - p_fill);
        let q_rel_b = self.relief.flow(p_b - p_fill);
        let (xp, vp) = (x[ix::X], x[ix::V]);
        let (v1, v2) = self.cylinder.volumes(xp);
        let area = self.cylinder.area_m2;
        let net_a = -q_int - q_ext_a - q_cyl + q_chk_a - q_rel_a;
        let net_b = q_int - q_ext_b + q_cyl + q_chk_b - q_rel_b;
        let (k_a, k_b) = (self.beta / v1, self.beta / v2);
        let q_abs = if self.absorber.enabled {
            x[ix::ABS_Q]
        } else {
            0.0
        };
        g.f_pa = k_a * net_a - (k_a - k[0]) * (q_abs + area * vp);
        g.f_pb = k_b * net_b + (k_b - k[1]) * area * vp;
        g.q_fill = q_ext_a + q_ext_b + q_rel_a + q_rel_b - q_chk_a - q_chk_b;
        g.p_hyd = (q_int + q_cyl) * (p_a - p_b)
            + q_ext_a * (p_a - p_fill)
            + q_ext_b * (p_b - p_fill)
            + q_chk_a * (p_fill - p_a)
            + q_chk_b * (p_fill - p_b)
            + q_rel_a * (p_a - p_fill)
            + q_rel_b * (p_b - p_fill);
        if self.absorber.enabled {
            g.f_q = -(x[ix::ABS_PGAS] - ATMOSPHERE_PA) / self.absorber.inertance_kg_m4;
        }

        // --- piston (eq. 12)
        let c = &self.cylinder;
        g.piston_drive = c.drive_force(p_a, p_b, xp, vp, 0.0);
        if !c.blocked {
            let f_fric = self.piston_friction.force(self.discrete.piston);
            if !(self.discrete.piston == Slip::Stuck && self.piston_friction.is_active()) {
                let block = area * (p_a - p_b) - c.viscous * vp;
                g.f_v = (g.piston_drive - block - f_fric) / c.mass_kg;
            }
            // The stop contact's force less its spring part is what the contact dissipates.
            let stop_loss = c.stop_dissipative_force(xp, vp);
            g.p_visc += c.viscous * vp * vp - stop_loss * vp;
        }
        g
    }
}
