//! Everything that depends on the shaft angle alone: the rotor phasors, the magnet flux with
//! its harmonics (eq. 17–19), the cogging torque (eq. 16) and the pump's displacement factor
//! (eq. 20), one `sincos` per evaluation at most (every harmonic a power of the shaft-angle
//! phasor), the kept terms reused while the angle is the same.

use super::actuator::Plant;
use super::state::AngleTerms;
use crate::motor::Phasor;

impl Plant {
    /// The shaft-angle terms at `theta`: the kept ones when they belong to it, else computed
    /// from the shaft phasor ([`Plant::shaft_phasor`]).
    #[inline]
    pub(super) fn angle_terms(&self, theta: f64) -> AngleTerms {
        if theta == self.angle.theta {
            self.angle
        } else {
            self.angle_terms_of(theta, self.shaft_phasor(theta))
        }
    }

    /// The shaft-angle phasor at `theta`: the kept rotor phasor when it belongs to it, else
    /// one `sincos`.
    #[inline]
    fn shaft_phasor(&self, theta: f64) -> Phasor {
        if theta == self.rotor.theta {
            self.rotor.phasor
        } else {
            Phasor::of(theta)
        }
    }

    /// The rotor's electrical phasor at `theta`: the kept one when it belongs to it, else the
    /// shaft phasor's power alone (the flux, cogging and pump terms are not needed for it).
    #[inline]
    pub(super) fn rotor_e(&self, theta: f64) -> Phasor {
        if theta == self.angle.theta {
            self.angle.rot_e
        } else {
            self.shaft_phasor(theta).pow(self.pole_pairs)
        }
    }

    /// The shaft-angle terms at `theta` near `a0.theta` (an RK4 stage), its phasor by rotating
    /// `a0`'s through the difference.
    #[inline]
    pub(super) fn angle_terms_rotated(&self, a0: &AngleTerms, theta: f64) -> AngleTerms {
        self.angle_terms_of(theta, a0.rot_m * Phasor::small(theta - a0.theta))
    }

    /// One sincos per evaluation at most: every harmonic is a power of the shaft-angle phasor.
    #[inline]
    pub(super) fn angle_terms_of(&self, theta: f64, rot_m: Phasor) -> AngleTerms {
        let rot_e = rot_m.pow(self.pole_pairs);
        AngleTerms {
            theta,
            rot_m,
            rot_e,
            flux: self.motor.magnet_flux_at(rot_e),
            t_cog: self.motor.cogging_torque_at(rot_m),
            factor: self.pump.displacement_factor_at(theta, rot_m),
        }
    }
}
