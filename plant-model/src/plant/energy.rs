//! The energy bookkeeping: the stored energy of a state (windings, shaft and piston, cogging,
//! spring, gravity, stops, oil compression, gases, the absorber's oil column), the balance
//! since the start that must close up to the constant-β approximation of oil compression
//! energy, and the oil inventory of the closed circuit.

use super::actuator::Plant;
use super::state::{ix, Vector};
use crate::faults::PUMP_MANIFOLD_VOLUME_M3;

/// Energy bookkeeping since the start of the run. [J]
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct EnergyBalance {
    /// Energy delivered by the drive (electrical at the motor terminals). [J]
    pub input_j: f64,
    /// Copper loss. [J]
    pub copper_loss_j: f64,
    /// Shaft and piston friction, damping and stop losses. [J]
    pub mechanical_loss_j: f64,
    /// Leakage, valve and absorber-inlet losses. [J]
    pub hydraulic_loss_j: f64,
    /// Work done on the external load. [J]
    pub external_work_j: f64,
    /// Energy removed by projections (sticking, poppet closing, current extinction). [J]
    pub projection_loss_j: f64,
    /// Stored energy now minus at the start. [J]
    pub stored_change_j: f64,
}

impl EnergyBalance {
    /// What is not accounted for: input − Δstored − every loss and work. [J]
    pub fn residual_j(&self) -> f64 {
        self.input_j
            - self.stored_change_j
            - self.copper_loss_j
            - self.mechanical_loss_j
            - self.hydraulic_loss_j
            - self.external_work_j
            - self.projection_loss_j
    }
}

impl Plant {
    /// Energy bookkeeping since the start.
    pub fn energy(&self) -> EnergyBalance {
        let x = &self.x;
        EnergyBalance {
            input_j: x[ix::E_IN],
            copper_loss_j: x[ix::E_CU],
            mechanical_loss_j: x[ix::E_MECH],
            hydraulic_loss_j: x[ix::E_HYD],
            external_work_j: x[ix::E_EXT],
            projection_loss_j: self.projection_loss_j,
            stored_change_j: self.stored_energy_j(x) - self.stored0_j,
        }
    }

    /// Oil in the closed circuit (chambers at their pressure-compressed volumes, absorber,
    /// fill accumulator) expressed at zero gauge pressure; constant up to O(p/β)² when no oil
    /// leaves the circuit. [m³]
    pub fn oil_inventory_m3(&self) -> f64 {
        let x = &self.x;
        let (v1, v2) = self.cylinder.volumes(x[ix::X]);
        v1 * (1.0 + x[ix::PA] / self.beta)
            + v2 * (1.0 + x[ix::PB] / self.beta)
            + x[ix::ABS_OIL]
            + x[ix::FILL_OIL]
    }

    /// Stored energy of a state: windings, shaft and piston kinetic, slotting, spring,
    /// gravity, stops, oil compression, absorber gas and oil column, fill gas. [J]
    pub(super) fn stored_energy_j(&self, x: &Vector) -> f64 {
        let (v1, v2) = self.cylinder.volumes(x[ix::X]);
        let c = &self.cylinder;
        let mut e = self.motor.winding_energy_j(x[ix::ID], x[ix::IQ])
            + 0.5 * self.inertia * x[ix::OMEGA] * x[ix::OMEGA]
            + self.motor.cogging_energy_j(x[ix::THETA])
            + 0.5 * c.mass_kg * x[ix::V] * x[ix::V]
            + 0.5 * c.spring * x[ix::X] * x[ix::X]
            + c.gravity_n * x[ix::X]
            + c.stop_energy_j(x[ix::X])
            + v1 * x[ix::PA] * x[ix::PA] / (2.0 * self.beta)
            + v2 * x[ix::PB] * x[ix::PB] / (2.0 * self.beta)
            + self.fill_gas.energy_j(x[ix::FILL_OIL]);
        if self.faults.pump_port_blocked {
            e += PUMP_MANIFOLD_VOLUME_M3 * x[ix::PP] * x[ix::PP] / (2.0 * self.beta);
        }
        if self.absorber.enabled {
            e += self.absorber.gas.energy_j(x[ix::ABS_OIL])
                + 0.5 * self.absorber.inertance_kg_m4 * x[ix::ABS_Q] * x[ix::ABS_Q];
        }
        e
    }
}
