//! The non-smooth constraints at a step boundary and the prescribed motion before a step:
//! stick/slip of shaft and piston, the absorber's poppet, the currents' extinction through
//! the bridge's diodes, the cavitation floor, each projection's removed energy booked.

use super::actuator::Plant;
use super::inputs::{Drive, Inputs};
use super::state::{ix, Aux};
use crate::friction::Slip;

impl Plant {
    /// Writes prescribed quantities into the state before a step.
    pub(super) fn impose(&mut self, inputs: &Inputs) {
        match inputs.drive {
            Drive::Inverter { enabled, .. } => {
                if enabled {
                    self.discrete.extinguished = false;
                }
                // A line confinement that begins now (the bridge switched off onto a short)
                // starts from the line, not from the three-phase currents.
                if self.faulted {
                    if let Some(line) = self.line_mode(enabled) {
                        self.project_line(line);
                    }
                }
            }
            Drive::Currents { i_d, i_q } => {
                self.x[ix::ID] = i_d;
                self.x[ix::IQ] = i_q;
            }
            Drive::ShaftSpeed { omega_rad_s } => {
                self.x[ix::ID] = 0.0;
                self.x[ix::IQ] = 0.0;
                self.x[ix::OMEGA] = omega_rad_s;
                self.discrete.shaft = Slip::Sliding(if omega_rad_s < 0.0 { -1.0 } else { 1.0 });
            }
        }
        if let Some((xp, vp)) = inputs.piston {
            self.x[ix::X] = xp;
            self.x[ix::V] = vp;
        }
        if self.cylinder.blocked {
            self.x[ix::X] = 0.0;
            self.x[ix::V] = 0.0;
        }
    }

    /// Enforces the non-smooth constraints at a step boundary and books the energy they
    /// remove.
    pub(super) fn project(&mut self, inputs: &Inputs) {
        // The drive torque and force matter only to a stuck body or one whose velocity
        // reached zero; evaluate the model only then.
        let shaft_switch = match self.discrete.shaft {
            Slip::Stuck => true,
            Slip::Sliding(dir) => self.x[ix::OMEGA] * dir <= 0.0,
        };
        let piston_free = inputs.piston.is_none() && !self.cylinder.blocked;
        let shaft_switch = shaft_switch && !matches!(inputs.drive, Drive::ShaftSpeed { .. });
        let piston_switch = piston_free
            && match self.discrete.piston {
                Slip::Stuck => true,
                Slip::Sliding(dir) => self.x[ix::V] * dir <= 0.0,
            };
        let needs = (shaft_switch && self.shaft_friction.is_active())
            || (piston_switch && self.piston_friction.is_active());
        let aux = if needs {
            self.derivative(&self.x, inputs).1
        } else {
            Aux::default()
        };
        self.project_with(inputs, aux);
    }

    /// [`Plant::project`] with the drive torque and force `aux` of the present state given
    /// (only read for a body that may switch).
    pub(super) fn project_with(&mut self, inputs: &Inputs, aux: Aux) {
        let piston_free = inputs.piston.is_none() && !self.cylinder.blocked;
        // Shaft stick/slip (not when the speed is prescribed).
        if !matches!(inputs.drive, Drive::ShaftSpeed { .. }) && self.shaft_friction.is_active() {
            let w = self.x[ix::OMEGA];
            let (slip, w_new) =
                self.shaft_friction
                    .transition(self.discrete.shaft, w, aux.shaft_drive);
            self.projection_loss_j += 0.5 * self.inertia * (w * w - w_new * w_new);
            self.discrete.shaft = slip;
            self.x[ix::OMEGA] = w_new;
        }
        // Piston stick/slip.
        if piston_free && self.piston_friction.is_active() {
            let v = self.x[ix::V];
            let (slip, v_new) =
                self.piston_friction
                    .transition(self.discrete.piston, v, aux.piston_drive);
            self.projection_loss_j += 0.5 * self.cylinder.mass_kg * (v * v - v_new * v_new);
            self.discrete.piston = slip;
            self.x[ix::V] = v_new;
        }
        // Absorber poppet: the bladder cannot push out oil it does not hold.
        if self.absorber.enabled && self.x[ix::ABS_OIL] <= 0.0 {
            let q = self.x[ix::ABS_Q];
            if q < 0.0 {
                self.projection_loss_j += 0.5 * self.absorber.inertance_kg_m4 * q * q;
                self.x[ix::ABS_Q] = 0.0;
            }
            self.x[ix::ABS_PGAS] = self.absorber.gas.precharge_abs_pa();
            // Oil overdrawn within the step returns from the port node.
            let overdraw = -self.x[ix::ABS_OIL];
            if overdraw > 0.0 {
                let (v1, _) = self.cylinder.volumes(self.x[ix::X]);
                let p_old = self.x[ix::PA];
                let p_new = p_old - self.beta * overdraw / v1;
                self.projection_loss_j += v1 / (2.0 * self.beta) * (p_old * p_old - p_new * p_new);
                self.x[ix::PA] = p_new;
                self.x[ix::ABS_OIL] = 0.0;
            }
        }
        // Bridge off: once the phase currents have died out through the diodes they stay
        // out while the line back-EMF cannot forward-bias the diodes.
        let line = match inputs.drive {
            Drive::Inverter { enabled, .. } if self.faulted => self.line_mode(enabled),
            _ => None,
        };
        if let Some(line) = line {
            self.project_line(line);
        }
        // A short keeps the motor's circuit closed with the bridge off.
        let closed_by_short = self.faulted && self.short_closes_circuit(line);
        if let (Drive::Inverter { enabled: false, .. }, false) = (inputs.drive, closed_by_short) {
            let (id, iq) = (self.x[ix::ID], self.x[ix::IQ]);
            let emf = self
                .motor
                .line_emf_peak_v(self.motor.pole_pairs * self.x[ix::OMEGA]);
            let small = id * id + iq * iq < 1e-6;
            if (self.discrete.extinguished || small) && emf < self.inverter.u_dc_v {
                self.projection_loss_j += self.motor.winding_energy_j(id, iq);
                self.x[ix::ID] = 0.0;
                self.x[ix::IQ] = 0.0;
                self.discrete.extinguished = true;
            }
        }
        // Cavitation floor: oil cannot be pulled below vapour pressure.
        for node in [ix::PA, ix::PB] {
            let floor = -0.99 * crate::accumulator::ATMOSPHERE_PA;
            if self.x[node] < floor {
                let (v1, v2) = self.cylinder.volumes(self.x[ix::X]);
                let v = if node == ix::PA { v1 } else { v2 };
                let p = self.x[node];
                self.projection_loss_j += v / (2.0 * self.beta) * (p * p - floor * floor);
                self.x[node] = floor;
            }
        }
        if self.sensor_lag_s <= 0.0 {
            self.x[ix::P_SENSOR] = self.x[ix::PA];
        }
        if self.faulted && !self.faults.pump_port_blocked {
            self.x[ix::PP] = self.x[ix::PA];
        }
    }
}
