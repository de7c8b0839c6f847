//! Controller configuration: SI parameters of the drive, the sensors, the loops, the
//! hydraulics the pressure loop is scheduled from, and the supervisor's limits.
//!
//! [`Config::nominal`] is the nominal rig (`contracts/nominal-rig.md`) with the Table 1
//! gains of the paper (Section 3.1). A configuration is checked once by
//! [`Config::validate`]; the control step then never re-checks it. Configuration is kept
//! apart from controller state: [`crate::Controller::new`] derives its discrete-time
//! constants from a validated `Config` and never mutates it.
//!
//! Its parts: [`sections`] (the structs), [`error`] (the [`ConfigError`] every check
//! returns), [`nominal`] (the nominal and bring-up configurations) and [`validate`] (the
//! check and [`whole_ratio`]).

pub mod error;
pub mod nominal;
pub mod sections;
pub mod validate;

pub use crate::commissioning::config::CommissioningConfig;
pub use crate::compensation::config::CompensationConfig;
pub use error::ConfigError;
pub use sections::{
    CalibrationConfig, Config, CurrentLoopConfig, FaultLimits, Hydraulics, Motor,
    PressureLoopConfig, Rates, SensorScaling, SpeedLoopConfig,
};
pub use validate::whole_ratio;

#[cfg(test)]
mod tests;
