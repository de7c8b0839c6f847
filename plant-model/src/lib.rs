//! Physics of the electro-hydrostatic actuator of Qian et al., "Optimal Design of Accumulator
//! Parameters for an Electro-Hydrostatic Actuator at Low Speed" (2021): PMSM, inverter,
//! shaft, axial piston pump, cylinder with payload, pulsation absorber and fill accumulator,
//! valves and sensors, with every low-speed effect of the paper switchable.
//!
//! `no_std` (the PIL binary runs it on a Cortex-M4F); f64 throughout; every float function
//! through `libm`, so the host computes what the target computes. Build a [`rig::Rig`]
//! (start from [`rig::Rig::nominal`], switch effects on with [`effects::Effect::apply`]),
//! make a [`plant::Plant`], then alternate [`plant::Plant::sample`] and
//! [`plant::Plant::advance`].
#![cfg_attr(not(feature = "std"), no_std)]
#![deny(missing_docs)]

pub mod accumulator;
pub mod cylinder;
pub mod effects;
pub mod faults;
pub mod friction;
mod gaussian;
pub mod inverter;
pub mod motor;
pub mod plant;
pub mod pump;
pub mod rig;
pub mod sensor_faults;
pub mod sensors;
pub mod valves;

pub use effects::Effect;
pub use faults::PlantFaults;
pub use plant::{
    CurrentWatch, Drive, EnergyBalance, InitialConditions, Inputs, Integrator, Observables, Plant,
};
pub use rig::{Rig, RigError};
pub use sensor_faults::SensorFaults;
pub use sensors::SensorReadings;
