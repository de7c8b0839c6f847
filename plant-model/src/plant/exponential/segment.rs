//! One segment of the exponential integrator's step: the winding series, the shaft by the
//! torque's integrals and the load's extrapolation, the pump's flow along the shaft's speed,
//! the hydraulic block solved exactly, the absorber's oil and both gases along their
//! polytropic laws (the scheme of [`super`]).

use super::super::actuator::Plant;
use super::super::inputs::{Drive, Inputs};
use super::super::state::{ix, AngleTerms, Vector};
use super::blocks::mv;
use super::gas::gas_growth;
use super::history::{BlockKey, BlockPhi, Poly};
use super::rates::Rates;
use super::winding::Shaft;
use crate::friction::Slip;
use crate::motor::Phasor;

/// Whether the absorber's poppet lets oil through during a segment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Port {
    /// Open: port A and the inlet flow are the exact block.
    Open,
    /// Shut (or no absorber): the inlet flow is held, port A is explicit.
    Shut,
}

/// The state at a segment's end, its shaft-angle terms, and the energies it books besides
/// friction's and the external work.
#[derive(Clone, Copy, Debug)]
pub(super) struct Segment {
    pub(super) x: Vector,
    pub(super) at: AngleTerms,
    /// Input energy, copper loss, damping and stop losses, hydraulic losses. [J]
    pub(super) e_in: f64,
    pub(super) e_cu: f64,
    pub(super) visc_loss: f64,
    pub(super) hyd_loss: f64,
}

/// What a segment starts from.
#[derive(Clone, Copy, Debug)]
pub(super) struct Start<'a> {
    pub(super) x: &'a Vector,
    pub(super) at: &'a AngleTerms,
    pub(super) g: &'a Rates,
    pub(super) inputs: &'a Inputs,
    pub(super) port: Port,
    pub(super) key: BlockKey,
    pub(super) enabled: bool,
}

impl Plant {
    /// Integrates one segment of `tau` from `start` with the extrapolation `poly`.
    #[inline(always)]
    pub(super) fn exp_segment(&self, start: &Start, poly: &Poly, tau: f64) -> Segment {
        let (x0, g0, inputs) = (start.x, start.g, start.inputs);
        let (g1, g2) = (&poly.g1, &poly.g2);
        // ∫ over the segment of c0 + c1·t + c2·t², and of (τ − t)·(…).
        let t2 = tau * tau;
        let t3 = t2 * tau;
        let int = |c0: f64, c1: f64, c2: f64| tau * c0 + 0.5 * t2 * c1 + t3 / 3.0 * c2;
        let moment =
            |c0: f64, c1: f64, c2: f64| 0.5 * t2 * c0 + t3 / 6.0 * c1 + t3 * tau / 12.0 * c2;
        let shaft_free = !(self.discrete.shaft == Slip::Stuck && self.shaft_friction.is_active());
        let inv_j = 1.0 / self.inertia;
        let l0 = if shaft_free {
            g0.t_load + inputs.external_torque_nm
        } else {
            0.0
        };
        let alpha0 = if shaft_free {
            (g0.t_em + l0) * inv_j
        } else {
            0.0
        };
        let mut seg = Segment {
            x: *x0,
            at: *start.at,
            e_in: 0.0,
            e_cu: 0.0,
            visc_loss: int(g0.p_visc, g1.p_visc, g2.p_visc),
            hyd_loss: int(g0.p_hyd, g1.p_hyd, g2.p_hyd),
        };
        // --- winding currents, their torque and power
        let mut torque = (0.0, 0.0);
        // The shaft's speed at the segment's middle (from the winding series when it runs).
        let mut omega_mid = None;
        if let Drive::Inverter {
            duties,
            enabled: true,
        } = inputs.drive
        {
            let p = self.motor.pole_pairs;
            // The shaft's acceleration: p_n/J times the torque's gradient in i and the
            // load's extrapolation (none for a shaft held by friction).
            let shaft = if shaft_free {
                let f = &start.at.flux;
                let dl = self.motor.l_d_h - self.motor.l_q_h;
                let k = 1.5 * p * p * inv_j;
                Shaft {
                    alpha_e: p * alpha0,
                    gain: [
                        k * (f.d_slope_wb - f.q_wb + dl * x0[ix::IQ]),
                        k * (f.d_wb + f.q_slope_wb + dl * x0[ix::ID]),
                    ],
                    load: [p * inv_j * g1.t_load, p * inv_j * g2.t_load],
                }
            } else {
                Shaft::default()
            };
            let o = self.winding_step(x0, start.at, g0, poly, &duties, &shaft, tau);
            seg.x[ix::ID] = o.i[0];
            seg.x[ix::IQ] = o.i[1];
            if shaft_free {
                omega_mid = Some(o.omega_e_mid / p);
            }
            torque = (o.torque, o.torque_moment);
            seg.e_in = o.e_in;
            seg.e_cu = o.e_cu;
        }
        // --- shaft
        let w0 = x0[ix::OMEGA];
        if shaft_free {
            let (i_t, i2_t) = torque;
            seg.x[ix::OMEGA] = w0 + (i_t + int(l0, g1.t_load, g2.t_load)) * inv_j;
            seg.x[ix::THETA] =
                x0[ix::THETA] + tau * w0 + (i2_t + moment(l0, g1.t_load, g2.t_load)) * inv_j;
            seg.at = self.angle_after(start.at, seg.x[ix::THETA]);
        }
        // The pump's geometric flow D·s(θ)·ω from the shaft's own speed (it follows the
        // torque within the step, which the rates' extrapolation cannot), quadratic through
        // the segment's start, middle and end: q(t) = c0 + c1·t + c2·t².
        let w_mid = omega_mid.unwrap_or_else(|| {
            let h = 0.5 * tau;
            w0 + (h * l0 + 0.5 * h * h * g1.t_load + h * h * h / 3.0 * g2.t_load) * inv_j
        });
        let w_mid = if shaft_free { w_mid } else { w0 };
        let (f0, f1) = (start.at.factor, seg.at.factor);
        let pump = &self.pump;
        let q0 = pump.geometric_flow(w0, f0);
        let qm = pump.geometric_flow(w_mid, 0.5 * (f0 + f1));
        let q1 = pump.geometric_flow(seg.x[ix::OMEGA], f1);
        let pump_c = [
            q0,
            (4.0 * qm - 3.0 * q0 - q1) / tau,
            2.0 * (q0 + q1 - 2.0 * qm) / (tau * tau),
        ];
        let (v1, v2) = self.cylinder.volumes(x0[ix::X]);
        let (k_a, k_b) = (self.beta / v1, self.beta / v2);
        // --- the hydraulic block: port A, the absorber's inlet, port B, the payload
        let key = &start.key;
        let c = &self.cylinder;
        let a = &self.absorber;
        let f_v0 = g0.f_v + inputs.external_force_n / c.mass_kg;
        // The forcing's coefficients f_0, f_1, f_2 in block order (p_A, q, p_B, v).
        let f = [
            [
                g0.f_pa + k_a * pump_c[0],
                g0.f_q,
                g0.f_pb - k_b * pump_c[0],
                f_v0,
            ],
            [
                g1.f_pa + k_a * pump_c[1],
                g1.f_q,
                g1.f_pb - k_b * pump_c[1],
                g1.f_v,
            ],
            [
                g2.f_pa + k_a * pump_c[2],
                g2.f_q,
                g2.f_pb - k_b * pump_c[2],
                g2.f_v,
            ],
        ];
        let y0 = [x0[ix::PA], x0[ix::ABS_Q], x0[ix::PB], x0[ix::V]];
        let owned;
        let phi = match self.block_phi(key, tau) {
            Some(p) => p,
            None => {
                owned = self.block_phi_new(key, tau);
                &owned
            }
        };
        let y1 = match phi {
            BlockPhi::Four(b) => {
                let (e, p1, p2, p3) = (
                    mv(&b.e, y0),
                    mv(&b.p1, f[0]),
                    mv(&b.p2, f[1]),
                    mv(&b.p3, f[2]),
                );
                core::array::from_fn(|k| e[k] + tau * p1[k] + t2 * p2[k] + 2.0 * t3 * p3[k])
            }
            BlockPhi::Two(b) => {
                let sub = |v: [f64; 4]| [v[0], v[1]];
                let (e, p1, p2, p3) = (
                    mv(&b.e, sub(y0)),
                    mv(&b.p1, sub(f[0])),
                    mv(&b.p2, sub(f[1])),
                    mv(&b.p3, sub(f[2])),
                );
                let y = |k: usize| e[k] + tau * p1[k] + t2 * p2[k] + 2.0 * t3 * p3[k];
                // Port B alone: its forcing integrated (the piston is still).
                [y(0), y(1), y0[2] + int(f[0][2], f[1][2], f[2][2]), y0[3]]
            }
        };
        // The block's rates at both ends (rows q and v), for the Hermite rule on the oil and
        // the stroke.
        let forcing = |k: usize, t: f64| f[0][k] + t * (f[1][k] + t * f[2][k]);
        let hermite =
            |a0: f64, a1: f64, d0: f64, d1: f64| 0.5 * tau * (a0 + a1) + t2 / 12.0 * (d0 - d1);
        seg.x[ix::PA] = y1[0];
        seg.x[ix::PB] = y1[2];
        if key.open {
            let inv_i = 1.0 / a.inertance_kg_m4;
            let r_i = a.resistance_pa_s_m3 * inv_i;
            let (q0, q1) = (y0[1], y1[1]);
            let dq0 = inv_i * y0[0] - r_i * q0 + forcing(1, 0.0);
            let dq1 = inv_i * y1[0] - r_i * q1 + forcing(1, tau);
            let d_oil = hermite(q0, q1, dq0, dq1);
            seg.hyd_loss += a.resistance_pa_s_m3
                * (0.5 * tau * (q0 * q0 + q1 * q1) + t2 / 6.0 * (q0 * dq0 - q1 * dq1));
            seg.x[ix::ABS_Q] = q1;
            seg.x[ix::ABS_OIL] = x0[ix::ABS_OIL] + d_oil;
            seg.x[ix::ABS_PGAS] = x0[ix::ABS_PGAS]
                * gas_growth(
                    d_oil,
                    x0[ix::ABS_OIL],
                    a.gas.shell_volume_m3,
                    a.gas.exponent,
                    &self.exp.gas[0],
                );
        }
        if key.free {
            let (am, cm) = (c.area_m2 / c.mass_kg, c.viscous / c.mass_kg);
            let dv = |y: &[f64; 4], t: f64| am * (y[0] - y[2]) - cm * y[3] + forcing(3, t);
            seg.x[ix::V] = y1[3];
            seg.x[ix::X] = x0[ix::X] + hermite(y0[3], y1[3], dv(&y0, 0.0), dv(&y1, tau));
        }
        let d_fill = int(g0.q_fill, g1.q_fill, g2.q_fill);
        seg.x[ix::FILL_OIL] = x0[ix::FILL_OIL] + d_fill;
        let fill = &self.fill_gas;
        seg.x[ix::FILL_PGAS] = x0[ix::FILL_PGAS]
            * gas_growth(
                d_fill,
                x0[ix::FILL_OIL],
                fill.shell_volume_m3,
                fill.exponent,
                &self.exp.gas[1],
            );
        seg
    }

    /// The shaft-angle terms at `theta`, the rotor phasor turned from `at0`'s.
    #[inline]
    pub(super) fn angle_after(&self, at0: &AngleTerms, theta: f64) -> AngleTerms {
        self.angle_terms_of(theta, at0.rot_m * Phasor::small(theta - at0.theta))
    }
}
