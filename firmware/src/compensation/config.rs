//! The torque feed-forward's live parameters (ids 60–62 of [`crate::parameters`], and the
//! pump's flow-ripple modulation, [`super::flow`]) and their single-field rules; the
//! amplitude bound against the other sections is [`super::Compensation::check_amplitude`].

use crate::config::error::ConfigError;

/// Fewest pistons the closed form holds for (z = 1 and 2 are not a cosine cap of half
/// width ≤ π/4). [1]
pub const MIN_PISTONS: u32 = 3;

/// The feed-forward's live parameters (ids 60–62 of [`crate::parameters`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompensationConfig {
    /// The feed-forward acts (in Speed and Pressure, with a committed table).
    pub enabled: bool,
    /// Gain g on the whole table. [1]
    pub scale: f32,
    /// Largest amplitude the feed-forward may reach over the operating range. [A]
    pub max_current_a: f32,
    /// Pistons z of the pump whose flow ripple the speed modulation cancels ([`flow`];
    /// 0: no modulation, else at least [`MIN_PISTONS`]). [1]
    pub flow_pistons: u32,
    /// The pump's flow ripple, peak-to-peak over the mean flow (0: no modulation). [1]
    pub flow_ratio: f32,
    /// Phase of the ripple's shape against the encoder's angle. [rad]
    pub flow_phase_rad: f32,
    /// Shaft inertia (motor and pump) of the modulation's acceleration current. [kg·m²]
    pub inertia_kg_m2: f32,
    /// Largest modulation depth `scale·flow_ratio` (peak-to-peak over the mean speed). [1]
    pub max_flow_ratio: f32,
}

impl CompensationConfig {
    /// Off, unit scale, 3 A limit (a tenth of the q-current limit: room for three times
    /// the nominal rig's ripples at full current, whose flux harmonics alone are 2 % of it).
    pub const fn nominal() -> CompensationConfig {
        CompensationConfig {
            enabled: false,
            scale: 1.0,
            max_current_a: 3.0,
            flow_pistons: 0,
            flow_ratio: 0.0,
            flow_phase_rad: 0.0,
            inertia_kg_m2: 8.0e-4,
            max_flow_ratio: 0.1,
        }
    }

    /// The single-field rules (the parameter bounds).
    pub fn validate(&self) -> Result<(), ConfigError> {
        if !(self.scale.is_finite() && (0.0..=2.0).contains(&self.scale)) {
            return Err(ConfigError {
                field: "compensation.scale",
                problem: "must be within 0..=2",
            });
        }
        if !(self.max_current_a.is_finite() && (0.0..=10.0).contains(&self.max_current_a)) {
            return Err(ConfigError {
                field: "compensation.max_current_a",
                problem: "must be within 0..=10",
            });
        }
        if self.flow_pistons > 31 || (1..MIN_PISTONS).contains(&self.flow_pistons) {
            return Err(ConfigError {
                field: "compensation.flow_pistons",
                problem: "must be 0 (off) or within 3..=31",
            });
        }
        let within = |v: f32, hi: f32| v.is_finite() && (0.0..=hi).contains(&v);
        if !within(self.flow_ratio, 0.5) {
            return Err(ConfigError {
                field: "compensation.flow_ratio",
                problem: "must be within 0..=0.5",
            });
        }
        if !within(self.flow_phase_rad, core::f32::consts::TAU) {
            return Err(ConfigError {
                field: "compensation.flow_phase_rad",
                problem: "must be within 0..=2*pi",
            });
        }
        if !within(self.inertia_kg_m2, 1.0) {
            return Err(ConfigError {
                field: "compensation.inertia_kg_m2",
                problem: "must be within 0..=1",
            });
        }
        if !within(self.max_flow_ratio, 0.5) {
            return Err(ConfigError {
                field: "compensation.max_flow_ratio",
                problem: "must be within 0..=0.5",
            });
        }
        if self.scale * self.flow_ratio > self.max_flow_ratio {
            return Err(ConfigError {
                field: "compensation.flow_ratio",
                problem: "scale * flow_ratio must be at most compensation.max_flow_ratio",
            });
        }
        Ok(())
    }
}
