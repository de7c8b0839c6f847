//! The live parameter table: every loop gain and limit, the pressure-loop schedule's
//! hydraulic assumptions, the ramp rate, the telemetry decimation and the commissioning
//! results, each with a stable wire id, a name (the [`Config`] field path), an SI unit and
//! documented bounds.
//!
//! A parameter is read from and written into a [`Config`]; [`ParamId::set`] checks the
//! value against the parameter's bounds first (so a refusal names the bound), then the
//! rules of [`Config::validate`] that tie a parameter to other fields ([`cross_check()`]:
//! "the feedback filter must be at least twice the pressure bandwidth", "the over-current
//! trip must exceed the q-current limit", …; a refusal names the conflicting field). The
//! bounds contain every single-field rule of the validator, so bounds plus cross-check
//! accept exactly what the validator accepts (a test holds them to that) for a fraction
//! of its code: the firmware links no general validator, the nominal configuration's
//! check folds away at compile time. Defaults are those of [`Config::nominal`].
//! How a changed value reaches the running loops is the controller's business
//! ([`crate::Controller`] applies it between control steps, bumplessly).
//!
//! Ids are grouped by tens (current loop 1–5, speed loop 10–15, pressure loop 20–25,
//! hydraulics 30–36, telemetry 40, commissioning results 50–54, torque feed-forward 60–63
//! and its speed modulation against the pump's flow ripple 64–68);
//! an id is never reused for another meaning. `compensation.clear` is an action: writing 1
//! empties the feed-forward's table ([`crate::compensation`]), it always reads 0. The
//! feed-forward's amplitude limit also involves its table, which the controller checks
//! ([`crate::compensation::Compensation::check_amplitude`]). The stored table ([`crate::param_store`]) carries a fingerprint of this
//! list ([`LAYOUT_FINGERPRINT`]), so a firmware with a changed table never loads an old
//! record as if it matched.
//!
//! # Parameter table
//!
//! Bounds are inclusive. Values travel on the wire as IEEE-754 `f32` in the unit shown;
//! `rates.telemetry_decimation` must be a whole number.
//!
//! | id | name | unit | min | max | default |
//! |----|------|------|-----|-----|---------|
//! | 1 | `current.kp_d` | V/A | 0.01 | 200 | 5.775 |
//! | 2 | `current.ki_d` | V/(A·s) | 0 | 100000 | 1053.8 |
//! | 3 | `current.kp_q` | V/A | 0.01 | 200 | 13.2 |
//! | 4 | `current.ki_q` | V/(A·s) | 0 | 100000 | 1053.8 |
//! | 5 | `current.voltage_limit_v` | V | 1 | 250 | 161.6 |
//! | 10 | `speed.kp` | A/(rad/s) | 0.0001 | 10 | 0.14 |
//! | 11 | `speed.ki` | A/rad | 0 | 1000 | 7 |
//! | 12 | `speed.active_damping` | A/(rad/s) | 0 | 1 | 0.013 |
//! | 13 | `speed.iq_limit_a` | A | 0.1 | 100 | 30 |
//! | 14 | `speed.speed_limit_rad_s` | rad/s | 1 | 1000 | 200 |
//! | 15 | `speed.observer_bandwidth_rad_s` | rad/s | 10 | 5000 | 1000 |
//! | 20 | `pressure.bandwidth_rad_s` | rad/s | 0.1 | 200 | 20 |
//! | 21 | `pressure.integral_corner_ratio` | 1 | 0 | 1 | 0.25 |
//! | 22 | `pressure.feedback_filter_rad_s` | rad/s | 1 | 5000 | 150 |
//! | 23 | `pressure.ramp_pa_per_s` | Pa/s | 1000 | 1000000000 | 10000000 |
//! | 24 | `pressure.setpoint_min_pa` | Pa | 0 | 25000000 | 0 |
//! | 25 | `pressure.setpoint_max_pa` | Pa | 100000 | 25000000 | 18000000 |
//! | 30 | `hydraulics.pump_displacement_m3_per_rev` | m³/rev | 1e-8 | 0.0001 | 0.0000015 |
//! | 31 | `hydraulics.oil_volume_m3` | m³ | 0.000001 | 0.01 | 0.00045 |
//! | 32 | `hydraulics.bulk_modulus_pa` | Pa | 100000000 | 2500000000 | 650000000 |
//! | 33 | `hydraulics.absorber_volume_m3` | m³ | 0 | 0.01 | 0.0004 |
//! | 34 | `hydraulics.absorber_precharge_pa` | Pa | 0 | 25000000 | 3000000 |
//! | 35 | `hydraulics.polytropic_exponent` | 1 | 1 | 2 | 1.3 |
//! | 36 | `hydraulics.leakage_m3_per_s_pa` | (m³/s)/Pa | 0 | 1e-9 | 3e-13 |
//! | 40 | `rates.telemetry_decimation` | 1 | 1 | 10000 | 20 |
//! | 50 | `motor.stator_resistance_ohm` | Ω | 0.001 | 100 | 0.958 |
//! | 51 | `motor.d_inductance_h` | H | 0.000001 | 1 | 0.00525 |
//! | 52 | `motor.q_inductance_h` | H | 0.000001 | 1 | 0.012 |
//! | 53 | `motor.flux_linkage_wb` | Wb | 0 | 5 | 0.1827 |
//! | 54 | `sensors.encoder_offset_rad` | rad | 0 | 6.2831855 | 0 |
//! | 60 | `compensation.enabled` | 1 | 0 | 1 | 0 |
//! | 61 | `compensation.scale` | 1 | 0 | 2 | 1 |
//! | 62 | `compensation.max_current_a` | A | 0 | 10 | 3 |
//! | 63 | `compensation.clear` | 1 | 0 | 1 | 0 |
//! | 64 | `compensation.flow_pistons` | 1 | 0 | 31 | 0 |
//! | 65 | `compensation.flow_ratio` | 1 | 0 | 0.5 | 0 |
//! | 66 | `compensation.flow_phase_rad` | rad | 0 | 6.2831855 | 0 |
//! | 67 | `compensation.inertia_kg_m2` | kg·m² | 0 | 1 | 0.0008 |
//! | 68 | `compensation.max_flow_ratio` | 1 | 0 | 0.5 | 0.1 |
//!
//! The table above is checked against the code by this module's tests.
//!
//! [`Config`]: crate::Config
//! [`Config::validate`]: crate::Config::validate
//! [`Config::nominal`]: crate::Config::nominal
pub mod cross_check;
pub mod id;
pub mod table;

pub use cross_check::cross_check;
pub use id::{ParamError, ParamId, ADDED_DEFAULTS, COUNT, LEGACY_COUNT};
pub use table::{apply_all, snapshot, TableError, LAYOUT_FINGERPRINT, LEGACY_FINGERPRINT};

#[cfg(test)]
mod tests;
