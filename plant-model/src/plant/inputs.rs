//! What crosses the seam into the plant for one call of [`super::Plant::advance`]: the drive
//! of the shaft (inverter duties and enable, or the replays' prescribed currents or speed),
//! the prescribed piston and the external load, and their sanitising (non-finite inputs
//! read as zero duty, zero force).

/// How the shaft is driven during a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Drive {
    /// The inverter, with three duties in [0, 1] held over the step, and the bridge enable.
    Inverter {
        /// Duty of phases a, b, c. [1]
        duties: [f64; 3],
        /// Gate drivers enabled; disabled, the bridge's diodes let the currents die out.
        enabled: bool,
    },
    /// Prescribed d-q currents (motor-and-shaft replay from logged currents). [A]
    Currents {
        /// i_d. [A]
        i_d: f64,
        /// i_q. [A]
        i_q: f64,
    },
    /// Prescribed shaft speed (hydraulics replay from logged speed). [rad/s]
    ShaftSpeed {
        /// ω_m. [rad/s]
        omega_rad_s: f64,
    },
}

/// Inputs held over one call of [`super::Plant::advance`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inputs {
    /// What drives the shaft.
    pub drive: Drive,
    /// Prescribed piston position and velocity (hydraulics replay); `None`: the force
    /// balance moves it (or it is blocked). [m], [m/s]
    pub piston: Option<(f64, f64)>,
    /// External load force on the piston, positive towards +x (F_L of eq. 12 with the
    /// opposite sign). [N]
    pub external_force_n: f64,
    /// External torque on the shaft, positive in the direction of rotation (a replay's
    /// tracking correction; 0 on a real rig). [N·m]
    pub external_torque_nm: f64,
}

impl Inputs {
    /// Inverter drive with the given duties, bridge enabled, no external force.
    pub fn duties(duties: [f64; 3], enabled: bool) -> Inputs {
        Inputs {
            drive: Drive::Inverter { duties, enabled },
            piston: None,
            external_force_n: 0.0,
            external_torque_nm: 0.0,
        }
    }
}

fn finite_or(v: f64, default: f64) -> f64 {
    if v.is_finite() {
        v
    } else {
        default
    }
}

pub(super) fn sanitise(inputs: &Inputs) -> Inputs {
    let drive = match inputs.drive {
        Drive::Inverter { duties, enabled } => Drive::Inverter {
            duties: duties.map(|d| finite_or(d, 0.5).clamp(0.0, 1.0)),
            enabled,
        },
        Drive::Currents { i_d, i_q } => Drive::Currents {
            i_d: finite_or(i_d, 0.0),
            i_q: finite_or(i_q, 0.0),
        },
        Drive::ShaftSpeed { omega_rad_s } => Drive::ShaftSpeed {
            omega_rad_s: finite_or(omega_rad_s, 0.0),
        },
    };
    Inputs {
        drive,
        piston: inputs
            .piston
            .map(|(x, v)| (finite_or(x, 0.0), finite_or(v, 0.0))),
        external_force_n: finite_or(inputs.external_force_n, 0.0),
        external_torque_nm: finite_or(inputs.external_torque_nm, 0.0),
    }
}
