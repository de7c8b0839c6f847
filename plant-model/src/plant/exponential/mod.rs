//! The plant's default integrator: the fast linear subsystems solved exactly over each step,
//! the rest by a third-order exponential Adams–Bashforth scheme, one evaluation of the
//! model per step, switching events located inside the step.
//!
//! # Why
//! Classical RK4 ([`super::rk4`]) evaluates the whole model four times per 50 µs step. But
//! only two parts of the plant move on the step's time scale: the winding currents (the
//! inverter's voltage changes every PWM period, the rotor turns the voltage in the d-q frame,
//! and the speed couples the axes) and port A's node against the oil column of the absorber's
//! inlet (1/√(I·C_oil) ≈ 1.9e3 rad/s, damping ratio 0.02 at the nominal rig). Both are
//! linear at a given speed and chamber volume, so their exact solution over a step is cheap
//! ([`blocks`]); everything else — the shaft, port B, the piston, the gases, the valves,
//! the angle-dependent torques and flows — changes on millisecond scales and is well served
//! by a polynomial extrapolation of its rates over the step.
//!
//! # The scheme
//! With the state split into the blocks y (i_d, i_q; p_A, q_abs) and the rest z, and g the
//! model's rates at a state without the blocks' own linear terms ([`rates`]), one step of
//! length τ from t_0 takes the quadratic g(t) ≈ g_0 + g_1·t + g_2·t² through the rates at
//! the last three step boundaries (Newton's divided differences on the actual step lengths)
//! and integrates it:
//!
//! ```text
//! y(τ) = e^{τA}·y_0 + τ·φ₁(τA)·g_0 + τ²·φ₂(τA)·g_1 + 2τ³·φ₃(τA)·g_2   (exact for it)
//! z(τ) = z_0 + τ·g_0 + τ²/2·g_1 + τ³/3·g_2                      (Adams–Bashforth 3)
//! ```
//!
//! which is third-order accurate in the slow part and exact in the linear blocks: their
//! oscillation and decay carry no phase or amplitude error, whatever the step. Third order
//! because the payload on its oil springs (≈ 270 rad/s at the nominal rig) is almost
//! undamped (ζ ≈ 1e-4): a second-order scheme's phase error, (5/12)·(ωh)³ per step, would
//! add up over a stroke to tens of pascals of its pressure ringing; the third order's,
//! (3/8)·(ωh)⁴, stays a hundred times smaller. AB3 is stable for |λh| < 0.54 on the real
//! axis and |ωh| < 0.72 on the imaginary one, beyond everything left in the slow part at the
//! 50 µs step (check valve near an end stop 0.35, dead time's current band 0.27). The shaft
//! takes the electromagnetic torque from the winding series itself, integrated over the
//! step by Simpson's rule (the current responds to a new duty within the step, which no
//! extrapolation from the past could see), and the rest of its torque extrapolated:
//!
//! ```text
//! ω(τ) = ω_0 + (∫T_e dt + τ·L_0 + τ²/2·L_1 + τ³/3·L_2)/J
//! θ(τ) = θ_0 + τ·ω_0 + (∫(τ − t)·T_e dt + τ²/2·L_0 + τ³/6·L_1 + τ⁴/12·L_2)/J
//! ```
//!
//! with the speed over the step taken as ω_0 + α_0·t in the winding series (α_0 the shaft's
//! acceleration at the step's start). The absorber's oil is the integral of its inlet flow by
//! the Hermite rule τ/2·(q_0 + q_1) + τ²/12·(q̇_0 − q̇_1) on the block's exact flow, and each
//! gas follows its polytropic law along the oil it takes, p_1 = p_0·(1 − ΔV/V_g)^(−n), so
//! pressure and volume never drift apart. Energies: input and copper loss by Simpson's rule
//! on the winding series, the absorber inlet's loss R·∫q² by the Hermite rule, friction's
//! and the external work exactly (their forces are constant within a segment: F·Δx, T·Δθ),
//! the other losses by the same extrapolation as the states.
//!
//! The first step, and every step after a switching event or a change of the bridge's enable,
//! has no rates from the past: it takes the secant of a predictor instead (Heun's method on
//! the slow part, one more evaluation), the next one the linear extrapolation (order two),
//! then the quadratic.
//!
//! # Events
//! As in RK4, switching inside a step is located by regula falsi on event functions that
//! cross zero there: a sliding body's velocity (it sticks or reverses), a stuck body's drive
//! against its breakaway, the absorber running empty while its poppet is open and its gas
//! giving way to the port while it is shut, and the piston meeting or leaving an end stop.
//! The step is cut there, the projection of [`Plant::project`] enforces the constraint and
//! books its energy, and the rest of the step restarts from the new state.
//!
//! # Where it applies
//! The inverter drive without faults, bridge enabled or with its currents died out. The
//! faulted plant, the replays' prescribed currents, speed and piston, and a disabled bridge
//! whose currents still free-wheel through the diodes take the RK4 path for those steps.
//!
//! # Accuracy
//! Against RK4 at a quarter of the step on the closed loop's own duty sequence
//! (`cargo run --release -p tests --example integrator_accuracy`, its table in
//! `docs/plant-model.md`), and in this crate's physics tests (energy and oil balances, the
//! analytic responses), which run on this integrator.

mod blocks;
mod rates;
mod segment;
mod winding;

use super::{
    ix, AngleTerms, Aux, Drive, Inputs, Plant, RotorPhasor, Vector, EVENT_REFINEMENTS,
    EVENT_TOLERANCE, MAX_EVENTS_PER_STEP, ROTOR_RESYNC_STEPS,
};
use crate::accumulator::ATMOSPHERE_PA;
use crate::friction::{Friction, Slip};
use crate::motor::Phasor;
use blocks::{phi, Mat, Phi};
use rates::Rates;

/// Event functions: shaft friction, piston friction, absorber poppet, piston end stop.
const EVENTS: usize = 4;

/// The hydraulic block is rebuilt when β/V_1 or β/V_2 has moved this far from the one it
/// was built at (the difference is carried in the forcing meanwhile). [1]
const BLOCK_REBUILD: f64 = 1e-3;

/// What the integrator carries from step to step.
#[derive(Clone, Debug, Default)]
pub(super) struct History {
    /// The rates at the present state, with the bridge enable and the hydraulic block they
    /// were taken for (every change of the state outside a step resets them).
    now: Option<Now>,
    /// The divided difference of the rates over the last step and its length; `None`: the
    /// next step restarts.
    last: Option<(Rates, f64)>,
    /// The same over the step before.
    before: Option<(Rates, f64)>,
    /// The hydraulic block's matrix functions.
    block: Option<HydroBlock>,
    /// The winding's constants.
    winding: WindingConsts,
}

/// The winding's constants, computed once.
#[derive(Clone, Copy, Debug, Default)]
struct WindingConsts {
    /// 1/L_d, 1/L_q. [1/H]
    inv_l: [f64; 2],
    /// L_q/L_d, −L_d/L_q. [1]
    coupling: [f64; 2],
    /// −R/L_d, −R/L_q. [1/s]
    decay: [f64; 2],
    /// The fastest the series sees from resistance, with the dead time's band:
    /// (R + r_band)·max(1/L). [1/s]
    nu_r: f64,
    /// max(L_q/L_d, L_d/L_q). [1]
    nu_w: f64,
}

#[derive(Clone, Copy, Debug)]
struct Now {
    rates: Rates,
    enabled: bool,
    key: BlockKey,
}

/// What the hydraulic block is built for.
#[derive(Clone, Copy, Debug, PartialEq)]
struct BlockKey {
    /// β/V_1 and β/V_2. [Pa/m³]
    k: [f64; 2],
    /// The absorber's poppet open.
    open: bool,
    /// The piston free to move (not blocked, not stuck): the 4×4 block, else the 2×2.
    free: bool,
}

/// The hydraulic block's matrix functions.
// Held once, in the history; boxing the larger variant would need an allocator, which this
// `no_std` crate does without.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
enum BlockPhi {
    /// (p_A, q).
    Two(Phi<2>),
    /// (p_A, q, p_B, v).
    Four(Phi<4>),
}

#[derive(Clone, Copy, Debug)]
struct HydroBlock {
    key: BlockKey,
    /// Its step. [s]
    tau: f64,
    phi: BlockPhi,
}

impl History {
    /// A history for a plant with `motor` driven by `inverter`, empty.
    pub(super) fn new(motor: &crate::motor::Motor, inverter: &crate::inverter::Inverter) -> Self {
        let inv_l = [1.0 / motor.l_d_h, 1.0 / motor.l_q_h];
        let coupling = [motor.l_q_h / motor.l_d_h, -motor.l_d_h / motor.l_q_h];
        let band = if inverter.has_dead_time() {
            inverter.dead_time_parts(&[0.0; 3]).1
        } else {
            0.0
        };
        History {
            winding: WindingConsts {
                inv_l,
                coupling,
                decay: [-motor.r_s_ohm * inv_l[0], -motor.r_s_ohm * inv_l[1]],
                nu_r: (motor.r_s_ohm + band) * inv_l[0].max(inv_l[1]),
                nu_w: coupling[0].max(-coupling[1]),
            },
            ..History::default()
        }
    }

    /// Forgets the rates and their slope (the state changed from outside).
    pub(super) fn reset(&mut self) {
        self.now = None;
        self.last = None;
        self.before = None;
    }

    /// The extrapolation's coefficients from the history, if there is any.
    fn poly(&self) -> Option<Poly> {
        let (d1, h1) = self.last?;
        Some(match self.before {
            // g(t) = g_0 + d1·t + dd·t·(t + h1), dd the second divided difference.
            Some((d0, h0)) => {
                let inv = 1.0 / (h1 + h0);
                let dd = d1.map2(&d0, |a, b| (a - b) * inv);
                Poly {
                    g1: d1.map2(&dd, |a, b| a + b * h1),
                    g2: dd,
                }
            }
            None => Poly {
                g1: d1,
                g2: Rates::default(),
            },
        })
    }

    /// Takes a step of `tau` from rates `g0` to `g1` into the history.
    fn push(&mut self, g0: &Rates, g1: &Rates, tau: f64) {
        self.before = self.last;
        let inv = 1.0 / tau;
        self.last = Some((g1.map2(g0, |a, b| (a - b) * inv), tau));
    }
}

/// The linear and quadratic coefficients of the rates' extrapolation over a segment.
#[derive(Clone, Copy, Debug, Default)]
struct Poly {
    g1: Rates,
    g2: Rates,
}

/// Whether the absorber's poppet lets oil through during a segment.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Port {
    /// Open: port A and the inlet flow are the exact block.
    Open,
    /// Shut (or no absorber): the inlet flow is held, port A is explicit.
    Shut,
}

/// The state at a segment's end, its shaft-angle terms, and the energies it books besides
/// friction's and the external work.
#[derive(Clone, Copy, Debug)]
struct Segment {
    x: Vector,
    at: AngleTerms,
    /// Input energy, copper loss, damping and stop losses, hydraulic losses. [J]
    e_in: f64,
    e_cu: f64,
    visc_loss: f64,
    hyd_loss: f64,
}

/// What a segment starts from.
#[derive(Clone, Copy, Debug)]
struct Start<'a> {
    x: &'a Vector,
    at: &'a AngleTerms,
    g: &'a Rates,
    inputs: &'a Inputs,
    port: Port,
    key: BlockKey,
    enabled: bool,
}

impl Plant {
    /// One step of `h` with the exponential scheme, events located inside it.
    pub(super) fn exp_step(&mut self, h: f64, inputs: &Inputs) {
        let enabled = matches!(inputs.drive, Drive::Inverter { enabled: true, .. });
        let mut remaining = h;
        for _ in 0..MAX_EVENTS_PER_STEP {
            let mut port = self.port_mode(&self.x);
            let mut key = self.block_key(h, port);
            let mut g0 = self.rates_now(enabled, key);
            let mut e0 = self.exp_events(&self.x, &g0, inputs, port, &self.x);
            // A body at rest whose drive already exceeds breakaway is released first.
            if e0[..2].iter().any(|e| *e <= 0.0) && self.exp_project(inputs, &g0) {
                port = self.port_mode(&self.x);
                key = self.block_key(h, port);
                g0 = self.rates_now(enabled, key);
                e0 = self.exp_events(&self.x, &g0, inputs, port, &self.x);
            }
            let x0 = self.x;
            let at0 = self.angle;
            let start = Start {
                x: &x0,
                at: &at0,
                g: &g0,
                inputs,
                port,
                key,
                enabled,
            };
            let poly = self.exp.poly();
            let (seg, g1, used, mid) = self.exp_full_segment(&start, poly, remaining);
            let e1 = self.exp_events(&seg.x, &g1, inputs, port, &x0);
            let mut first: Option<(usize, f64)> = None;
            for k in 0..EVENTS {
                if e0[k] > 0.0 && e1[k] <= 0.0 {
                    let f = e0[k] / (e0[k] - e1[k]);
                    if first.is_none_or(|(_, best)| f < best) {
                        first = Some((k, f));
                    }
                }
            }
            let Some((k, f_guess)) = first else {
                self.exp_commit(&start, &seg, g1, remaining, mid);
                self.exp_project(inputs, &g1);
                return;
            };
            let hi = self.locate(&start, &used, remaining, k, (e0[k], e1[k]), f_guess);
            let tau = hi * remaining;
            let seg = self.exp_segment(&start, &used, tau);
            let g1 = self.exp_rates(&seg.x, &seg.at, enabled, start.key.k);
            self.exp_commit(&start, &seg, g1, tau, None);
            self.exp_project(inputs, &g1);
            // The rates' history ends at a switch.
            self.exp.reset();
            remaining -= tau;
            if remaining <= 1e-12 * h {
                return;
            }
        }
        // More events than expected in one step: finish it in one piece.
        let port = self.port_mode(&self.x);
        let key = self.block_key(h, port);
        let g0 = self.rates_now(enabled, key);
        let x0 = self.x;
        let at0 = self.angle;
        let start = Start {
            x: &x0,
            at: &at0,
            g: &g0,
            inputs,
            port,
            key,
            enabled,
        };
        let (seg, g1, _, mid) = self.exp_full_segment(&start, None, remaining);
        self.exp_commit(&start, &seg, g1, remaining, mid);
        self.exp_project(inputs, &g1);
    }

    /// The segment of `tau` with the extrapolation `poly`, or, without one (a restart),
    /// Kutta's third-order stages: the rates at the half step predicted with the start's,
    /// then at the end predicted with 2·g(τ/2) − g(0), and the quadratic through the three.
    /// Returns the end, its rates, the extrapolation used, and for a restart the rates at
    /// the half step taken on the final trajectory (the history's middle point).
    #[inline(always)]
    fn exp_full_segment(
        &self,
        start: &Start,
        poly: Option<Poly>,
        tau: f64,
    ) -> (Segment, Rates, Poly, Option<Rates>) {
        let (used, restart) = match poly {
            Some(p) => (p, false),
            None => {
                let rates_at = |poly: &Poly, t: f64| {
                    let seg = self.exp_segment(start, poly, t);
                    self.exp_rates(&seg.x, &seg.at, start.enabled, start.key.k)
                };
                let g0 = start.g;
                let ga = rates_at(&Poly::default(), 0.5 * tau);
                let gb = rates_at(
                    &Poly {
                        g1: ga.map2(g0, |a, b| 4.0 * (a - b) / tau),
                        g2: Rates::default(),
                    },
                    tau,
                );
                (quadratic(g0, &ga, &gb, tau), true)
            }
        };
        let seg = self.exp_segment(start, &used, tau);
        let g1 = self.exp_rates(&seg.x, &seg.at, start.enabled, start.key.k);
        let mid = restart.then(|| {
            let half = self.exp_segment(start, &used, 0.5 * tau);
            self.exp_rates(&half.x, &half.at, start.enabled, start.key.k)
        });
        (seg, g1, used, mid)
    }

    /// The fraction of the segment at which event `k` has just happened, by the Illinois
    /// variant of regula falsi on the bracket (0, 1] with values `e`.
    fn locate(
        &self,
        start: &Start,
        poly: &Poly,
        tau: f64,
        k: usize,
        e: (f64, f64),
        f_guess: f64,
    ) -> f64 {
        let (mut lo, mut hi) = ((0.0, e.0), (1.0, e.1));
        let mut f = f_guess;
        let mut kept = 0i8;
        for _ in 0..EVENT_REFINEMENTS {
            if hi.0 - lo.0 <= EVENT_TOLERANCE {
                break;
            }
            let seg = self.exp_segment(start, poly, f * tau);
            let g = self.exp_rates(&seg.x, &seg.at, start.enabled, start.key.k);
            let v = self.exp_events(&seg.x, &g, start.inputs, start.port, start.x)[k];
            if v > 0.0 {
                lo = (f, v);
                kept = if kept > 0 { kept + 1 } else { 1 };
                if kept > 1 {
                    hi.1 *= 0.5;
                }
            } else {
                hi = (f, v);
                kept = if kept < 0 { kept - 1 } else { -1 };
                if kept < -1 {
                    lo.1 *= 0.5;
                }
            }
            f = lo.0 + (hi.0 - lo.0) * lo.1 / (lo.1 - hi.1);
        }
        hi.0
    }

    /// The shaft-angle terms at `theta`, the rotor phasor turned from `at0`'s.
    #[inline]
    fn angle_after(&self, at0: &AngleTerms, theta: f64) -> AngleTerms {
        self.angle_terms_of(theta, at0.rot_m * Phasor::small(theta - at0.theta))
    }

    /// Whether the absorber's poppet is open at `x` (as in [`crate::accumulator::Absorber`]'s
    /// flow equation: shut with the absorber empty, its flow not entering and the port below
    /// the gas).
    fn port_mode(&self, x: &Vector) -> Port {
        if !self.absorber.enabled {
            return Port::Shut;
        }
        let q = x[ix::ABS_Q];
        let drive =
            x[ix::PA] - (x[ix::ABS_PGAS] - ATMOSPHERE_PA) - self.absorber.resistance_pa_s_m3 * q;
        if x[ix::ABS_OIL] <= 0.0 && q <= 0.0 && drive < 0.0 {
            Port::Shut
        } else {
            Port::Open
        }
    }

    /// The hydraulic block for steps of `h` with the poppet `port`: rebuilt when the poppet
    /// or the piston's freedom changed or a chamber has moved.
    fn block_key(&mut self, h: f64, port: Port) -> BlockKey {
        let (v1, v2) = self.cylinder.volumes(self.x[ix::X]);
        let k = [self.beta / v1, self.beta / v2];
        let free = !(self.cylinder.blocked
            || (self.discrete.piston == Slip::Stuck && self.piston_friction.is_active()));
        let open = port == Port::Open;
        if let Some(b) = &self.exp.block {
            let near = |a: f64, b: f64| libm::fabs(a - b) <= BLOCK_REBUILD * b;
            let key = b.key;
            if key.open == open
                && key.free == free
                && near(k[0], key.k[0])
                && near(k[1], key.k[1])
                && b.tau == h
            {
                return key;
            }
        }
        let key = BlockKey { k, open, free };
        self.exp.block = Some(HydroBlock {
            key,
            tau: h,
            phi: self.block_phi_new(&key, h),
        });
        self.exp.reset();
        key
    }

    /// The hydraulic block's matrix (see [`blocks`]).
    fn hydro_matrix(&self, key: &BlockKey) -> Mat<4> {
        let mut m = [[0.0; 4]; 4];
        if key.open {
            let a = &self.absorber;
            m[0][1] = -key.k[0];
            m[1][0] = 1.0 / a.inertance_kg_m4;
            m[1][1] = -a.resistance_pa_s_m3 / a.inertance_kg_m4;
        }
        if key.free {
            let c = &self.cylinder;
            m[0][3] = -key.k[0] * c.area_m2;
            m[2][3] = key.k[1] * c.area_m2;
            m[3][0] = c.area_m2 / c.mass_kg;
            m[3][2] = -c.area_m2 / c.mass_kg;
            m[3][3] = -c.viscous / c.mass_kg;
        }
        m
    }

    /// The block's matrix functions at step `tau`, computed.
    fn block_phi_new(&self, key: &BlockKey, tau: f64) -> BlockPhi {
        let m = self.hydro_matrix(key);
        if key.free {
            BlockPhi::Four(phi(&m, tau))
        } else {
            BlockPhi::Two(phi(&[[m[0][0], m[0][1]], [m[1][0], m[1][1]]], tau))
        }
    }

    /// The block's matrix functions at step `tau` (kept for the standard step).
    fn block_phi(&self, key: &BlockKey, tau: f64) -> Option<&BlockPhi> {
        match &self.exp.block {
            Some(b) if b.key == *key && b.tau == tau => Some(&b.phi),
            _ => None,
        }
    }

    /// The rates at the present state (kept from the last step when they belong to it; taken
    /// afresh, they start a new history).
    fn rates_now(&mut self, enabled: bool, key: BlockKey) -> Rates {
        if let Some(n) = &self.exp.now {
            if n.enabled == enabled && n.key == key {
                return n.rates;
            }
        }
        let at = self.angle_terms(self.x[ix::THETA]);
        let rates = self.exp_rates(&self.x, &at, enabled, key.k);
        self.exp.reset();
        self.exp.now = Some(Now {
            rates,
            enabled,
            key,
        });
        rates
    }

    /// Takes the segment's end as the present state: energies booked, the rotor phasor
    /// carried, the rates kept for the next step.
    #[inline(always)]
    fn exp_commit(
        &mut self,
        start: &Start,
        seg: &Segment,
        mut g1: Rates,
        tau: f64,
        mid: Option<Rates>,
    ) {
        let at1 = seg.at;
        let (x0, g0, inputs) = (start.x, start.g, start.inputs);
        let mut x = seg.x;
        let (d_theta, d_x) = (x[ix::THETA] - x0[ix::THETA], x[ix::X] - x0[ix::X]);
        x[ix::E_IN] += seg.e_in;
        x[ix::E_CU] += seg.e_cu;
        x[ix::E_MECH] += seg.visc_loss
            + self.shaft_friction.force(self.discrete.shaft) * d_theta
            + self.piston_friction.force(self.discrete.piston) * d_x;
        x[ix::E_HYD] += seg.hyd_loss;
        x[ix::E_EXT] += -inputs.external_force_n * d_x - inputs.external_torque_nm * d_theta;
        self.x = x;
        let theta = x[ix::THETA];
        if self.rotor.rotations >= ROTOR_RESYNC_STEPS {
            // The phasor taken afresh from the angle moves the angle terms by rounding: the
            // end's rates follow them.
            self.rotor = RotorPhasor::at(theta);
            self.angle = self.angle_terms_of(theta, self.rotor.phasor);
            g1 = self.exp_rates(&self.x, &self.angle, start.enabled, start.key.k);
        } else {
            self.rotor = RotorPhasor {
                theta,
                phasor: at1.rot_m,
                rotations: self.rotor.rotations + 1,
            };
            self.angle = at1;
        }
        match mid {
            Some(gm) => {
                self.exp.reset();
                self.exp.push(g0, &gm, 0.5 * tau);
                self.exp.push(&gm, &g1, 0.5 * tau);
            }
            None => self.exp.push(g0, &g1, tau),
        }
        self.exp.now = Some(Now {
            rates: g1,
            enabled: start.enabled,
            key: start.key,
        });
    }

    /// The projection at a segment's end with the drives of `g`; true when it changed the
    /// state (the rates and their history are dropped then).
    fn exp_project(&mut self, inputs: &Inputs, g: &Rates) -> bool {
        if !self.exp_may_project(inputs) {
            return false;
        }
        let before = (self.x, self.discrete);
        let aux = Aux {
            shaft_drive: g.shaft_drive + inputs.external_torque_nm,
            piston_drive: g.piston_drive + inputs.external_force_n,
        };
        self.project_with(inputs, aux);
        let changed = !same_state(&before.0, &self.x) || before.1 != self.discrete;
        if changed {
            self.exp.reset();
        }
        changed
    }

    /// Whether [`Plant::project_with`] may change anything at the present state: a body at
    /// rest or whose velocity reached zero, an empty absorber drawing oil, a bridge off, a
    /// node below the cavitation floor, a transducer without lag (its reading follows the
    /// port). Otherwise the projection is the identity and is skipped.
    fn exp_may_project(&self, inputs: &Inputs) -> bool {
        let x = &self.x;
        let turning = |slip: Slip, v: f64| match slip {
            Slip::Stuck => true,
            Slip::Sliding(dir) => v * dir <= 0.0,
        };
        let floor = -0.99 * ATMOSPHERE_PA;
        (self.shaft_friction.is_active() && turning(self.discrete.shaft, x[ix::OMEGA]))
            || (!self.cylinder.blocked
                && self.piston_friction.is_active()
                && turning(self.discrete.piston, x[ix::V]))
            || (self.absorber.enabled && x[ix::ABS_OIL] <= 0.0)
            || !matches!(inputs.drive, Drive::Inverter { enabled: true, .. })
            || x[ix::PA] < floor
            || x[ix::PB] < floor
    }

    /// Event functions at `x` with rates `g`, for a segment that started at `x0` with the
    /// poppet `port`: positive while nothing switches.
    fn exp_events(
        &self,
        x: &Vector,
        g: &Rates,
        inputs: &Inputs,
        port: Port,
        x0: &Vector,
    ) -> [f64; EVENTS] {
        let mut e = [1.0; EVENTS];
        let event = |f: &Friction, slip: Slip, velocity: f64, drive: f64| match slip {
            Slip::Sliding(dir) => velocity * dir,
            Slip::Stuck => f.breakaway - libm::fabs(drive),
        };
        if self.shaft_friction.is_active() {
            e[0] = event(
                &self.shaft_friction,
                self.discrete.shaft,
                x[ix::OMEGA],
                g.shaft_drive + inputs.external_torque_nm,
            );
        }
        let c = &self.cylinder;
        if !c.blocked && self.piston_friction.is_active() {
            e[1] = event(
                &self.piston_friction,
                self.discrete.piston,
                x[ix::V],
                g.piston_drive + inputs.external_force_n,
            );
        }
        if self.absorber.enabled {
            e[2] = match port {
                // Scaled so that a full absorber reads 1.
                Port::Open => x[ix::ABS_OIL] / self.absorber.gas.shell_volume_m3,
                // The gas's excess over the port's pressure, in MPa.
                Port::Shut => {
                    let drive = x[ix::PA]
                        - (x[ix::ABS_PGAS] - ATMOSPHERE_PA)
                        - self.absorber.resistance_pa_s_m3 * x[ix::ABS_Q];
                    -1e-6 * drive
                }
            };
        }
        if !c.blocked {
            let inside = libm::fabs(x0[ix::X]) <= c.half_stroke_m;
            let margin = (c.half_stroke_m - libm::fabs(x[ix::X])) / c.half_stroke_m;
            e[3] = if inside { margin } else { -margin };
        }
        e
    }
}

/// The quadratic g(0) + g_1·t + g_2·t² through rates `g0`, `ga`, `gb` at 0, τ/2 and τ.
fn quadratic(g0: &Rates, ga: &Rates, gb: &Rates, tau: f64) -> Poly {
    let d1 = ga.map2(g0, |a, b| (a - b) / (0.5 * tau));
    let d2 = gb.map2(ga, |a, b| (a - b) / (0.5 * tau));
    let g2 = d2.map2(&d1, |a, b| (a - b) / tau);
    Poly {
        g1: d1.map2(&g2, |a, b| a - b * 0.5 * tau),
        g2,
    }
}

/// Whether two states are the same for the rates (the transducer's lag is filtered after the
/// step and enters no rate).
fn same_state(a: &Vector, b: &Vector) -> bool {
    a.iter()
        .zip(b)
        .enumerate()
        .all(|(k, (a, b))| k == ix::P_SENSOR || a == b)
}
