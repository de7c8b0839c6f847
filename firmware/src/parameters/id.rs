//! The parameters' identities: each parameter's wire id, name (its [`Config`] field
//! path), SI unit and bounds, how it is read from and written into a [`Config`], and why a
//! value is refused ([`ParamError`]). The table itself is in the [`super`] documentation.

use super::cross_check::cross_check;
use crate::config::sections::Config;
use core::fmt;

/// Number of parameters in the table.
pub const COUNT: usize = 39;

/// Number of parameters before the flow-ripple modulation's (ids 64–68) were added: a
/// stored record of that table still loads ([`crate::param_store`]), the new ones at
/// their defaults.
pub const LEGACY_COUNT: usize = 34;

/// The defaults of the parameters after the first [`LEGACY_COUNT`] (ids 64–68, those of
/// [`Config::nominal`]: a test holds them to it), as constants, so loading a legacy record
/// links no configuration.
pub const ADDED_DEFAULTS: [f32; COUNT - LEGACY_COUNT] = [0.0, 0.0, 0.0, 8.0e-4, 0.1];

/// A parameter of the live table; the discriminant is the wire id.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum ParamId {
    /// d-axis current PI proportional gain `current.kp_d`. [V/A]
    CurrentKpD = 1,
    /// d-axis current PI integral gain `current.ki_d`. [V/(A·s)]
    CurrentKiD = 2,
    /// q-axis current PI proportional gain `current.kp_q`. [V/A]
    CurrentKpQ = 3,
    /// q-axis current PI integral gain `current.ki_q`. [V/(A·s)]
    CurrentKiQ = 4,
    /// Output limit of each current PI `current.voltage_limit_v`. [V]
    CurrentVoltageLimit = 5,
    /// Speed PI proportional gain `speed.kp`. [A/(rad/s)]
    SpeedKp = 10,
    /// Speed PI integral gain `speed.ki`. [A/rad]
    SpeedKi = 11,
    /// Active damping Ba `speed.active_damping`. [A/(rad/s)]
    SpeedActiveDamping = 12,
    /// q-current reference limit `speed.iq_limit_a`. [A]
    SpeedIqLimit = 13,
    /// Speed reference limit `speed.speed_limit_rad_s`. [rad/s]
    SpeedLimit = 14,
    /// Speed observer bandwidth `speed.observer_bandwidth_rad_s`. [rad/s]
    SpeedObserverBandwidth = 15,
    /// Pressure-loop crossover `pressure.bandwidth_rad_s`. [rad/s]
    PressureBandwidth = 20,
    /// PI corner as a fraction of the crossover `pressure.integral_corner_ratio`. [1]
    PressureIntegralCornerRatio = 21,
    /// Pressure feedback low-pass corner `pressure.feedback_filter_rad_s`. [rad/s]
    PressureFeedbackFilter = 22,
    /// Pressure setpoint ramp rate `pressure.ramp_pa_per_s`. [Pa/s]
    PressureRamp = 23,
    /// Smallest pressure setpoint `pressure.setpoint_min_pa`. [Pa]
    PressureSetpointMin = 24,
    /// Largest pressure setpoint `pressure.setpoint_max_pa`. [Pa]
    PressureSetpointMax = 25,
    /// Pump displacement `hydraulics.pump_displacement_m3_per_rev`. [m³/rev]
    PumpDisplacement = 30,
    /// High-side oil volume `hydraulics.oil_volume_m3`. [m³]
    OilVolume = 31,
    /// Oil bulk modulus `hydraulics.bulk_modulus_pa`. [Pa]
    BulkModulus = 32,
    /// Absorber shell volume `hydraulics.absorber_volume_m3`. [m³]
    AbsorberVolume = 33,
    /// Absorber gas precharge (gauge) `hydraulics.absorber_precharge_pa`. [Pa]
    AbsorberPrechargePa = 34,
    /// Gas polytropic exponent `hydraulics.polytropic_exponent`. [1]
    PolytropicExponent = 35,
    /// Leakage conductance `hydraulics.leakage_m3_per_s_pa`. [(m³/s)/Pa]
    Leakage = 36,
    /// PWM periods per telemetry frame `rates.telemetry_decimation`. [1]
    TelemetryDecimation = 40,
    /// Commissioned stator resistance `motor.stator_resistance_ohm`. [Ω]
    StatorResistance = 50,
    /// Commissioned d-axis inductance `motor.d_inductance_h`. [H]
    DInductance = 51,
    /// Commissioned q-axis inductance `motor.q_inductance_h`. [H]
    QInductance = 52,
    /// Commissioned flux linkage `motor.flux_linkage_wb`. [Wb]
    FluxLinkage = 53,
    /// Commissioned encoder electrical offset `sensors.encoder_offset_rad`. [rad]
    EncoderOffset = 54,
    /// Torque feed-forward on (1) or off (0) `compensation.enabled`. [1]
    CompensationEnabled = 60,
    /// Gain on the feed-forward's table `compensation.scale`. [1]
    CompensationScale = 61,
    /// Largest feed-forward amplitude `compensation.max_current_a`. [A]
    CompensationMaxCurrent = 62,
    /// Action: 1 empties the feed-forward's table `compensation.clear`. [1]
    CompensationClear = 63,
    /// Pistons of the pump whose flow ripple the speed modulation cancels (0: off)
    /// `compensation.flow_pistons`. [1]
    CompensationFlowPistons = 64,
    /// The pump's flow ripple, peak-to-peak over mean flow `compensation.flow_ratio`. [1]
    CompensationFlowRatio = 65,
    /// Phase of the flow ripple against the encoder's angle `compensation.flow_phase_rad`.
    /// [rad]
    CompensationFlowPhase = 66,
    /// Shaft inertia of the modulation's acceleration current `compensation.inertia_kg_m2`.
    /// [kg·m²]
    CompensationInertia = 67,
    /// Largest speed-modulation depth `compensation.max_flow_ratio`. [1]
    CompensationMaxFlowRatio = 68,
}

/// Name, unit and bounds of one parameter.
pub(super) struct Spec {
    pub(super) name: &'static str,
    unit: &'static str,
    min: f32,
    max: f32,
}

const fn spec(name: &'static str, unit: &'static str, min: f32, max: f32) -> Spec {
    Spec {
        name,
        unit,
        min,
        max,
    }
}

impl ParamId {
    /// Every parameter, in wire-id order (also the order of the stored record).
    pub const ALL: [ParamId; COUNT] = [
        ParamId::CurrentKpD,
        ParamId::CurrentKiD,
        ParamId::CurrentKpQ,
        ParamId::CurrentKiQ,
        ParamId::CurrentVoltageLimit,
        ParamId::SpeedKp,
        ParamId::SpeedKi,
        ParamId::SpeedActiveDamping,
        ParamId::SpeedIqLimit,
        ParamId::SpeedLimit,
        ParamId::SpeedObserverBandwidth,
        ParamId::PressureBandwidth,
        ParamId::PressureIntegralCornerRatio,
        ParamId::PressureFeedbackFilter,
        ParamId::PressureRamp,
        ParamId::PressureSetpointMin,
        ParamId::PressureSetpointMax,
        ParamId::PumpDisplacement,
        ParamId::OilVolume,
        ParamId::BulkModulus,
        ParamId::AbsorberVolume,
        ParamId::AbsorberPrechargePa,
        ParamId::PolytropicExponent,
        ParamId::Leakage,
        ParamId::TelemetryDecimation,
        ParamId::StatorResistance,
        ParamId::DInductance,
        ParamId::QInductance,
        ParamId::FluxLinkage,
        ParamId::EncoderOffset,
        ParamId::CompensationEnabled,
        ParamId::CompensationScale,
        ParamId::CompensationMaxCurrent,
        ParamId::CompensationClear,
        ParamId::CompensationFlowPistons,
        ParamId::CompensationFlowRatio,
        ParamId::CompensationFlowPhase,
        ParamId::CompensationInertia,
        ParamId::CompensationMaxFlowRatio,
    ];

    pub(super) const fn spec(self) -> Spec {
        use ParamId::*;
        match self {
            CurrentKpD => spec("current.kp_d", "V/A", 0.01, 200.0),
            CurrentKiD => spec("current.ki_d", "V/(A·s)", 0.0, 1e5),
            CurrentKpQ => spec("current.kp_q", "V/A", 0.01, 200.0),
            CurrentKiQ => spec("current.ki_q", "V/(A·s)", 0.0, 1e5),
            CurrentVoltageLimit => spec("current.voltage_limit_v", "V", 1.0, 250.0),
            SpeedKp => spec("speed.kp", "A/(rad/s)", 1e-4, 10.0),
            SpeedKi => spec("speed.ki", "A/rad", 0.0, 1000.0),
            SpeedActiveDamping => spec("speed.active_damping", "A/(rad/s)", 0.0, 1.0),
            SpeedIqLimit => spec("speed.iq_limit_a", "A", 0.1, 100.0),
            SpeedLimit => spec("speed.speed_limit_rad_s", "rad/s", 1.0, 1000.0),
            SpeedObserverBandwidth => spec("speed.observer_bandwidth_rad_s", "rad/s", 10.0, 5000.0),
            PressureBandwidth => spec("pressure.bandwidth_rad_s", "rad/s", 0.1, 200.0),
            PressureIntegralCornerRatio => spec("pressure.integral_corner_ratio", "1", 0.0, 1.0),
            PressureFeedbackFilter => spec("pressure.feedback_filter_rad_s", "rad/s", 1.0, 5000.0),
            PressureRamp => spec("pressure.ramp_pa_per_s", "Pa/s", 1e3, 1e9),
            PressureSetpointMin => spec("pressure.setpoint_min_pa", "Pa", 0.0, 25e6),
            PressureSetpointMax => spec("pressure.setpoint_max_pa", "Pa", 1e5, 25e6),
            PumpDisplacement => spec(
                "hydraulics.pump_displacement_m3_per_rev",
                "m³/rev",
                1e-8,
                1e-4,
            ),
            OilVolume => spec("hydraulics.oil_volume_m3", "m³", 1e-6, 1e-2),
            BulkModulus => spec("hydraulics.bulk_modulus_pa", "Pa", 1e8, 2.5e9),
            AbsorberVolume => spec("hydraulics.absorber_volume_m3", "m³", 0.0, 1e-2),
            AbsorberPrechargePa => spec("hydraulics.absorber_precharge_pa", "Pa", 0.0, 25e6),
            PolytropicExponent => spec("hydraulics.polytropic_exponent", "1", 1.0, 2.0),
            Leakage => spec("hydraulics.leakage_m3_per_s_pa", "(m³/s)/Pa", 0.0, 1e-9),
            TelemetryDecimation => spec("rates.telemetry_decimation", "1", 1.0, 10_000.0),
            StatorResistance => spec("motor.stator_resistance_ohm", "Ω", 1e-3, 100.0),
            DInductance => spec("motor.d_inductance_h", "H", 1e-6, 1.0),
            QInductance => spec("motor.q_inductance_h", "H", 1e-6, 1.0),
            FluxLinkage => spec("motor.flux_linkage_wb", "Wb", 0.0, 5.0),
            EncoderOffset => spec(
                "sensors.encoder_offset_rad",
                "rad",
                0.0,
                core::f32::consts::TAU,
            ),
            CompensationEnabled => spec("compensation.enabled", "1", 0.0, 1.0),
            CompensationScale => spec("compensation.scale", "1", 0.0, 2.0),
            CompensationMaxCurrent => spec("compensation.max_current_a", "A", 0.0, 10.0),
            CompensationClear => spec("compensation.clear", "1", 0.0, 1.0),
            CompensationFlowPistons => spec("compensation.flow_pistons", "1", 0.0, 31.0),
            CompensationFlowRatio => spec("compensation.flow_ratio", "1", 0.0, 0.5),
            CompensationFlowPhase => spec(
                "compensation.flow_phase_rad",
                "rad",
                0.0,
                core::f32::consts::TAU,
            ),
            CompensationInertia => spec("compensation.inertia_kg_m2", "kg·m²", 0.0, 1.0),
            CompensationMaxFlowRatio => spec("compensation.max_flow_ratio", "1", 0.0, 0.5),
        }
    }

    /// Wire id.
    pub fn code(self) -> u8 {
        self as u8
    }

    /// From a wire id.
    pub fn from_code(code: u8) -> Option<ParamId> {
        ParamId::ALL.iter().copied().find(|p| p.code() == code)
    }

    /// Name: the dotted [`Config`] field path, e.g. `speed.kp`.
    pub fn name(self) -> &'static str {
        self.spec().name
    }

    /// From a name as returned by [`ParamId::name`].
    pub fn from_name(name: &str) -> Option<ParamId> {
        ParamId::ALL.iter().copied().find(|p| p.name() == name)
    }

    /// SI unit, as written in the table.
    pub fn unit(self) -> &'static str {
        self.spec().unit
    }

    /// Smallest accepted value. [unit]
    pub fn min(self) -> f32 {
        self.spec().min
    }

    /// Largest accepted value. [unit]
    pub fn max(self) -> f32 {
        self.spec().max
    }

    /// True for a parameter that may change only while the bridge is off: a new encoder
    /// offset turns the field orientation at once, a torque step no ramp can soften.
    pub fn needs_disabled(self) -> bool {
        self == ParamId::EncoderOffset
    }

    /// True for a parameter that takes whole numbers only.
    pub fn is_integer(self) -> bool {
        matches!(
            self,
            ParamId::TelemetryDecimation
                | ParamId::CompensationEnabled
                | ParamId::CompensationClear
                | ParamId::CompensationFlowPistons
        )
    }

    /// True for an action rather than a setting: writing it does something once, it is
    /// not a configuration field and always reads 0 (`compensation.clear`).
    pub fn is_action(self) -> bool {
        self == ParamId::CompensationClear
    }

    /// Default: the value in [`Config::nominal`]. [unit]
    pub fn default_value(self) -> f32 {
        self.get(&Config::nominal())
    }

    /// The value in `cfg`. [unit]
    pub fn get(self, cfg: &Config) -> f32 {
        use ParamId::*;
        match self {
            CurrentKpD => cfg.current.kp_d,
            CurrentKiD => cfg.current.ki_d,
            CurrentKpQ => cfg.current.kp_q,
            CurrentKiQ => cfg.current.ki_q,
            CurrentVoltageLimit => cfg.current.voltage_limit_v,
            SpeedKp => cfg.speed.kp,
            SpeedKi => cfg.speed.ki,
            SpeedActiveDamping => cfg.speed.active_damping,
            SpeedIqLimit => cfg.speed.iq_limit_a,
            SpeedLimit => cfg.speed.speed_limit_rad_s,
            SpeedObserverBandwidth => cfg.speed.observer_bandwidth_rad_s,
            PressureBandwidth => cfg.pressure.bandwidth_rad_s,
            PressureIntegralCornerRatio => cfg.pressure.integral_corner_ratio,
            PressureFeedbackFilter => cfg.pressure.feedback_filter_rad_s,
            PressureRamp => cfg.pressure.ramp_pa_per_s,
            PressureSetpointMin => cfg.pressure.setpoint_min_pa,
            PressureSetpointMax => cfg.pressure.setpoint_max_pa,
            PumpDisplacement => cfg.hydraulics.pump_displacement_m3_per_rev,
            OilVolume => cfg.hydraulics.oil_volume_m3,
            BulkModulus => cfg.hydraulics.bulk_modulus_pa,
            AbsorberVolume => cfg.hydraulics.absorber_volume_m3,
            AbsorberPrechargePa => cfg.hydraulics.absorber_precharge_pa,
            PolytropicExponent => cfg.hydraulics.polytropic_exponent,
            Leakage => cfg.hydraulics.leakage_m3_per_s_pa,
            // Validated to at most 10 000, exact in f32.
            TelemetryDecimation => cfg.rates.telemetry_decimation as f32,
            StatorResistance => cfg.motor.stator_resistance_ohm,
            DInductance => cfg.motor.d_inductance_h,
            QInductance => cfg.motor.q_inductance_h,
            FluxLinkage => cfg.motor.flux_linkage_wb,
            EncoderOffset => cfg.sensors.encoder_offset_rad,
            CompensationEnabled => f32::from(u8::from(cfg.compensation.enabled)),
            CompensationScale => cfg.compensation.scale,
            CompensationMaxCurrent => cfg.compensation.max_current_a,
            CompensationClear => 0.0,
            // At most 31, exact in f32.
            CompensationFlowPistons => cfg.compensation.flow_pistons as f32,
            CompensationFlowRatio => cfg.compensation.flow_ratio,
            CompensationFlowPhase => cfg.compensation.flow_phase_rad,
            CompensationInertia => cfg.compensation.inertia_kg_m2,
            CompensationMaxFlowRatio => cfg.compensation.max_flow_ratio,
        }
    }

    /// Writes `value` into `cfg` without any check (see [`ParamId::set`]).
    pub(super) fn write(self, cfg: &mut Config, value: f32) {
        use ParamId::*;
        let slot = match self {
            CurrentKpD => &mut cfg.current.kp_d,
            CurrentKiD => &mut cfg.current.ki_d,
            CurrentKpQ => &mut cfg.current.kp_q,
            CurrentKiQ => &mut cfg.current.ki_q,
            CurrentVoltageLimit => &mut cfg.current.voltage_limit_v,
            SpeedKp => &mut cfg.speed.kp,
            SpeedKi => &mut cfg.speed.ki,
            SpeedActiveDamping => &mut cfg.speed.active_damping,
            SpeedIqLimit => &mut cfg.speed.iq_limit_a,
            SpeedLimit => &mut cfg.speed.speed_limit_rad_s,
            SpeedObserverBandwidth => &mut cfg.speed.observer_bandwidth_rad_s,
            PressureBandwidth => &mut cfg.pressure.bandwidth_rad_s,
            PressureIntegralCornerRatio => &mut cfg.pressure.integral_corner_ratio,
            PressureFeedbackFilter => &mut cfg.pressure.feedback_filter_rad_s,
            PressureRamp => &mut cfg.pressure.ramp_pa_per_s,
            PressureSetpointMin => &mut cfg.pressure.setpoint_min_pa,
            PressureSetpointMax => &mut cfg.pressure.setpoint_max_pa,
            PumpDisplacement => &mut cfg.hydraulics.pump_displacement_m3_per_rev,
            OilVolume => &mut cfg.hydraulics.oil_volume_m3,
            BulkModulus => &mut cfg.hydraulics.bulk_modulus_pa,
            AbsorberVolume => &mut cfg.hydraulics.absorber_volume_m3,
            AbsorberPrechargePa => &mut cfg.hydraulics.absorber_precharge_pa,
            PolytropicExponent => &mut cfg.hydraulics.polytropic_exponent,
            Leakage => &mut cfg.hydraulics.leakage_m3_per_s_pa,
            TelemetryDecimation => {
                // Checked to be a whole number within 1..=10 000 before this is reached.
                cfg.rates.telemetry_decimation = value as u32;
                return;
            }
            CompensationEnabled => {
                // Checked to be 0 or 1 before this is reached.
                cfg.compensation.enabled = value != 0.0;
                return;
            }
            CompensationClear => return,
            CompensationFlowPistons => {
                // Checked to be a whole number within 0..=31 before this is reached.
                cfg.compensation.flow_pistons = value as u32;
                return;
            }
            StatorResistance => &mut cfg.motor.stator_resistance_ohm,
            DInductance => &mut cfg.motor.d_inductance_h,
            QInductance => &mut cfg.motor.q_inductance_h,
            FluxLinkage => &mut cfg.motor.flux_linkage_wb,
            EncoderOffset => &mut cfg.sensors.encoder_offset_rad,
            CompensationScale => &mut cfg.compensation.scale,
            CompensationMaxCurrent => &mut cfg.compensation.max_current_a,
            CompensationFlowRatio => &mut cfg.compensation.flow_ratio,
            CompensationFlowPhase => &mut cfg.compensation.flow_phase_rad,
            CompensationInertia => &mut cfg.compensation.inertia_kg_m2,
            CompensationMaxFlowRatio => &mut cfg.compensation.max_flow_ratio,
        };
        *slot = value;
    }

    /// Checks `value` against this parameter's own bounds (not the rest of a
    /// configuration).
    pub fn check(self, value: f32) -> Result<(), ParamError> {
        let s = self.spec();
        if value.is_nan() {
            Err(ParamError::NotANumber { id: self })
        } else if value < s.min {
            Err(ParamError::BelowMinimum {
                id: self,
                min: s.min,
            })
        } else if value > s.max {
            Err(ParamError::AboveMaximum {
                id: self,
                max: s.max,
            })
        } else if self.is_integer() && libm::truncf(value) != value {
            Err(ParamError::NotWhole { id: self })
        } else {
            Ok(())
        }
    }

    /// Sets the parameter in `cfg` if the value is within its bounds and the resulting
    /// configuration validates; otherwise `cfg` is left as it was.
    pub fn set(self, cfg: &mut Config, value: f32) -> Result<(), ParamError> {
        self.check(value)?;
        let mut next = *cfg;
        self.write(&mut next, value);
        cross_check(&next).map_err(|e| ParamError::Inconsistent {
            id: self,
            field: e.field,
            problem: e.problem,
        })?;
        *cfg = next;
        Ok(())
    }
}

impl fmt::Display for ParamId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} (id {})", self.name(), self.code())
    }
}

/// Why a parameter value was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamError {
    /// Below the parameter's minimum.
    BelowMinimum {
        /// The parameter.
        id: ParamId,
        /// Its minimum. [unit]
        min: f32,
    },
    /// Above the parameter's maximum.
    AboveMaximum {
        /// The parameter.
        id: ParamId,
        /// Its maximum. [unit]
        max: f32,
    },
    /// Not a number.
    NotANumber {
        /// The parameter.
        id: ParamId,
    },
    /// A whole-number parameter given a fraction.
    NotWhole {
        /// The parameter.
        id: ParamId,
    },
    /// Changeable only in Disabled ([`ParamId::needs_disabled`]).
    NotWhileRunning {
        /// The parameter.
        id: ParamId,
    },
    /// Within its bounds, but the configuration with it fails validation.
    Inconsistent {
        /// The parameter.
        id: ParamId,
        /// The configuration field [`Config::validate`] named.
        field: &'static str,
        /// What is wrong with it.
        problem: &'static str,
    },
}

impl ParamError {
    /// The refused parameter.
    pub fn id(&self) -> ParamId {
        match *self {
            ParamError::BelowMinimum { id, .. }
            | ParamError::AboveMaximum { id, .. }
            | ParamError::NotANumber { id }
            | ParamError::NotWhole { id }
            | ParamError::NotWhileRunning { id }
            | ParamError::Inconsistent { id, .. } => id,
        }
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamError::BelowMinimum { id, min } => {
                write!(f, "{id}: below its minimum {min} {}", id.unit())
            }
            ParamError::AboveMaximum { id, max } => {
                write!(f, "{id}: above its maximum {max} {}", id.unit())
            }
            ParamError::NotANumber { id } => write!(f, "{id}: not a number"),
            ParamError::NotWhole { id } => write!(f, "{id}: must be a whole number"),
            ParamError::NotWhileRunning { id } => write!(f, "{id}: only in Disabled"),
            ParamError::Inconsistent { id, field, problem } => {
                write!(f, "{id}: refused, config field `{field}` {problem}")
            }
        }
    }
}
