//! The hydraulic block the exponential step solves exactly (port A with the absorber's inlet
//! column, and port B with the payload while the piston is free): the poppet's state, the
//! block's matrix, and its matrix functions, rebuilt when the poppet or the piston's freedom
//! changes or a chamber's stiffness β/V has moved.

use super::super::actuator::Plant;
use super::super::state::{ix, Vector};
use super::blocks::{phi, Mat};
use super::history::{BlockKey, BlockPhi, HydroBlock};
use super::segment::Port;
use crate::accumulator::ATMOSPHERE_PA;
use crate::friction::Slip;

/// The hydraulic block is rebuilt when β/V_1 or β/V_2 has moved this far from the one it
/// was built at (the difference is carried in the forcing meanwhile). [1]
const BLOCK_REBUILD: f64 = 1e-3;

impl Plant {
    /// Whether the absorber's poppet is open at `x` (as in [`crate::accumulator::Absorber`]'s
    /// flow equation: shut with the absorber empty, its flow not entering and the port below
    /// the gas).
    pub(super) fn port_mode(&self, x: &Vector) -> Port {
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
    pub(super) fn block_key(&mut self, h: f64, port: Port) -> BlockKey {
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

    /// The hydraulic block's matrix (see [`super::blocks`]).
    pub(super) fn hydro_matrix(&self, key: &BlockKey) -> Mat<4> {
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
    pub(super) fn block_phi_new(&self, key: &BlockKey, tau: f64) -> BlockPhi {
        let m = self.hydro_matrix(key);
        if key.free {
            BlockPhi::Four(phi(&m, tau))
        } else {
            BlockPhi::Two(phi(&[[m[0][0], m[0][1]], [m[1][0], m[1][1]]], tau))
        }
    }

    /// The block's matrix functions at step `tau` (kept for the standard step).
    pub(super) fn block_phi(&self, key: &BlockKey, tau: f64) -> Option<&BlockPhi> {
        match &self.exp.block {
            Some(b) if b.key == *key && b.tau == tau => Some(&b.phi),
            _ => None,
        }
    }
}
