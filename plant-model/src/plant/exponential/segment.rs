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
use super::winding::{Shaft, WindingOut};
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

/// A segment's length τ with its powers, for the integrals over it.
#[derive(Clone, Copy, Debug)]
struct Span {
    /// τ. [s]
    tau: f64,
    /// τ². [s²]
    t2: f64,
    /// τ³. [s³]
    t3: f64,
}

impl Span {
    /// The span of `tau`.
    #[inline(always)]
    fn new(tau: f64) -> Span {
        let t2 = tau * tau;
        let t3 = t2 * tau;
        Span { tau, t2, t3 }
    }

    /// ∫ over the segment of c0 + c1·t + c2·t²: τ·c0 + τ²/2·c1 + τ³/3·c2.
    #[inline(always)]
    fn int(&self, c0: f64, c1: f64, c2: f64) -> f64 {
        self.tau * c0 + 0.5 * self.t2 * c1 + self.t3 / 3.0 * c2
    }

    /// ∫ over the segment of (τ − t)·(c0 + c1·t + c2·t²): τ²/2·c0 + τ³/6·c1 + τ⁴/12·c2.
    #[inline(always)]
    fn moment(&self, c0: f64, c1: f64, c2: f64) -> f64 {
        0.5 * self.t2 * c0 + self.t3 / 6.0 * c1 + self.t3 * self.tau / 12.0 * c2
    }

    /// The Hermite rule on a quantity `a0`, `a1` with rates `d0`, `d1` at the segment's
    /// ends: τ/2·(a0 + a1) + τ²/12·(d0 − d1).
    #[inline(always)]
    fn hermite(&self, a0: f64, a1: f64, d0: f64, d1: f64) -> f64 {
        0.5 * self.tau * (a0 + a1) + self.t2 / 12.0 * (d0 - d1)
    }
}

/// The shaft at a segment's start.
#[derive(Clone, Copy, Debug)]
struct ShaftStart {
    /// Whether it turns (not held by its friction).
    free: bool,
    /// 1/J. [1/(kg·m²)]
    inv_j: f64,
    /// Its torque besides the electromagnetic, L_0 (zero while held). [N·m]
    l0: f64,
    /// Its acceleration α_0 (zero while held). [rad/s²]
    alpha0: f64,
}

/// The absorber's inlet over a segment with its poppet open.
#[derive(Clone, Copy, Debug)]
struct AbsorberEnd {
    /// The inlet's loss R·∫q² dt. [J]
    loss: f64,
    /// The inlet flow at the end. [m³/s]
    q: f64,
    /// The oil in the absorber at the end. [m³]
    oil: f64,
    /// Its gas pressure at the end. [Pa]
    p_gas: f64,
}

/// The hydraulic block's forcing coefficients f_0, f_1, f_2, each in block order
/// (p_A, q, p_B, v).
type BlockForcing = [[f64; 4]; 3];

impl Plant {
    /// Integrates one segment of `tau` from `start` with the extrapolation `poly`.
    #[inline(always)]
    pub(super) fn exp_segment(&self, start: &Start, poly: &Poly, tau: f64) -> Segment {
        let (x0, g0) = (start.x, start.g);
        let (g1, g2) = (&poly.g1, &poly.g2);
        // ∫ over the segment of c0 + c1·t + c2·t², and of (τ − t)·(…).
        let span = Span::new(tau);
        let sh = self.shaft_start(g0, start.inputs);
        let mut seg = Segment {
            x: *x0,
            at: *start.at,
            e_in: 0.0,
            e_cu: 0.0,
            visc_loss: span.int(g0.p_visc, g1.p_visc, g2.p_visc),
            hyd_loss: span.int(g0.p_hyd, g1.p_hyd, g2.p_hyd),
        };
        // --- winding currents, their torque and power
        let mut torque = (0.0, 0.0);
        // The shaft's speed at the segment's middle (from the winding series when it runs).
        let mut omega_mid = None;
        if let Some(o) = self.segment_winding(start, poly, &sh, tau) {
            seg.x[ix::ID] = o.i[0];
            seg.x[ix::IQ] = o.i[1];
            if sh.free {
                omega_mid = Some(o.omega_e_mid / self.motor.pole_pairs);
            }
            torque = (o.torque, o.torque_moment);
            seg.e_in = o.e_in;
            seg.e_cu = o.e_cu;
        }
        // --- shaft
        let w0 = x0[ix::OMEGA];
        if sh.free {
            (seg.x[ix::OMEGA], seg.x[ix::THETA]) = shaft_end(start.x, poly, &sh, torque, &span);
            seg.at = self.angle_after(start.at, seg.x[ix::THETA]);
        }
        let w_mid = mid_speed(&sh, omega_mid, w0, poly, tau);
        let (f0, f1) = (start.at.factor, seg.at.factor);
        let pump_c = self.pump_quadratic([w0, w_mid, seg.x[ix::OMEGA]], f0, f1, tau);
        // --- the hydraulic block: port A, the absorber's inlet, port B, the payload
        let key = &start.key;
        let f = self.block_forcing(start, poly, &pump_c);
        let y0 = [x0[ix::PA], x0[ix::ABS_Q], x0[ix::PB], x0[ix::V]];
        let y1 = self.block_solve(key, y0, &f, &span);
        seg.x[ix::PA] = y1[0];
        seg.x[ix::PB] = y1[2];
        if key.open {
            let ab = self.absorber_oil(x0, &y0, &y1, &f, &span);
            seg.hyd_loss += ab.loss;
            seg.x[ix::ABS_Q] = ab.q;
            seg.x[ix::ABS_OIL] = ab.oil;
            seg.x[ix::ABS_PGAS] = ab.p_gas;
        }
        if key.free {
            (seg.x[ix::V], seg.x[ix::X]) = self.piston_stroke(x0, &y0, &y1, &f, &span);
        }
        (seg.x[ix::FILL_OIL], seg.x[ix::FILL_PGAS]) = self.fill_gas(x0, g0, poly, &span);
        seg
    }

    /// The shaft at a segment's start: free unless held by its friction, its load torque
    /// L_0 = T_load + T_ext and acceleration α_0 = (T_e + L_0)/J (both zero while held).
    #[inline(always)]
    fn shaft_start(&self, g0: &Rates, inputs: &Inputs) -> ShaftStart {
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
        ShaftStart {
            free: shaft_free,
            inv_j,
            l0,
            alpha0,
        }
    }

    /// The winding currents over the segment while the inverter drives them (bridge
    /// enabled): the series' step ([`Plant::winding_step`]) with the shaft's acceleration
    /// ([`Plant::series_shaft`], none for a shaft held by friction); `None` otherwise.
    #[inline(always)]
    fn segment_winding(
        &self,
        start: &Start,
        poly: &Poly,
        sh: &ShaftStart,
        tau: f64,
    ) -> Option<WindingOut> {
        if let Drive::Inverter {
            duties,
            enabled: true,
        } = start.inputs.drive
        {
            // The shaft's acceleration: p_n/J times the torque's gradient in i and the
            // load's extrapolation (none for a shaft held by friction).
            let shaft = if sh.free {
                self.series_shaft(start, poly, sh)
            } else {
                Shaft::default()
            };
            Some(self.winding_step(start.x, start.at, start.g, poly, &duties, &shaft, tau))
        } else {
            None
        }
    }

    /// A free shaft as the winding series sees it: the electrical acceleration p_n·α_0, its
    /// gain per ampere 1.5·p_n²/J·∂T_e/∂i (from eq. 5's torque with the flux harmonics and
    /// the reluctance term) and the load's extrapolation p_n/J·(L_1, L_2).
    #[inline(always)]
    fn series_shaft(&self, start: &Start, poly: &Poly, sh: &ShaftStart) -> Shaft {
        let (x0, g1, g2) = (start.x, &poly.g1, &poly.g2);
        let (p, inv_j) = (self.motor.pole_pairs, sh.inv_j);
        let f = &start.at.flux;
        let dl = self.motor.l_d_h - self.motor.l_q_h;
        let k = 1.5 * p * p * inv_j;
        Shaft {
            alpha_e: p * sh.alpha0,
            gain: [
                k * (f.d_slope_wb - f.q_wb + dl * x0[ix::IQ]),
                k * (f.d_wb + f.q_slope_wb + dl * x0[ix::ID]),
            ],
            load: [p * inv_j * g1.t_load, p * inv_j * g2.t_load],
        }
    }

    /// The pump's geometric flow D·s(θ)·ω from the shaft's own speed (it follows the
    /// torque within the step, which the rates' extrapolation cannot), quadratic through
    /// the segment's start, middle and end: q(t) = c0 + c1·t + c2·t², as [c0, c1, c2], from
    /// the speeds `w` there and the displacement factors `f0`, `f1` at the ends.
    #[inline(always)]
    fn pump_quadratic(&self, w: [f64; 3], f0: f64, f1: f64, tau: f64) -> [f64; 3] {
        let pump = &self.pump;
        let q0 = pump.geometric_flow(w[0], f0);
        let qm = pump.geometric_flow(w[1], 0.5 * (f0 + f1));
        let q1 = pump.geometric_flow(w[2], f1);
        [
            q0,
            (4.0 * qm - 3.0 * q0 - q1) / tau,
            2.0 * (q0 + q1 - 2.0 * qm) / (tau * tau),
        ]
    }

    /// The hydraulic block's forcing over the segment: the rates' extrapolation with the
    /// pump's flow `pump_c` into the ports (k_A = β/V_1, k_B = β/V_2 at the start's
    /// stroke) and the external force on the payload.
    #[inline(always)]
    fn block_forcing(&self, start: &Start, poly: &Poly, pump_c: &[f64; 3]) -> BlockForcing {
        let (x0, g0, g1, g2) = (start.x, start.g, &poly.g1, &poly.g2);
        let (v1, v2) = self.cylinder.volumes(x0[ix::X]);
        let (k_a, k_b) = (self.beta / v1, self.beta / v2);
        let f_v0 = g0.f_v + start.inputs.external_force_n / self.cylinder.mass_kg;
        [
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
        ]
    }

    /// The hydraulic block's state at the segment's end from `y0` under the forcing `f`
    /// (the scheme of [`super`]): y(τ) = e^{τA}·y_0 + τ·φ₁·f_0 + τ²·φ₂·f_1 + 2τ³·φ₃·f_2, the
    /// φ functions of the block `key` cached or computed; with the piston still, only
    /// port A and the inlet flow, port B's forcing integrated.
    #[inline(always)]
    fn block_solve(&self, key: &BlockKey, y0: [f64; 4], f: &BlockForcing, span: &Span) -> [f64; 4] {
        let (tau, t2, t3) = (span.tau, span.t2, span.t3);
        let owned;
        let phi = match self.block_phi(key, tau) {
            Some(p) => p,
            None => {
                owned = self.block_phi_new(key, tau);
                &owned
            }
        };
        match phi {
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
                [
                    y(0),
                    y(1),
                    y0[2] + span.int(f[0][2], f[1][2], f[2][2]),
                    y0[3],
                ]
            }
        }
    }

    /// The absorber with its poppet open over the segment: the inlet flow q from the
    /// block's end `y1`, the oil it takes by the Hermite rule on q (its rate q̇ = p_A/I −
    /// R/I·q + the forcing), the inlet's loss R·∫q² by the same rule, and the gas along its
    /// polytropic law p_1 = p_0·(1 − ΔV/V_g)^(−n).
    #[inline(always)]
    fn absorber_oil(
        &self,
        x0: &Vector,
        y0: &[f64; 4],
        y1: &[f64; 4],
        f: &BlockForcing,
        span: &Span,
    ) -> AbsorberEnd {
        let a = &self.absorber;
        let (tau, t2) = (span.tau, span.t2);
        let inv_i = 1.0 / a.inertance_kg_m4;
        let r_i = a.resistance_pa_s_m3 * inv_i;
        let (q0, q1) = (y0[1], y1[1]);
        let dq0 = inv_i * y0[0] - r_i * q0 + forcing_at(f, 1, 0.0);
        let dq1 = inv_i * y1[0] - r_i * q1 + forcing_at(f, 1, tau);
        let d_oil = span.hermite(q0, q1, dq0, dq1);
        AbsorberEnd {
            loss: a.resistance_pa_s_m3
                * (0.5 * tau * (q0 * q0 + q1 * q1) + t2 / 6.0 * (q0 * dq0 - q1 * dq1)),
            q: q1,
            oil: x0[ix::ABS_OIL] + d_oil,
            p_gas: x0[ix::ABS_PGAS]
                * gas_growth(
                    d_oil,
                    x0[ix::ABS_OIL],
                    a.gas.shell_volume_m3,
                    a.gas.exponent,
                    &self.exp.gas[0],
                ),
        }
    }

    /// A free piston's speed and stroke at the segment's end: its speed from the block's end
    /// `y1`, its stroke by the Hermite rule on the speed with the acceleration
    /// A/m·(p_A − p_B) − B_p/m·v + the forcing at both ends.
    #[inline(always)]
    fn piston_stroke(
        &self,
        x0: &Vector,
        y0: &[f64; 4],
        y1: &[f64; 4],
        f: &BlockForcing,
        span: &Span,
    ) -> (f64, f64) {
        let c = &self.cylinder;
        let (am, cm) = (c.area_m2 / c.mass_kg, c.viscous / c.mass_kg);
        let dv = |y: &[f64; 4], t: f64| am * (y[0] - y[2]) - cm * y[3] + forcing_at(f, 3, t);
        (
            y1[3],
            x0[ix::X] + span.hermite(y0[3], y1[3], dv(y0, 0.0), dv(y1, span.tau)),
        )
    }

    /// The fill accumulator's oil and gas pressure at the segment's end: its oil by the
    /// extrapolated inflow's integral, its gas along its polytropic law
    /// p_1 = p_0·(1 − ΔV/V_g)^(−n).
    #[inline(always)]
    fn fill_gas(&self, x0: &Vector, g0: &Rates, poly: &Poly, span: &Span) -> (f64, f64) {
        let (g1, g2) = (&poly.g1, &poly.g2);
        let d_fill = span.int(g0.q_fill, g1.q_fill, g2.q_fill);
        let fill = &self.fill_gas;
        (
            x0[ix::FILL_OIL] + d_fill,
            x0[ix::FILL_PGAS]
                * gas_growth(
                    d_fill,
                    x0[ix::FILL_OIL],
                    fill.shell_volume_m3,
                    fill.exponent,
                    &self.exp.gas[1],
                ),
        )
    }

    /// The shaft-angle terms at `theta`, the rotor phasor turned from `at0`'s.
    #[inline]
    pub(super) fn angle_after(&self, at0: &AngleTerms, theta: f64) -> AngleTerms {
        self.angle_terms_of(theta, at0.rot_m * Phasor::small(theta - at0.theta))
    }
}

/// The shaft's speed at the segment's middle: a free shaft's from the winding series
/// (`omega_mid`) or, without it, ω_0 + (h·L_0 + h²/2·L_1 + h³/3·L_2)/J at h = τ/2; a held
/// shaft's ω_0.
#[inline(always)]
fn mid_speed(sh: &ShaftStart, omega_mid: Option<f64>, w0: f64, poly: &Poly, tau: f64) -> f64 {
    let (g1, g2) = (&poly.g1, &poly.g2);
    let (l0, inv_j) = (sh.l0, sh.inv_j);
    let w_mid = omega_mid.unwrap_or_else(|| {
        let h = 0.5 * tau;
        w0 + (h * l0 + 0.5 * h * h * g1.t_load + h * h * h / 3.0 * g2.t_load) * inv_j
    });
    if sh.free {
        w_mid
    } else {
        w0
    }
}

/// Row `k` of the block's forcing at `t`: f_0 + t·(f_1 + t·f_2).
#[inline(always)]
fn forcing_at(f: &BlockForcing, k: usize, t: f64) -> f64 {
    f[0][k] + t * (f[1][k] + t * f[2][k])
}

/// A free shaft's speed and angle at the segment's end (the scheme of [`super`]):
/// ω(τ) = ω_0 + (∫T_e dt + ∫L dt)/J and θ(τ) = θ_0 + τ·ω_0 + (∫(τ − t)·T_e dt +
/// ∫(τ − t)·L dt)/J, from the winding's `torque` integrals and the load's extrapolation.
#[inline(always)]
fn shaft_end(
    x0: &Vector,
    poly: &Poly,
    sh: &ShaftStart,
    torque: (f64, f64),
    span: &Span,
) -> (f64, f64) {
    let (g1, g2) = (&poly.g1, &poly.g2);
    let (l0, inv_j, tau) = (sh.l0, sh.inv_j, span.tau);
    let w0 = x0[ix::OMEGA];
    let (i_t, i2_t) = torque;
    (
        w0 + (i_t + span.int(l0, g1.t_load, g2.t_load)) * inv_j,
        x0[ix::THETA] + tau * w0 + (i2_t + span.moment(l0, g1.t_load, g2.t_load)) * inv_j,
    )
}
