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

/// The shaft's torques in one evaluation (eq. 4). [N·m]
#[derive(Clone, Copy, Debug)]
struct ShaftTorques {
    /// Electromagnetic.
    t_em: f64,
    /// Cogging.
    t_cog: f64,
    /// The pump's load.
    t_pump: f64,
    /// Friction.
    t_fric: f64,
}

/// The hydraulic nodes' pressures in one evaluation (gauge). [Pa]
#[derive(Clone, Copy, Debug)]
struct Nodes {
    /// The pump's manifold: port A's unless the pump's port is blocked.
    p_pump: f64,
    /// Port A.
    p_a: f64,
    /// Port B.
    p_b: f64,
    /// The fill accumulator.
    p_fill: f64,
}

/// The flows between the hydraulic nodes in one evaluation (eq. 9–11, 20). [m³/s]
#[derive(Clone, Copy, Debug)]
struct Flows {
    /// The pump's geometric flow, from port B to the manifold.
    q_geo: f64,
    /// The pump's internal leakage, from the manifold to port B.
    q_int: f64,
    /// External leakage of the manifold (with a fault's extra) and of port B to the fill.
    q_ext_a: f64,
    q_ext_b: f64,
    /// The cylinder's leakage from port A to port B.
    q_cyl: f64,
    /// The check valves' flows from the fill into the manifold and port B.
    q_chk_a: f64,
    q_chk_b: f64,
    /// The relief valves' flows from the manifold and port B to the fill.
    q_rel_a: f64,
    q_rel_b: f64,
    /// A burst's outflow of port A (zero unless faulted).
    q_burst: f64,
}

impl Flows {
    /// What flows into the fill accumulator: the external leakages and the reliefs less the
    /// check valves' draw. [m³/s]
    #[inline(always)]
    fn fill_inflow(&self) -> f64 {
        self.q_ext_a + self.q_ext_b + self.q_rel_a + self.q_rel_b - self.q_chk_a - self.q_chk_b
    }
}

/// A piston free to move: its position and speed rates and the power its damping,
/// friction and stops dissipate (eq. 12).
#[derive(Clone, Copy, Debug)]
struct PistonRates {
    /// dx/dt. [m/s]
    d_x: f64,
    /// dv/dt. [m/s²]
    d_v: f64,
    /// Mechanical loss. [W]
    p_mech: f64,
}

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

        // --- motor and inverter (eq. 1–3, 17–19)
        let el = self.electrical::<FAULTED>(x, inputs, at);
        dx[ix::ID] = el.did;
        dx[ix::IQ] = el.diq;
        dx[ix::E_CU] = self.copper_loss(x);

        // --- pump (eq. 9, 20) and shaft (eq. 4)
        let blocked = FAULTED && self.faults.pump_port_blocked;
        let p = nodes(x, blocked);
        let tq = self.shaft_torques(x, at, &p);
        aux.shaft_drive =
            tq.t_em + tq.t_cog - tq.t_pump - self.shaft_viscous * omega + inputs.external_torque_nm;
        [dx[ix::THETA], dx[ix::OMEGA]] =
            self.shaft_rates(&inputs.drive, omega, aux.shaft_drive, tq.t_fric);
        let mut p_in = self.drive_power(&inputs.drive, omega, &tq, el.p_in, dx[ix::E_CU]);
        let mut p_mech = self.shaft_viscous * omega * omega + tq.t_fric * omega;

        // --- hydraulics (eq. 9–12, 22–26)
        let q = self.flows::<FAULTED>(x, &p, at.factor);
        [dx[ix::PP], dx[ix::PA], dx[ix::PB]] = self.port_pressure_rates(x, &q, blocked);
        dx[ix::FILL_OIL] = q.fill_inflow();
        dx[ix::FILL_PGAS] =
            self.fill_gas
                .pressure_rate(x[ix::FILL_PGAS], x[ix::FILL_OIL], dx[ix::FILL_OIL]);
        let mut p_hyd = hydraulic_power(&p, &q, blocked);
        if self.absorber.enabled {
            let (rates, p_loss) = self.absorber_rates(x, p.p_a);
            [dx[ix::ABS_OIL], dx[ix::ABS_Q], dx[ix::ABS_PGAS]] = rates;
            p_hyd += p_loss;
        }

        // --- piston (eq. 12)
        let (xp, vp) = (x[ix::X], x[ix::V]);
        let c = &self.cylinder;
        aux.piston_drive = c.drive_force(p.p_a, p.p_b, xp, vp, inputs.external_force_n);
        dx[ix::X] = vp;
        if inputs.piston.is_none() && !c.blocked {
            let piston = self.free_piston(xp, vp, aux.piston_drive);
            dx[ix::X] = piston.d_x;
            dx[ix::V] = piston.d_v;
            p_mech += piston.p_mech;
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

    /// The winding's copper loss 3/2·R·(i_d² + i_q²) in state `x` (the energy balance's). [W]
    #[inline(always)]
    fn copper_loss(&self, x: &Vector) -> f64 {
        let (i_d, i_q) = (x[ix::ID], x[ix::IQ]);
        1.5 * self.motor.r_s_ohm * (i_d * i_d + i_q * i_q)
    }

    /// The shaft's torques in state `x` with its angle terms `at` and the node pressures
    /// `p`: the motor's (eq. 3 with the flux harmonics), cogging (eq. 16), the pump's load
    /// (eq. 9, 20) and the shaft's friction. [N·m]
    #[inline(always)]
    fn shaft_torques(&self, x: &Vector, at: &AngleTerms, p: &Nodes) -> ShaftTorques {
        let flux = at.flux;
        ShaftTorques {
            t_em: self.motor.torque_nm(x[ix::ID], x[ix::IQ], &flux),
            t_cog: at.t_cog,
            t_pump: self.pump.load_torque(p.p_pump, p.p_b, at.factor),
            t_fric: self.shaft_friction.force(self.discrete.shaft),
        }
    }

    /// dθ/dt and dω/dt (eq. 4) at speed `omega` under the torque `shaft_drive` (all but
    /// friction) and friction `t_fric`: held still while stuck, and no acceleration of its
    /// own under a prescribed speed. [rad/s], [rad/s²]
    #[inline(always)]
    fn shaft_rates(&self, drive: &Drive, omega: f64, shaft_drive: f64, t_fric: f64) -> [f64; 2] {
        if matches!(drive, Drive::ShaftSpeed { .. }) {
            [omega, 0.0]
        } else if self.discrete.shaft == Slip::Stuck && self.shaft_friction.is_active() {
            [0.0, 0.0]
        } else {
            [omega, (shaft_drive - t_fric) / self.inertia]
        }
    }

    /// The power into the actuator from its drive at speed `omega`: the inverter's
    /// electrical power `p_el`; for prescribed currents the motor's mechanical power plus
    /// the copper loss `p_cu`; for a prescribed speed what holds that motion against the
    /// shaft's load (eq. 4). [W]
    #[inline(always)]
    fn drive_power(
        &self,
        drive: &Drive,
        omega: f64,
        tq: &ShaftTorques,
        p_el: f64,
        p_cu: f64,
    ) -> f64 {
        match drive {
            // The prescribed motion is supplied by the drive: its power is the input.
            Drive::ShaftSpeed { .. } => {
                (tq.t_pump + self.shaft_viscous * omega + tq.t_fric - tq.t_cog) * omega
            }
            Drive::Currents { .. } => tq.t_em * omega + p_cu,
            Drive::Inverter { .. } => p_el,
        }
    }

    /// The flows between the nodes at pressures `p`, the pump turning at `x`'s speed with
    /// displacement factor `factor` (eq. 9–10, 20). The pump's manifold (pump, its
    /// leakage, check and relief valves) is port A's node unless the pump's port is blocked
    /// ([`crate::faults`]). [m³/s]
    #[inline(always)]
    fn flows<const FAULTED: bool>(&self, x: &Vector, p: &Nodes, factor: f64) -> Flows {
        let Nodes {
            p_pump,
            p_a,
            p_b,
            p_fill,
        } = *p;
        Flows {
            q_geo: self.pump.geometric_flow(x[ix::OMEGA], factor),
            q_int: self.pump.internal_leakage * (p_pump - p_b),
            q_ext_a: (self.pump.external_leakage + self.pump.extra_leakage) * (p_pump - p_fill),
            q_ext_b: self.pump.external_leakage * (p_b - p_fill),
            q_cyl: self.cylinder.leakage * (p_a - p_b),
            q_chk_a: self.check.flow(p_fill - p_pump),
            q_chk_b: self.check.flow(p_fill - p_b),
            q_rel_a: self.relief_a.flow(p_pump - p_fill),
            q_rel_b: self.relief.flow(p_b - p_fill),
            q_burst: if FAULTED {
                self.burst_outflow(p_a)
            } else {
                0.0
            },
        }
    }

    /// The pressure rates of the pump's manifold, port A and port B (eq. 11) under the
    /// flows `q`, the absorber's inlet and the piston's displacement in state `x`; the
    /// manifold's is zero unless `blocked`: its state follows port A's at each step's end
    /// (`project`). [Pa/s]
    #[inline(always)]
    fn port_pressure_rates(&self, x: &Vector, q: &Flows, blocked: bool) -> [f64; 3] {
        let Flows {
            q_geo,
            q_int,
            q_ext_a,
            q_ext_b,
            q_cyl,
            q_chk_a,
            q_chk_b,
            q_rel_a,
            q_rel_b,
            q_burst,
        } = *q;
        let q_abs = x[ix::ABS_Q];
        let vp = x[ix::V];
        let (v1, v2) = self.cylinder.volumes(x[ix::X]);
        let area = self.cylinder.area_m2;
        let net_b = -q_geo + q_int - q_ext_b + q_cyl + q_chk_b - q_rel_b + area * vp;
        let (d_pp, d_pa) = if blocked {
            let net_pump = q_geo - q_int - q_ext_a + q_chk_a - q_rel_a;
            (
                self.beta / PUMP_MANIFOLD_VOLUME_M3 * net_pump,
                self.beta / v1 * (-q_cyl - q_abs - area * vp - q_burst),
            )
        } else {
            let net_a =
                q_geo - q_int - q_ext_a - q_cyl + q_chk_a - q_rel_a - q_abs - area * vp - q_burst;
            (0.0, self.beta / v1 * net_a)
        };
        [d_pp, d_pa, self.beta / v2 * net_b]
    }

    /// The absorber's rates in state `x` with port A at `p_a` — its oil volume, inlet flow
    /// and gas pressure (eq. 22–26) — and the power its inlet dissipates. [m³/s], [m³/s²],
    /// [Pa/s], [W]
    #[inline(always)]
    fn absorber_rates(&self, x: &Vector, p_a: f64) -> ([f64; 3], f64) {
        let (q_abs, abs_oil) = (x[ix::ABS_Q], x[ix::ABS_OIL]);
        let p_gas = x[ix::ABS_PGAS] - ATMOSPHERE_PA;
        let rates = [
            q_abs,
            self.absorber.flow_derivative(p_a, p_gas, abs_oil, q_abs),
            self.absorber
                .gas
                .pressure_rate(x[ix::ABS_PGAS], abs_oil, q_abs),
        ];
        (rates, self.absorber.resistance_pa_s_m3 * q_abs * q_abs)
    }

    /// A piston free to move at `xp`, `vp` under the force `piston_drive` (all but
    /// friction): its rates (held still while stuck) and the power its damping, friction
    /// and stop contact dissipate (eq. 12).
    #[inline(always)]
    fn free_piston(&self, xp: f64, vp: f64, piston_drive: f64) -> PistonRates {
        let c = &self.cylinder;
        let f_fric = self.piston_friction.force(self.discrete.piston);
        let (d_x, d_v) = if self.discrete.piston == Slip::Stuck && self.piston_friction.is_active()
        {
            (0.0, 0.0)
        } else {
            (vp, (piston_drive - f_fric) / c.mass_kg)
        };
        // The stop contact's force less its spring part is what the contact dissipates.
        let stop_loss = c.stop_dissipative_force(xp, vp);
        PistonRates {
            d_x,
            d_v,
            p_mech: c.viscous * vp * vp + f_fric * vp - stop_loss * vp,
        }
    }
}

/// The nodes' pressures in state `x`; the pump's manifold is a node of its own while
/// `blocked`. [Pa]
#[inline(always)]
fn nodes(x: &Vector, blocked: bool) -> Nodes {
    let p_a = x[ix::PA];
    Nodes {
        p_pump: if blocked { x[ix::PP] } else { p_a },
        p_a,
        p_b: x[ix::PB],
        p_fill: x[ix::FILL_PGAS] - ATMOSPHERE_PA,
    }
}

/// The power the flows `q` dissipate across the pressures `p` they pass: through the pump
/// and the cylinder, the leakages, the valves and a burst (the energy balance's). [W]
#[inline(always)]
fn hydraulic_power(p: &Nodes, q: &Flows, blocked: bool) -> f64 {
    let Nodes {
        p_pump,
        p_a,
        p_b,
        p_fill,
    } = *p;
    let through = if blocked {
        q.q_int * (p_pump - p_b) + q.q_cyl * (p_a - p_b)
    } else {
        (q.q_int + q.q_cyl) * (p_a - p_b)
    };
    let mut p_hyd = through
        + q.q_ext_a * (p_pump - p_fill)
        + q.q_ext_b * (p_b - p_fill)
        + q.q_chk_a * (p_fill - p_pump)
        + q.q_chk_b * (p_fill - p_b)
        + q.q_rel_a * (p_pump - p_fill)
        + q.q_rel_b * (p_b - p_fill);
    if q.q_burst != 0.0 {
        p_hyd += q.q_burst * p_a;
    }
    p_hyd
}
