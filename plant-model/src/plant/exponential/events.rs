//! The exponential step's switching events and projection: the event functions (a sliding
//! body's velocity, a stuck body's drive against breakaway, the absorber's poppet, the
//! piston's end stop), positive while nothing switches, and the projection at a segment's
//! end with the drives of its rates, skipped where it cannot change anything.

use super::super::actuator::Plant;
use super::super::inputs::{Drive, Inputs};
use super::super::state::{ix, Aux, Vector};
use super::rates::Rates;
use super::segment::Port;
use crate::accumulator::ATMOSPHERE_PA;
use crate::friction::{Friction, Slip};

/// Event functions: shaft friction, piston friction, absorber poppet, piston end stop.
pub(super) const EVENTS: usize = 4;

impl Plant {
    /// The projection at a segment's end with the drives of `g`; true when it changed the
    /// state (the rates and their history are dropped then).
    pub(super) fn exp_project(&mut self, inputs: &Inputs, g: &Rates) -> bool {
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
    pub(super) fn exp_may_project(&self, inputs: &Inputs) -> bool {
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
    pub(super) fn exp_events(
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

/// Whether two states are the same for the rates (the transducer's lag is filtered after the
/// step and enters no rate).
fn same_state(a: &Vector, b: &Vector) -> bool {
    a.iter()
        .zip(b)
        .enumerate()
        .all(|(k, (a, b))| k == ix::P_SENSOR || a == b)
}
