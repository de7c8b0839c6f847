//! The catalogue of switchable physical effects (`shared/contracts/effects.md`): their fixed
//! names and parameter names, parsing of `name:param=value,…`, and how each changes a rig.
//!
//! Parameters not given take the defaults below: realistic magnitudes for this rig, used by
//! the paper's low-speed study when "all low-speed effects" are switched on.
//! `flux_harmonics` realises its 6th-harmonic torque ratio r with 5th and 7th flux harmonics
//! sharing it equally: with i_d = 0, T_6/T_0 = (7ψ_7 − 5ψ_5)/ψ_f (see [`crate::motor`]), so
//! ψ_7 = r·ψ_f/14 and ψ_5 = −r·ψ_f/10 at the same phase.

use crate::rig::{CoggingHarmonic, FluxHarmonic, Rig};

/// One effect with its parameters (SI; orders in cycles per mechanical revolution).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Effect {
    /// The nominal model explains the data.
    None,
    /// Kinematic flow ripple of the piston pump (eq. 20–21).
    PistonRipple {
        /// Pistons z. [1]
        pistons: u32,
        /// Peak-to-peak flow ripple over mean flow (0: kinematic value for z). [1]
        amplitude_ratio: f64,
    },
    /// Slotting torque (eq. 16).
    CoggingTorque {
        /// Amplitude. [N·m]
        amplitude_nm: f64,
        /// Cycles per mechanical revolution, 1 to [`MAX_COGGING_ORDER`]; 0 stands for the
        /// rig's own, LCM(slots, poles), when `order` is not given ([`Effect::resolved`]
        /// says which). [1]
        order: u32,
        /// Phase. [rad]
        phase_rad: f64,
    },
    /// 5th/7th flux harmonics giving a 6th-electrical-harmonic torque (eq. 17–19).
    FluxHarmonics {
        /// 6th-harmonic torque over mean torque. [1]
        t6_ratio: f64,
        /// Phase. [rad]
        phase_rad: f64,
    },
    /// Inverter dead time.
    DeadTime {
        /// Dead time. [s]
        dead_time_s: f64,
    },
    /// Coulomb and breakaway friction of the motor–pump shaft.
    ShaftFriction {
        /// Coulomb torque. [N·m]
        coulomb_nm: f64,
        /// Breakaway torque. [N·m]
        static_nm: f64,
    },
    /// Cylinder friction beyond the rig file.
    CylinderFriction {
        /// Additional Coulomb force. [N]
        coulomb_n: f64,
        /// Additional breakaway force. [N]
        static_n: f64,
    },
    /// Leakage from the high-pressure side beyond the rig file.
    ExtraLeakage {
        /// Coefficient. [(m³/s)/Pa]
        coefficient_m3_s_pa: f64,
    },
    /// Effective bulk modulus below the rig file's.
    EntrainedAir {
        /// Effective bulk modulus. [Pa]
        effective_bulk_modulus_pa: f64,
    },
    /// Absorber precharge different from the rig file.
    AccumulatorPrecharge {
        /// Precharge. [Pa]
        precharge_pa: f64,
    },
    /// First-order lag of the pressure transducer.
    PressureSensorLag {
        /// Time constant. [s]
        time_constant_s: f64,
    },
    /// DC offset on phase a's current channel.
    CurrentSensorOffset {
        /// Offset. [A]
        offset_a: f64,
    },
}

/// Every effect name of the contract, in its order.
pub const EFFECT_NAMES: [&str; 12] = [
    "none",
    "piston_ripple",
    "cogging_torque",
    "flux_harmonics",
    "dead_time",
    "shaft_friction",
    "cylinder_friction",
    "extra_leakage",
    "entrained_air",
    "accumulator_precharge",
    "pressure_sensor_lag",
    "current_sensor_offset",
];

/// The highest cogging order `order` may name: at one revolution per second its torque
/// already beats at 10 kHz, the Nyquist rate of the 20 kHz current loop, so the controller
/// could not see a higher one; real motors' LCM(slots, poles) lie in the tens to hundreds.
pub const MAX_COGGING_ORDER: u32 = 10_000;

/// Why an effect specification was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EffectError {
    /// The name is not in the catalogue.
    UnknownEffect,
    /// The parameter is not one of this effect's.
    UnknownParameter,
    /// `param=value` was expected.
    Malformed,
    /// The value is not a finite number.
    BadValue,
    /// A count (pistons, an order) that is not a whole number from `min` to `max`.
    NotWhole {
        /// The parameter.
        param: &'static str,
        /// Its least value.
        min: u32,
        /// Its greatest value.
        max: u32,
    },
    /// The value is outside the parameter's physical range.
    OutOfRange,
}

impl core::fmt::Display for EffectError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            EffectError::UnknownEffect => f.write_str("unknown effect name"),
            EffectError::UnknownParameter => f.write_str("unknown parameter for this effect"),
            EffectError::Malformed => f.write_str("expected `param=value`"),
            EffectError::BadValue => f.write_str("value is not a finite number"),
            EffectError::NotWhole { param, min, max } => {
                write!(f, "`{param}` takes a whole number from {min} to {max}")?;
                if *param == "order" {
                    // The catalogue's default is the rig's own order; 0 never means it.
                    f.write_str(" (leave it out for the rig's LCM(slots, poles))")?;
                }
                Ok(())
            }
            EffectError::OutOfRange => {
                f.write_str("value is outside the parameter's physical range")
            }
        }
    }
}

impl Effect {
    /// The contract name.
    pub fn name(&self) -> &'static str {
        match self {
            Effect::None => "none",
            Effect::PistonRipple { .. } => "piston_ripple",
            Effect::CoggingTorque { .. } => "cogging_torque",
            Effect::FluxHarmonics { .. } => "flux_harmonics",
            Effect::DeadTime { .. } => "dead_time",
            Effect::ShaftFriction { .. } => "shaft_friction",
            Effect::CylinderFriction { .. } => "cylinder_friction",
            Effect::ExtraLeakage { .. } => "extra_leakage",
            Effect::EntrainedAir { .. } => "entrained_air",
            Effect::AccumulatorPrecharge { .. } => "accumulator_precharge",
            Effect::PressureSensorLag { .. } => "pressure_sensor_lag",
            Effect::CurrentSensorOffset { .. } => "current_sensor_offset",
        }
    }

    /// The effect `name` with default parameters.
    pub fn default_for(name: &str) -> Result<Effect, EffectError> {
        Ok(match name {
            "none" => Effect::None,
            "piston_ripple" => Effect::PistonRipple {
                pistons: 9,
                amplitude_ratio: 0.0,
            },
            "cogging_torque" => Effect::CoggingTorque {
                amplitude_nm: 0.05,
                order: 0,
                phase_rad: 0.0,
            },
            "flux_harmonics" => Effect::FluxHarmonics {
                t6_ratio: 0.02,
                phase_rad: 0.0,
            },
            "dead_time" => Effect::DeadTime { dead_time_s: 1e-6 },
            "shaft_friction" => Effect::ShaftFriction {
                coulomb_nm: 0.05,
                static_nm: 0.08,
            },
            "cylinder_friction" => Effect::CylinderFriction {
                coulomb_n: 200.0,
                static_n: 300.0,
            },
            "extra_leakage" => Effect::ExtraLeakage {
                coefficient_m3_s_pa: 1e-13,
            },
            "entrained_air" => Effect::EntrainedAir {
                effective_bulk_modulus_pa: 3e8,
            },
            "accumulator_precharge" => Effect::AccumulatorPrecharge { precharge_pa: 2e6 },
            "pressure_sensor_lag" => Effect::PressureSensorLag {
                time_constant_s: 2e-3,
            },
            "current_sensor_offset" => Effect::CurrentSensorOffset { offset_a: 0.2 },
            _ => return Err(EffectError::UnknownEffect),
        })
    }

    /// Parses `name` or `name:param=value,param=value` (parameter names of the contract).
    pub fn parse(spec: &str) -> Result<Effect, EffectError> {
        let (name, params) = match spec.split_once(':') {
            Some((n, p)) => (n.trim(), Some(p)),
            None => (spec.trim(), None),
        };
        let mut e = Effect::default_for(name)?;
        if let Some(params) = params {
            for kv in params.split(',').map(str::trim).filter(|s| !s.is_empty()) {
                let (k, v) = kv.split_once('=').ok_or(EffectError::Malformed)?;
                let v: f64 = v.trim().parse().map_err(|_| EffectError::BadValue)?;
                if !v.is_finite() {
                    return Err(EffectError::BadValue);
                }
                e.set(k.trim(), v)?;
            }
        }
        e.check_range()?;
        Ok(e)
    }

    /// The parameters as (contract name, value) pairs; unused slots are `None`.
    pub fn parameters(&self) -> [Option<(&'static str, f64)>; 3] {
        match *self {
            Effect::None => [None, None, None],
            Effect::PistonRipple {
                pistons,
                amplitude_ratio,
            } => [
                Some(("pistons", pistons as f64)),
                Some(("amplitude_ratio", amplitude_ratio)),
                None,
            ],
            Effect::CoggingTorque {
                amplitude_nm,
                order,
                phase_rad,
            } => [
                Some(("amplitude_nm", amplitude_nm)),
                Some(("order", order as f64)),
                Some(("phase_rad", phase_rad)),
            ],
            Effect::FluxHarmonics {
                t6_ratio,
                phase_rad,
            } => [
                Some(("t6_ratio", t6_ratio)),
                Some(("phase_rad", phase_rad)),
                None,
            ],
            Effect::DeadTime { dead_time_s } => [Some(("dead_time_s", dead_time_s)), None, None],
            Effect::ShaftFriction {
                coulomb_nm,
                static_nm,
            } => [
                Some(("coulomb_nm", coulomb_nm)),
                Some(("static_nm", static_nm)),
                None,
            ],
            Effect::CylinderFriction {
                coulomb_n,
                static_n,
            } => [
                Some(("coulomb_n", coulomb_n)),
                Some(("static_n", static_n)),
                None,
            ],
            Effect::ExtraLeakage {
                coefficient_m3_s_pa,
            } => [
                Some(("coefficient_m3_s_pa", coefficient_m3_s_pa)),
                None,
                None,
            ],
            Effect::EntrainedAir {
                effective_bulk_modulus_pa,
            } => [
                Some(("effective_bulk_modulus_pa", effective_bulk_modulus_pa)),
                None,
                None,
            ],
            Effect::AccumulatorPrecharge { precharge_pa } => {
                [Some(("precharge_pa", precharge_pa)), None, None]
            }
            Effect::PressureSensorLag { time_constant_s } => {
                [Some(("time_constant_s", time_constant_s)), None, None]
            }
            Effect::CurrentSensorOffset { offset_a } => [Some(("offset_a", offset_a)), None, None],
        }
    }

    /// Sets one parameter by its contract name.
    pub fn set(&mut self, param: &str, v: f64) -> Result<(), EffectError> {
        let whole = |param: &'static str, min: u32, max: u32| -> Result<u32, EffectError> {
            if v >= f64::from(min) && v <= f64::from(max) && libm::floor(v) == v {
                Ok(v as u32)
            } else {
                Err(EffectError::NotWhole { param, min, max })
            }
        };
        match (self, param) {
            (Effect::PistonRipple { pistons, .. }, "pistons") => {
                *pistons = whole("pistons", 3, 31)?
            }
            (
                Effect::PistonRipple {
                    amplitude_ratio, ..
                },
                "amplitude_ratio",
            ) => *amplitude_ratio = v,
            (Effect::CoggingTorque { amplitude_nm, .. }, "amplitude_nm") => *amplitude_nm = v,
            (Effect::CoggingTorque { order, .. }, "order") => {
                *order = whole("order", 1, MAX_COGGING_ORDER)?
            }
            (Effect::CoggingTorque { phase_rad, .. }, "phase_rad") => *phase_rad = v,
            (Effect::FluxHarmonics { t6_ratio, .. }, "t6_ratio") => *t6_ratio = v,
            (Effect::FluxHarmonics { phase_rad, .. }, "phase_rad") => *phase_rad = v,
            (Effect::DeadTime { dead_time_s }, "dead_time_s") => *dead_time_s = v,
            (Effect::ShaftFriction { coulomb_nm, .. }, "coulomb_nm") => *coulomb_nm = v,
            (Effect::ShaftFriction { static_nm, .. }, "static_nm") => *static_nm = v,
            (Effect::CylinderFriction { coulomb_n, .. }, "coulomb_n") => *coulomb_n = v,
            (Effect::CylinderFriction { static_n, .. }, "static_n") => *static_n = v,
            (
                Effect::ExtraLeakage {
                    coefficient_m3_s_pa,
                },
                "coefficient_m3_s_pa",
            ) => *coefficient_m3_s_pa = v,
            (
                Effect::EntrainedAir {
                    effective_bulk_modulus_pa,
                },
                "effective_bulk_modulus_pa",
            ) => *effective_bulk_modulus_pa = v,
            (Effect::AccumulatorPrecharge { precharge_pa }, "precharge_pa") => *precharge_pa = v,
            (Effect::PressureSensorLag { time_constant_s }, "time_constant_s") => {
                *time_constant_s = v
            }
            (Effect::CurrentSensorOffset { offset_a }, "offset_a") => *offset_a = v,
            _ => return Err(EffectError::UnknownParameter),
        }
        Ok(())
    }

    fn check_range(&self) -> Result<(), EffectError> {
        let ok = match *self {
            Effect::None => true,
            Effect::PistonRipple {
                pistons,
                amplitude_ratio,
            } => (3..=31).contains(&pistons) && (0.0..1.0).contains(&amplitude_ratio),
            Effect::CoggingTorque { amplitude_nm, .. } => amplitude_nm >= 0.0,
            Effect::FluxHarmonics { t6_ratio, .. } => libm::fabs(t6_ratio) < 0.5,
            Effect::DeadTime { dead_time_s } => (0.0..=10e-6).contains(&dead_time_s),
            Effect::ShaftFriction {
                coulomb_nm,
                static_nm,
            } => coulomb_nm >= 0.0 && static_nm >= 0.0,
            Effect::CylinderFriction {
                coulomb_n,
                static_n,
            } => coulomb_n >= 0.0 && static_n >= 0.0,
            Effect::ExtraLeakage {
                coefficient_m3_s_pa,
            } => coefficient_m3_s_pa >= 0.0,
            Effect::EntrainedAir {
                effective_bulk_modulus_pa,
            } => effective_bulk_modulus_pa > 1e6,
            Effect::AccumulatorPrecharge { precharge_pa } => precharge_pa > 0.0,
            Effect::PressureSensorLag { time_constant_s } => time_constant_s >= 0.0,
            Effect::CurrentSensorOffset { .. } => true,
        };
        if ok {
            Ok(())
        } else {
            Err(EffectError::OutOfRange)
        }
    }

    /// The effect as it acts on `rig`, every default stated: the cogging order left out
    /// (0) becomes the rig's LCM(slots, poles). What a log's metadata should record.
    pub fn resolved(&self, rig: &Rig) -> Effect {
        match *self {
            Effect::CoggingTorque {
                amplitude_nm,
                order: 0,
                phase_rad,
            } => Effect::CoggingTorque {
                amplitude_nm,
                order: rig.motor.cogging_fundamental_order(),
                phase_rad,
            },
            e => e,
        }
    }

    /// Switches the effect on in `rig` (the rig is re-validated by whoever builds a plant).
    pub fn apply(&self, rig: &mut Rig) {
        match *self {
            Effect::None => {}
            Effect::PistonRipple {
                pistons,
                amplitude_ratio,
            } => {
                rig.pump.pistons = pistons;
                rig.pump.piston_ripple = true;
                rig.pump.ripple_amplitude_ratio = amplitude_ratio;
            }
            Effect::CoggingTorque {
                amplitude_nm,
                order,
                phase_rad,
            } => {
                let order = if order == 0 {
                    rig.motor.cogging_fundamental_order()
                } else {
                    order
                };
                rig.motor.cogging[0] = CoggingHarmonic {
                    amplitude_nm,
                    order,
                    phase_rad,
                };
            }
            Effect::FluxHarmonics {
                t6_ratio,
                phase_rad,
            } => {
                let psi = rig.motor.psi_f_wb;
                rig.motor.flux_harmonics[0] = FluxHarmonic {
                    amplitude_wb: -t6_ratio * psi / 10.0,
                    order: 5,
                    phase_rad,
                };
                rig.motor.flux_harmonics[1] = FluxHarmonic {
                    amplitude_wb: t6_ratio * psi / 14.0,
                    order: 7,
                    phase_rad,
                };
            }
            Effect::DeadTime { dead_time_s } => rig.inverter.dead_time_s = dead_time_s,
            Effect::ShaftFriction {
                coulomb_nm,
                static_nm,
            } => {
                rig.shaft.coulomb_nm = coulomb_nm;
                rig.shaft.static_nm = static_nm;
            }
            Effect::CylinderFriction {
                coulomb_n,
                static_n,
            } => {
                rig.cylinder.coulomb_friction_n += coulomb_n;
                rig.cylinder.static_friction_n += static_n;
            }
            Effect::ExtraLeakage {
                coefficient_m3_s_pa,
            } => rig.pump.extra_leakage_m3_s_pa += coefficient_m3_s_pa,
            Effect::EntrainedAir {
                effective_bulk_modulus_pa,
            } => rig.oil.bulk_modulus_pa = effective_bulk_modulus_pa,
            Effect::AccumulatorPrecharge { precharge_pa } => {
                rig.absorber.precharge_pa = precharge_pa
            }
            Effect::PressureSensorLag { time_constant_s } => {
                rig.sensors.pressure.lag_time_constant_s = time_constant_s
            }
            Effect::CurrentSensorOffset { offset_a } => rig.sensors.current.offset_a[0] = offset_a,
        }
    }
}

/// The paper's low-speed effects (Section 4: cogging, flux harmonics, piston ripple) with
/// their default parameters.
pub fn paper_low_speed_effects() -> [Effect; 3] {
    [
        Effect::CoggingTorque {
            amplitude_nm: 0.05,
            order: 0,
            phase_rad: 0.0,
        },
        Effect::FluxHarmonics {
            t6_ratio: 0.02,
            phase_rad: 0.0,
        },
        Effect::PistonRipple {
            pistons: 9,
            amplitude_ratio: 0.0,
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_contract_name_parses_and_round_trips() {
        for name in EFFECT_NAMES {
            let e = Effect::parse(name).unwrap();
            assert_eq!(e.name(), name);
        }
        let e = Effect::parse("cogging_torque:amplitude_nm=0.07,order=36").unwrap();
        assert_eq!(
            e,
            Effect::CoggingTorque {
                amplitude_nm: 0.07,
                order: 36,
                phase_rad: 0.0
            }
        );
    }

    #[test]
    fn bad_specifications_are_refused() {
        assert_eq!(Effect::parse("cogging"), Err(EffectError::UnknownEffect));
        assert_eq!(
            Effect::parse("dead_time:deadtime=1e-6"),
            Err(EffectError::UnknownParameter)
        );
        assert_eq!(Effect::parse("dead_time:1e-6"), Err(EffectError::Malformed));
        assert_eq!(
            Effect::parse("dead_time:dead_time_s=inf"),
            Err(EffectError::BadValue)
        );
        let pistons = Err(EffectError::NotWhole {
            param: "pistons",
            min: 3,
            max: 31,
        });
        assert_eq!(Effect::parse("piston_ripple:pistons=8.5"), pistons);
        assert_eq!(Effect::parse("piston_ripple:pistons=2"), pistons);
        // Counts say they are counts, whatever is wrong with them; 0 is no cogging order.
        let order = EffectError::NotWhole {
            param: "order",
            min: 1,
            max: MAX_COGGING_ORDER,
        };
        for spec in [
            "cogging_torque:order=0.5",
            "cogging_torque:order=-3",
            "cogging_torque:order=1e30",
            "cogging_torque:order=0",
        ] {
            assert_eq!(Effect::parse(spec), Err(order), "{spec}");
        }
        extern crate std;
        use std::string::ToString;
        assert!(order.to_string().contains("whole number from 1 to 10000"));
        assert_eq!(
            Effect::parse("entrained_air:effective_bulk_modulus_pa=-3"),
            Err(EffectError::OutOfRange)
        );
    }

    #[test]
    fn nominal_rig_has_every_catalogue_effect_off() {
        let r = Rig::nominal();
        assert!(!r.pump.piston_ripple);
        assert!(r.motor.cogging.iter().all(|c| c.amplitude_nm == 0.0));
        assert!(r.motor.flux_harmonics.iter().all(|h| h.amplitude_wb == 0.0));
        assert_eq!(r.inverter.dead_time_s, 0.0);
        assert_eq!(r.shaft.static_nm, 0.0);
        assert_eq!(r.pump.extra_leakage_m3_s_pa, 0.0);
        assert_eq!(r.sensors.pressure.lag_time_constant_s, 0.0);
        assert_eq!(r.sensors.current.offset_a, [0.0; 3]);
        // Table 2's friction, leakage, compressibility and absorber are in.
        assert_eq!(r.cylinder.static_friction_n, 25.0);
        assert_eq!(r.absorber.precharge_pa, 3e6);
    }

    #[test]
    fn applied_effects_keep_the_rig_valid() {
        for name in EFFECT_NAMES {
            let mut r = Rig::nominal();
            Effect::parse(name).unwrap().apply(&mut r);
            assert_eq!(r.validate(), Ok(()), "{name}");
        }
    }
}
