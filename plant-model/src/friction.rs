//! Static (breakaway) and Coulomb friction with a stick state (Karnopp's model), shared by
//! the shaft (Section 5.3) and the cylinder piston (eq. 12, Table 2's F_s and F_c).
//!
//! A body at rest stays at rest — velocity exactly zero, no chattering — while the net
//! driving force stays within the breakaway level; it slides when the force exceeds it,
//! against a Coulomb force of constant magnitude opposing the slip direction. The slip
//! direction is a discrete state held over an integration step, so the friction force is
//! smooth within the step; the step's end decides the transitions: a body whose velocity
//! crossed zero sticks if the driving force cannot break it away, otherwise it reverses.

/// The discrete friction state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Slip {
    /// At rest, held by static friction.
    Stuck,
    /// Sliding in the direction of the sign (+1 or −1).
    Sliding(f64),
}

/// Breakaway and Coulomb levels of one body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Friction {
    /// Coulomb (sliding) force or torque magnitude. [N or N·m]
    pub coulomb: f64,
    /// Static (breakaway) force or torque magnitude, at least the Coulomb level. [N or N·m]
    pub breakaway: f64,
}

impl Friction {
    /// From the two levels; breakaway is raised to the Coulomb level if below it.
    pub fn new(coulomb: f64, breakaway: f64) -> Friction {
        Friction {
            coulomb,
            breakaway: if breakaway > coulomb {
                breakaway
            } else {
                coulomb
            },
        }
    }

    /// Whether the model does anything.
    pub fn is_active(&self) -> bool {
        self.breakaway > 0.0
    }

    /// Friction force during a step in state `slip` (opposes the slip). [N or N·m]
    #[inline]
    pub fn force(&self, slip: Slip) -> f64 {
        match slip {
            Slip::Stuck => 0.0,
            Slip::Sliding(dir) => self.coulomb * dir,
        }
    }

    /// The state for a body at `velocity` under net driving force `drive` (everything but
    /// friction), decided at a step boundary; returns the new state and the velocity (zero
    /// when the body sticks).
    #[inline]
    pub fn transition(&self, slip: Slip, velocity: f64, drive: f64) -> (Slip, f64) {
        if !self.is_active() {
            return (Slip::Sliding(sign(velocity)), velocity);
        }
        match slip {
            Slip::Stuck => {
                if libm::fabs(drive) >= self.breakaway {
                    (Slip::Sliding(sign(drive)), 0.0)
                } else {
                    (Slip::Stuck, 0.0)
                }
            }
            Slip::Sliding(dir) => {
                if velocity * dir > 0.0 {
                    (Slip::Sliding(dir), velocity)
                } else if libm::fabs(drive) > self.breakaway {
                    // Crossed zero with enough force to keep going the other way.
                    (Slip::Sliding(sign(drive)), 0.0)
                } else {
                    (Slip::Stuck, 0.0)
                }
            }
        }
    }
}

#[inline]
fn sign(x: f64) -> f64 {
    if x < 0.0 {
        -1.0
    } else {
        1.0
    }
}
