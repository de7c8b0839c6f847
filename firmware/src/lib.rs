//! EHA motor-drive control core: hardware-free, `no_std`, linked by the MCU application,
//! the host simulator, the tests and the PIL binary.
//!
//! Field-oriented control of the PMSM with SVPWM and the loops of the paper's Section 3.1
//! and Table 1, a gain-scheduled pressure loop, a supervisor with latched faults, and
//! telemetry in the bench-log columns. Everything runs in f32; sin/cos go through one path
//! ([`transforms::sin_cos`]) so host and target compute the same numbers.
//!
//! Entry point: [`Controller`] — `new(&Config)`, `on_current_sample(&Measurements) ->
//! Outputs` once per PWM period, `command(Command)`, `telemetry()`. The single loop steps
//! ([`current_loop::CurrentLoop::step`], [`speed_loop::SpeedLoop::step`],
//! [`pressure_loop::PressureLoop::step`]) are public for instruction-count benchmarks.
#![cfg_attr(not(test), no_std)]

pub mod angle_grid;
pub mod bridge;
pub mod can_protocol;
pub mod can_server;
pub mod commissioning;
pub mod compensation;
pub mod config;
pub mod controller;
pub mod current_loop;
pub mod encoder;
pub mod io;
pub mod liveness;
pub mod param_crc;
pub mod param_store;
pub mod parameters;
pub mod pi;
pub mod plausibility;
pub mod pressure_loop;
pub mod scaling;
pub mod shunt;
pub mod speed_loop;
pub mod speed_observer;
pub mod stack;
pub mod step_test;
pub mod supervisor;
pub mod svpwm;
pub mod sweep;
pub mod telemetry;
pub mod transforms;

pub use config::{Config, ConfigError};
pub use controller::{Command, CommandError, Controller};
pub use io::{Measurements, Outputs};
pub use supervisor::{FaultCode, Mode, NotReady, Readiness};
pub use telemetry::TelemetryFrame;
