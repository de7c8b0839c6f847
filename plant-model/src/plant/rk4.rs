//! Classical fourth-order Runge–Kutta over the whole state: the plant's integrator before the
//! exponential scheme ([`super::exponential`]), kept as the reference it is checked against
//! and as the path of the faulted plant and of the replays' prescribed drives.
//!
//! A fixed step h = dt/⌈dt/h_max⌉/s inside each call (h_max the rig's `integration.max_step_s`,
//! s the substeps of [`super::Integrator::Rk4`]). The plant is mildly stiff at most — the
//! fastest linear modes at the nominal rig are the check valve against a chamber near its
//! end stop (G/C ≈ 1e-9/1.5e-13 ≈ 7e3 s⁻¹), the oil column of the absorber inlet against
//! chamber 1 (1/√(I·C_oil) ≈ 2e3 rad/s) and the electrical poles (R/L ≈ 180 s⁻¹, ω_e up to
//! ≈ 1.3e3 rad/s), so |λ·h| ≤ 0.35 sits well inside RK4's stability interval (|λh| < 2.78 on
//! the real axis) and its error is O(h⁴). The discontinuities (stick/slip, poppet closure,
//! diode extinction) are handled at step boundaries by projection (their energy is booked)
//! so RK4 never integrates across a switching surface with a stale sign; the switching
//! instants inside a step are located by regula falsi on event functions.
//!
//! Cost: everything that depends on the shaft angle alone (rotor phasors, magnet-flux
//! harmonics, cogging, the pump's displacement factor) is evaluated once per RK4 stage and
//! kept for the step's end state, where `sample`, `observe`, the projection and the next
//! step's first stage all read it. The stage phasors come from the step's start phasor
//! rotated through the stage's angle increment (a Taylor series exact to rounding for the
//! ≤ 0.1 rad a step turns, libm beyond).

use super::actuator::Plant;
use super::inputs::{Drive, Inputs};
use super::integrator::{EVENT_REFINEMENTS, EVENT_TOLERANCE, MAX_EVENTS_PER_STEP};
use super::state::{ix, Aux, RotorPhasor, Vector, ROTOR_RESYNC_STEPS};
use crate::friction::{Friction, Slip};
use crate::motor::Phasor;

/// Event functions: shaft friction, piston friction, absorber empty.
const EVENTS: usize = 3;

impl Plant {
    /// One RK4 step of length `h` that stops at the switching events inside it (a sliding
    /// body reaching zero velocity, a stuck body's drive reaching breakaway, the absorber
    /// running empty), located by regula falsi on the event functions, so that stick–slip
    /// timing is as accurate as the smooth dynamics instead of O(h).
    pub(super) fn step_with_events(&mut self, h: f64, inputs: &Inputs) {
        let mut remaining = h;
        for _ in 0..MAX_EVENTS_PER_STEP {
            let mut g0 = self.event_functions(&self.x, inputs);
            // A body at rest whose drive already exceeds breakaway (a new run, a step change
            // of load) is released before the step, not one step late.
            if g0[..2].iter().any(|g| *g <= 0.0) {
                self.project(inputs);
                g0 = self.event_functions(&self.x, inputs);
            }
            let x0 = self.x;
            self.rk4(remaining, inputs);
            let g1 = self.event_functions(&self.x, inputs);
            // The earliest crossing from positive to non-positive, by linear interpolation.
            let mut first: Option<(usize, f64)> = None;
            for k in 0..EVENTS {
                if g0[k] > 0.0 && g1[k] <= 0.0 {
                    let f = g0[k] / (g0[k] - g1[k]);
                    if first.is_none_or(|(_, best)| f < best) {
                        first = Some((k, f));
                    }
                }
            }
            let Some((k, f_guess)) = first else {
                self.project(inputs);
                return;
            };
            // Refine the bracket [lo, hi] with g(lo) > 0 ≥ g(hi); step to hi, where the event
            // has happened, so the projection sees it.
            // Illinois variant of regula falsi: an end kept twice has its value halved, so
            // the bracket shrinks from both sides instead of stagnating.
            let (mut lo, mut hi) = ((0.0, g0[k]), (1.0, g1[k]));
            let mut f = f_guess;
            let mut kept = 0i8;
            for _ in 0..EVENT_REFINEMENTS {
                if hi.0 - lo.0 <= EVENT_TOLERANCE {
                    break;
                }
                self.x = x0;
                self.rk4(f * remaining, inputs);
                let g = self.event_functions(&self.x, inputs)[k];
                if g > 0.0 {
                    lo = (f, g);
                    kept = if kept > 0 { kept + 1 } else { 1 };
                    if kept > 1 {
                        hi.1 *= 0.5;
                    }
                } else {
                    hi = (f, g);
                    kept = if kept < 0 { kept - 1 } else { -1 };
                    if kept < -1 {
                        lo.1 *= 0.5;
                    }
                }
                f = lo.0 + (hi.0 - lo.0) * lo.1 / (lo.1 - hi.1);
            }
            self.x = x0;
            self.rk4(hi.0 * remaining, inputs);
            self.project(inputs);
            remaining *= 1.0 - hi.0;
            if remaining <= 1e-12 * h {
                return;
            }
        }
        // More events than expected in one step: finish it plainly.
        self.rk4(remaining, inputs);
        self.project(inputs);
    }

    /// Event functions: positive while nothing switches, crossing zero at an event. The
    /// drive torque and force are evaluated only when a body is stuck (a sliding body's event
    /// is its velocity), so a step costs four evaluations when nothing switches.
    fn event_functions(&self, x: &Vector, inputs: &Inputs) -> [f64; EVENTS] {
        let mut g = [1.0; EVENTS];
        let shaft =
            self.shaft_friction.is_active() && !matches!(inputs.drive, Drive::ShaftSpeed { .. });
        let piston =
            self.piston_friction.is_active() && inputs.piston.is_none() && !self.cylinder.blocked;
        let stuck = (shaft && self.discrete.shaft == Slip::Stuck)
            || (piston && self.discrete.piston == Slip::Stuck);
        let aux = if stuck {
            self.derivative(x, inputs).1
        } else {
            Aux::default()
        };
        let event = |f: &Friction, slip: Slip, velocity: f64, drive: f64| match slip {
            Slip::Sliding(dir) => velocity * dir,
            Slip::Stuck => f.breakaway - libm::fabs(drive),
        };
        if shaft {
            g[0] = event(
                &self.shaft_friction,
                self.discrete.shaft,
                x[ix::OMEGA],
                aux.shaft_drive,
            );
        }
        if piston {
            g[1] = event(
                &self.piston_friction,
                self.discrete.piston,
                x[ix::V],
                aux.piston_drive,
            );
        }
        if self.absorber.enabled {
            // Scaled so that a full absorber reads 1.
            g[2] = x[ix::ABS_OIL] / self.absorber.gas.shell_volume_m3;
        }
        g
    }

    fn rk4(&mut self, h: f64, inputs: &Inputs) {
        if self.faulted {
            self.rk4_with::<true>(h, inputs);
        } else {
            self.rk4_with::<false>(h, inputs);
        }
    }

    /// [`Plant::rk4`] with the faults' terms (`FAULTED`) or without them compiled in.
    #[inline(always)]
    fn rk4_with<const FAULTED: bool>(&mut self, h: f64, inputs: &Inputs) {
        let x0 = self.x;
        let a0 = self.angle_terms(x0[ix::THETA]);
        let stage = |x: &Vector| {
            let a = self.angle_terms_rotated(&a0, x[ix::THETA]);
            self.derivative_at::<FAULTED>(x, inputs, &a).0
        };
        let k1 = self.derivative_at::<FAULTED>(&x0, inputs, &a0).0;
        let k2 = stage(&axpy(&x0, 0.5 * h, &k1));
        let k3 = stage(&axpy(&x0, 0.5 * h, &k2));
        let k4 = stage(&axpy(&x0, h, &k3));
        for i in 0..ix::N {
            self.x[i] = x0[i] + h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
        let theta = self.x[ix::THETA];
        self.rotor = if self.rotor.rotations >= ROTOR_RESYNC_STEPS {
            RotorPhasor::at(theta)
        } else {
            RotorPhasor {
                theta,
                phasor: a0.rot_m * Phasor::small(theta - a0.theta),
                rotations: self.rotor.rotations + 1,
            }
        };
        self.angle = self.angle_terms(theta);
    }
}

#[inline]
fn axpy(x: &Vector, a: f64, y: &Vector) -> Vector {
    let mut out = *x;
    for (o, v) in out.iter_mut().zip(y) {
        *o += a * v;
    }
    out
}
