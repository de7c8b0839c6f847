//! One step of the exponential scheme: the segment to the step's end with the rates'
//! extrapolation (or, on a restart, Kutta's third-order stages), the switching events located
//! inside it by regula falsi and the step cut there, and the segment's end committed as the
//! present state with its energies, rotor phasor and rates.

use super::super::actuator::Plant;
use super::super::inputs::{Drive, Inputs};
use super::super::integrator::{EVENT_REFINEMENTS, EVENT_TOLERANCE, MAX_EVENTS_PER_STEP};
use super::super::state::{ix, RotorPhasor, ROTOR_RESYNC_STEPS};
use super::events::EVENTS;
use super::history::{quadratic, BlockKey, Now, Poly};
use super::rates::Rates;
use super::segment::{Segment, Start};

impl Plant {
    /// One step of `h` with the exponential scheme, events located inside it.
    pub(in crate::plant) fn exp_step(&mut self, h: f64, inputs: &Inputs) {
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
            let (seg, g1, restart) = self.exp_full_segment(&start, poly.as_ref(), remaining);
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
                let mid = restart.as_ref().map(|r| &r.mid);
                self.exp_commit(&start, &seg, g1, remaining, mid);
                self.exp_project(inputs, &g1);
                return;
            };
            let used = match restart {
                Some(r) => r.poly,
                None => poly.unwrap_or_default(),
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
        let (seg, g1, restart) = self.exp_full_segment(&start, None, remaining);
        let mid = restart.as_ref().map(|r| &r.mid);
        self.exp_commit(&start, &seg, g1, remaining, mid);
        self.exp_project(inputs, &g1);
    }

    /// The segment of `tau` with the extrapolation `poly`, or, without one (a restart),
    /// Kutta's third-order stages: the rates at the half step predicted with the start's,
    /// then at the end predicted with 2·g(τ/2) − g(0), and the quadratic through the three.
    /// Returns the end, its rates, and for a restart the extrapolation it took with the
    /// rates at the half step on the final trajectory (the history's middle point).
    #[inline(always)]
    pub(super) fn exp_full_segment(
        &self,
        start: &Start,
        poly: Option<&Poly>,
        tau: f64,
    ) -> (Segment, Rates, Option<Restart>) {
        let taken;
        let used = match poly {
            Some(p) => p,
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
                taken = quadratic(g0, &ga, &gb, tau);
                &taken
            }
        };
        let seg = self.exp_segment(start, used, tau);
        let g1 = self.exp_rates(&seg.x, &seg.at, start.enabled, start.key.k);
        let restart = poly.is_none().then(|| {
            let half = self.exp_segment(start, used, 0.5 * tau);
            Restart {
                poly: *used,
                mid: self.exp_rates(&half.x, &half.at, start.enabled, start.key.k),
            }
        });
        (seg, g1, restart)
    }

    /// The fraction of the segment at which event `k` has just happened, by the Illinois
    /// variant of regula falsi on the bracket (0, 1] with values `e`.
    pub(super) fn locate(
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

    /// The rates at the present state (kept from the last step when they belong to it; taken
    /// afresh, they start a new history).
    pub(super) fn rates_now(&mut self, enabled: bool, key: BlockKey) -> Rates {
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
    pub(super) fn exp_commit(
        &mut self,
        start: &Start,
        seg: &Segment,
        mut g1: Rates,
        tau: f64,
        mid: Option<&Rates>,
    ) {
        let at1 = seg.at;
        let (x0, g0, inputs) = (start.x, start.g, start.inputs);
        self.x = seg.x;
        let x = &mut self.x;
        let (d_theta, d_x) = (x[ix::THETA] - x0[ix::THETA], x[ix::X] - x0[ix::X]);
        x[ix::E_IN] += seg.e_in;
        x[ix::E_CU] += seg.e_cu;
        x[ix::E_MECH] += seg.visc_loss
            + self.shaft_friction.force(self.discrete.shaft) * d_theta
            + self.piston_friction.force(self.discrete.piston) * d_x;
        x[ix::E_HYD] += seg.hyd_loss;
        x[ix::E_EXT] += -inputs.external_force_n * d_x - inputs.external_torque_nm * d_theta;
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
                self.exp.push(g0, gm, 0.5 * tau);
                self.exp.push(gm, &g1, 0.5 * tau);
            }
            None => self.exp.push(g0, &g1, tau),
        }
        self.exp.now = Some(Now {
            rates: g1,
            enabled: start.enabled,
            key: start.key,
        });
    }
}

/// What a restarting segment took: the extrapolation through Kutta's stages and the rates
/// at its half step.
pub(super) struct Restart {
    pub(super) poly: Poly,
    pub(super) mid: Rates,
}
