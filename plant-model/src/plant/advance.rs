//! [`Plant::advance`]: the zero-order hold of the inputs over a call, its division into
//! equal steps, and the choice of scheme for each step (the exponential one where it
//! applies, RK4 with events otherwise, the faulted path when a fault was ever switched on),
//! the transducer's lag filtered after each step.

use super::actuator::Plant;
use super::inputs::{sanitise, Drive, Inputs};
use super::integrator::{Integrator, MAX_SUBSTEPS};
use super::state::ix;

impl Plant {
    /// Advances the plant by `dt_s` with `inputs` held (zero-order hold). Never panics:
    /// non-finite inputs are treated as zero duty / zero force, non-positive `dt_s` does
    /// nothing.
    pub fn advance(&mut self, dt_s: f64, inputs: &Inputs) {
        if dt_s.is_nan() || dt_s <= 0.0 {
            return;
        }
        let mut inputs = sanitise(inputs);
        self.gate_enable(&mut inputs);
        self.last_inputs = inputs;
        let n = libm::ceil(dt_s / self.max_step_s).clamp(1.0, 1e9) as u64;
        let (n, h) = match self.integrator {
            Integrator::Rk4 { substeps } => {
                let s = u64::from(substeps.clamp(1, MAX_SUBSTEPS));
                (n * s, dt_s / (n * s) as f64)
            }
            Integrator::Exponential => (n, dt_s / n as f64),
        };
        if self.faulted {
            self.advance_faulted(n, h, inputs);
        } else {
            let exponential = self.integrator == Integrator::Exponential;
            for _ in 0..n {
                self.impose(&inputs);
                let p0 = self.x[ix::PA];
                if exponential && self.exponential_applies(&inputs) {
                    self.exp_step(h, &inputs);
                } else {
                    self.exp.reset();
                    self.step_with_events(h, &inputs);
                }
                self.filter_pressure_sensor(p0, h);
            }
        }
        self.t_s += dt_s;
    }

    /// Whether the exponential scheme takes the next step: the inverter drives (its bridge
    /// enabled, or off with the currents died out) and nothing is prescribed.
    pub(super) fn exponential_applies(&self, inputs: &Inputs) -> bool {
        match inputs.drive {
            Drive::Inverter { enabled, .. } => {
                inputs.piston.is_none() && (enabled || self.discrete.extinguished)
            }
            _ => false,
        }
    }
}
