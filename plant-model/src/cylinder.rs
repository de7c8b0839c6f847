//! Double-acting cylinder with its payload: chamber continuity (eq. 11, per chamber) and the
//! force balance (eq. 12).
//!
//! Chamber volumes are V_1 = V_10 + A·x and V_2 = V_20 − A·x. Each chamber's pressure obeys
//! `dp/dt = β/V·(Q_in − dV/dt − Q_leak)`, the two-chamber form of eq. 11 (whose V_t/4β is
//! the symmetric mid-stroke special case). The piston: m·dv/dt = A·(p_1 − p_2) − B_p·v − K·x −
//! m·g·sin(α) − F_friction − F_stop, with Karnopp static/Coulomb friction
//! ([`crate::friction`]) and hard end stops as stiff spring–dampers that only push. A
//! blocked cylinder (pressure holding) keeps the piston at mid-stroke.

use crate::rig::{CylinderParams, GRAVITY_M_S2};

/// Cylinder equations, precomputed.
#[derive(Clone, Copy, Debug)]
pub struct Cylinder {
    /// A_p. [m²]
    pub area_m2: f64,
    /// V_10. [m³]
    pub v10_m3: f64,
    /// V_20. [m³]
    pub v20_m3: f64,
    /// C_ic. [(m³/s)/Pa]
    pub leakage: f64,
    /// B_p. [N·s/m]
    pub viscous: f64,
    /// m_t. [kg]
    pub mass_kg: f64,
    /// Stop position. [m]
    pub half_stroke_m: f64,
    /// Stop stiffness. [N/m]
    pub stop_k: f64,
    /// Stop damping. [N·s/m]
    pub stop_c: f64,
    /// K. [N/m]
    pub spring: f64,
    /// m·g·sin(α). [N]
    pub gravity_n: f64,
    /// Piston held.
    pub blocked: bool,
}

impl Cylinder {
    /// From validated parameters.
    pub fn new(p: &CylinderParams) -> Cylinder {
        Cylinder {
            area_m2: p.area_m2,
            v10_m3: p.chamber_a_volume_m3,
            v20_m3: p.chamber_b_volume_m3,
            leakage: p.internal_leakage_m3_s_pa,
            viscous: p.viscous_n_s_per_m,
            mass_kg: p.mass_kg,
            half_stroke_m: p.half_stroke_m,
            stop_k: p.end_stop_stiffness_n_per_m,
            stop_c: p.end_stop_damping_n_s_per_m,
            spring: p.spring_n_per_m,
            gravity_n: p.mass_kg * GRAVITY_M_S2 * libm::sin(p.gravity_angle_rad),
            blocked: p.blocked,
        }
    }

    /// Chamber volumes (V_1, V_2) at piston position `x`; floored at a tenth of the
    /// mid-stroke volume so a stop overrun cannot make them vanish. [m³]
    #[inline]
    pub fn volumes(&self, x: f64) -> (f64, f64) {
        (
            (self.v10_m3 + self.area_m2 * x).max(0.1 * self.v10_m3),
            (self.v20_m3 - self.area_m2 * x).max(0.1 * self.v20_m3),
        )
    }

    /// How far `x` lies beyond an end stop, signed as `x` (0 within the stroke). [m]
    #[inline]
    fn penetration(&self, x: f64) -> f64 {
        if x > self.half_stroke_m {
            x - self.half_stroke_m
        } else if x < -self.half_stroke_m {
            x + self.half_stroke_m
        } else {
            0.0
        }
    }

    /// End-stop contact force on the piston (pushes back inside the stroke). [N]
    #[inline]
    pub fn stop_force(&self, x: f64, v: f64) -> f64 {
        let over = self.penetration(x);
        if over == 0.0 {
            return 0.0;
        }
        let f = -self.stop_k * over - self.stop_c * v;
        // A contact only pushes.
        if over > 0.0 {
            f.min(0.0)
        } else {
            f.max(0.0)
        }
    }

    /// The part of [`Cylinder::stop_force`] the contact dissipates: the force less its
    /// spring part −k·(penetration), which the contact stores ([`Cylinder::stop_energy_j`]).
    /// [N]
    #[inline]
    pub fn stop_dissipative_force(&self, x: f64, v: f64) -> f64 {
        let over = self.penetration(x);
        if over == 0.0 {
            return 0.0;
        }
        self.stop_force(x, v) + self.stop_k * over
    }

    /// Stop contact energy. [J]
    pub fn stop_energy_j(&self, x: f64) -> f64 {
        let over = self.penetration(x);
        0.5 * self.stop_k * over * over
    }

    /// Net force on the piston except friction, at chamber pressures and motion. [N]
    #[inline]
    pub fn drive_force(&self, p1: f64, p2: f64, x: f64, v: f64, external_n: f64) -> f64 {
        self.area_m2 * (p1 - p2) - self.viscous * v - self.spring * x - self.gravity_n
            + external_n
            + self.stop_force(x, v)
    }
}
