//! The whole rig ([`Rig`]: every subsystem's parameters and the integration step) and the
//! nominal rig of `shared/contracts/nominal-rig.md` (the paper's Table 1 and Table 2, the
//! values derived from them, this project's assumptions where the paper is silent).

use super::hydraulics::{AbsorberParams, CylinderParams, FillParams, OilParams, PumpParams};
use super::motor::{
    InverterParams, MotorParams, ShaftParams, MAX_COGGING_HARMONICS, MAX_FLUX_HARMONICS,
    NO_COGGING, NO_FLUX_HARMONIC,
};
use super::sensors::{
    CurrentSensorParams, EncoderParams, PressureSensorParams, SensorParams, VoltageSensorParams,
};

/// Integration settings of the plant (see [`crate::plant`] for the choice of scheme).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct IntegrationParams {
    /// Largest RK4 step; a call to `advance(dt)` takes ⌈dt/max_step⌉ equal steps. [s]
    pub max_step_s: f64,
}

/// The whole actuator.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Rig {
    /// Servo motor.
    pub motor: MotorParams,
    /// Inverter.
    pub inverter: InverterParams,
    /// Shaft.
    pub shaft: ShaftParams,
    /// Pump.
    pub pump: PumpParams,
    /// Cylinder and load.
    pub cylinder: CylinderParams,
    /// Oil.
    pub oil: OilParams,
    /// Pulsation absorber.
    pub absorber: AbsorberParams,
    /// Fill accumulator, check and relief valves.
    pub fill: FillParams,
    /// Sensors.
    pub sensors: SensorParams,
    /// Integration.
    pub integration: IntegrationParams,
}

impl Rig {
    /// The nominal rig of `shared/contracts/nominal-rig.md`.
    pub fn nominal() -> Rig {
        Rig {
            motor: MotorParams {
                pole_pairs: 4,
                r_s_ohm: 0.958,
                l_d_h: 5.25e-3,
                l_q_h: 12e-3,
                psi_f_wb: 0.1827,
                stator_slots: 9,
                cogging: [NO_COGGING; MAX_COGGING_HARMONICS],
                flux_harmonics: [NO_FLUX_HARMONIC; MAX_FLUX_HARMONICS],
            },
            inverter: InverterParams {
                u_dc_v: 280.0,
                pwm_frequency_hz: 20e3,
                dead_time_s: 0.0,
                dead_time_current_band_a: 0.2,
            },
            shaft: ShaftParams {
                motor_inertia_kg_m2: 6.329e-4,
                pump_inertia_kg_m2: 1.671e-4,
                viscous_nm_s: 3.035e-4,
                coulomb_nm: 0.0,
                static_nm: 0.0,
            },
            pump: PumpParams {
                displacement_m3_per_rev: 1.5e-6,
                pistons: 9,
                piston_ripple: false,
                ripple_amplitude_ratio: 0.0,
                internal_leakage_m3_s_pa: 1e-13,
                external_leakage_m3_s_pa: 1e-13,
                extra_leakage_m3_s_pa: 0.0,
            },
            cylinder: CylinderParams {
                area_m2: 71e-4,
                chamber_a_volume_m3: 450e-6,
                chamber_b_volume_m3: 450e-6,
                internal_leakage_m3_s_pa: 1e-13,
                viscous_n_s_per_m: 150.0,
                static_friction_n: 25.0,
                coulomb_friction_n: 15.0,
                mass_kg: 2000.0,
                half_stroke_m: 0.05,
                end_stop_stiffness_n_per_m: 2e8,
                end_stop_damping_n_s_per_m: 2e5,
                spring_n_per_m: 0.0,
                gravity_angle_rad: 0.0,
                blocked: false,
            },
            oil: OilParams {
                bulk_modulus_pa: 6.5e8,
                density_kg_m3: 870.0,
            },
            absorber: AbsorberParams {
                enabled: true,
                shell_volume_m3: 400e-6,
                precharge_pa: 3e6,
                polytropic_exponent: 1.3,
                inlet_inertance_kg_m4: 3.85e5,
                inlet_resistance_pa_s_m3: 3e7,
            },
            fill: FillParams {
                pressure_pa: 0.5e6,
                precharge_pa: 0.3e6,
                shell_volume_m3: 1e-3,
                polytropic_exponent: 1.3,
                check_cracking_pa: 0.02e6,
                check_conductance_m3_s_pa: 1e-9,
                relief_cracking_pa: 21e6,
                relief_conductance_m3_s_pa: 7.5e-11,
            },
            sensors: SensorParams {
                current: CurrentSensorParams {
                    a_per_lsb: 100.0 / 4096.0,
                    zero_lsb: 2048.0,
                    bits: 12,
                    offset_a: [0.0; 3],
                    noise_a_rms: 0.02,
                },
                pressure: PressureSensorParams {
                    pa_per_lsb: 25e6 / 52428.8,
                    zero_lsb: 6554.0,
                    bits: 16,
                    offset_pa: 0.0,
                    noise_pa_rms: 1e3,
                    lag_time_constant_s: 0.0,
                },
                dc_link: VoltageSensorParams {
                    v_per_lsb: 0.1,
                    bits: 12,
                    noise_v_rms: 0.2,
                },
                encoder: EncoderParams {
                    counts_per_rev: 10_000,
                    offset_rad: 0.0,
                },
            },
            integration: IntegrationParams { max_step_s: 50e-6 },
        }
    }
}
