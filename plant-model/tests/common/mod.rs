//! What the plant's integration tests share.

use plant_model::{Drive, Inputs, Rig};

/// The rig without sensor noise.
pub fn quiet(mut rig: Rig) -> Rig {
    rig.sensors.current.noise_a_rms = 0.0;
    rig.sensors.pressure.noise_pa_rms = 0.0;
    rig.sensors.dc_link.noise_v_rms = 0.0;
    rig
}

/// The shaft driven at a prescribed speed `omega`. [rad/s]
pub fn speed_drive(omega: f64) -> Inputs {
    Inputs {
        drive: Drive::ShaftSpeed { omega_rad_s: omega },
        piston: None,
        external_force_n: 0.0,
        external_torque_nm: 0.0,
    }
}
