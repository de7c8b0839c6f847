//! The rig: every physical parameter of the actuator, in SI units, and its validation.
//!
//! [`Rig::nominal`] is the nominal rig of `shared/contracts/nominal-rig.md`: the paper's
//! Table 1 and Table 2, the values derived from them, and this project's assumptions where
//! the paper is silent (each marked *assumed* in its doc comment). Everything the effect
//! catalogue can switch on ([`crate::effects`]) is off here, except what Table 2 contains
//! (cylinder static and Coulomb friction, leakage, compressibility, the absorber).
//!
//! A rig is validated once ([`Rig::validate`]); the plant is built only from a valid rig, so
//! its step never meets a negative volume or a zero piston count.
//!
//! The parameters follow the actuator's parts: [`motor`] (motor, inverter, shaft),
//! [`hydraulics`] (pump, cylinder and payload, oil, absorber, fill accumulator and valves),
//! [`sensors`]; [`nominal`] assembles them into the [`Rig`], [`validate`] checks it.

mod hydraulics;
mod motor;
mod nominal;
mod sensors;
mod validate;

#[cfg(test)]
mod tests;

pub use hydraulics::{
    AbsorberParams, CylinderParams, FillParams, OilParams, PumpParams, GRAVITY_M_S2,
};
pub use motor::{
    lcm, CoggingHarmonic, FluxHarmonic, InverterParams, MotorParams, ShaftParams,
    MAX_COGGING_HARMONICS, MAX_FLUX_HARMONICS,
};
pub use nominal::{IntegrationParams, Rig};
pub use sensors::{
    CurrentSensorParams, EncoderParams, PressureSensorParams, SensorParams, VoltageSensorParams,
};
pub use validate::RigError;
