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

use core::f64::consts::PI;

/// Maximum number of cogging-torque harmonics (eq. 16 truncated).
pub const MAX_COGGING_HARMONICS: usize = 4;
/// Maximum number of permanent-magnet flux harmonics (eq. 17: orders 5, 7, 11, 13, …).
pub const MAX_FLUX_HARMONICS: usize = 4;

/// One term of the cogging torque series of eq. 16: `amplitude·sin(order·θ_m + phase)`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CoggingHarmonic {
    /// Amplitude. [N·m]
    pub amplitude_nm: f64,
    /// Cycles per mechanical revolution (a multiple of LCM(slots, poles) for slotting). [1]
    pub order: u32,
    /// Phase against the encoder's mechanical zero. [rad]
    pub phase_rad: f64,
}

/// One harmonic of the magnet flux linkage seen by phase a (eq. 17):
/// `amplitude·cos(order·θ_e + phase)`, phases b and c shifted by ∓2π/3 of the fundamental.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FluxHarmonic {
    /// Flux-linkage amplitude (signed). [Wb]
    pub amplitude_wb: f64,
    /// Electrical order: 6k ± 1 (5, 7, 11, 13, …). [1]
    pub order: u32,
    /// Phase. [rad]
    pub phase_rad: f64,
}

const NO_COGGING: CoggingHarmonic = CoggingHarmonic {
    amplitude_nm: 0.0,
    order: 72,
    phase_rad: 0.0,
};
const NO_FLUX_HARMONIC: FluxHarmonic = FluxHarmonic {
    amplitude_wb: 0.0,
    order: 5,
    phase_rad: 0.0,
};

/// PMSM parameters (eq. 1–7, 16–19).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MotorParams {
    /// Pole pairs p_n. [1]
    pub pole_pairs: u32,
    /// Stator resistance R_s. [Ω]
    pub r_s_ohm: f64,
    /// d-axis inductance L_d. [H]
    pub l_d_h: f64,
    /// q-axis inductance L_q. [H]
    pub l_q_h: f64,
    /// Permanent-magnet flux linkage ψ_f (fundamental, amplitude-invariant d-q). [Wb]
    pub psi_f_wb: f64,
    /// Stator slots N_s (sets the cogging fundamental LCM(N_s, 2·p_n)). [1]
    pub stator_slots: u32,
    /// Cogging torque series (eq. 16); zero amplitudes are off.
    pub cogging: [CoggingHarmonic; MAX_COGGING_HARMONICS],
    /// Flux-linkage harmonics (eq. 17); zero amplitudes are off.
    pub flux_harmonics: [FluxHarmonic; MAX_FLUX_HARMONICS],
}

impl MotorParams {
    /// Torque constant K_t = 1.5·p_n·ψ_f (eq. 5). [N·m/A]
    pub fn torque_constant_nm_per_a(&self) -> f64 {
        1.5 * self.pole_pairs as f64 * self.psi_f_wb
    }

    /// The cogging fundamental: cycles per mechanical revolution, LCM(N_s, 2·p_n) (eq. 16's N_cog).
    pub fn cogging_fundamental_order(&self) -> u32 {
        lcm(self.stator_slots, 2 * self.pole_pairs)
    }
}

/// Two-level voltage-source inverter, average model.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct InverterParams {
    /// DC-link voltage U_dc. [V]
    pub u_dc_v: f64,
    /// Switching (PWM) frequency, needed for the dead-time voltage error. [Hz]
    pub pwm_frequency_hz: f64,
    /// Dead time per switching edge pair; 0 is off. [s]
    pub dead_time_s: f64,
    /// Phase current below which the dead-time error fades linearly to zero (the ripple
    /// current makes the diode conduction interval depend on the current there). [A]
    pub dead_time_current_band_a: f64,
}

/// Motor-plus-pump shaft.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ShaftParams {
    /// Motor rotor inertia J_m (*assumed*). [kg·m²]
    pub motor_inertia_kg_m2: f64,
    /// Pump rotating-group inertia J_p (*assumed*). [kg·m²]
    pub pump_inertia_kg_m2: f64,
    /// Viscous friction D (eq. 4). [N·m·s/rad]
    pub viscous_nm_s: f64,
    /// Coulomb (sliding) friction torque; 0 is off. [N·m]
    pub coulomb_nm: f64,
    /// Static (breakaway) friction torque, ≥ Coulomb when on; 0 is off. [N·m]
    pub static_nm: f64,
}

impl ShaftParams {
    /// Total inertia J_L of eq. 4. [kg·m²]
    pub fn inertia_kg_m2(&self) -> f64 {
        self.motor_inertia_kg_m2 + self.pump_inertia_kg_m2
    }
}

/// Fixed-displacement axial piston pump (eq. 9, 20–21).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PumpParams {
    /// Displacement D_p. [m³/rev]
    pub displacement_m3_per_rev: f64,
    /// Pistons z (odd or even). [1]
    pub pistons: u32,
    /// Kinematic flow ripple of eq. 20 on or off (off: ideal flow D_p·ω).
    pub piston_ripple: bool,
    /// Peak-to-peak flow ripple over mean flow when the ripple is on; 0 means the kinematic
    /// value of eq. 20 for `pistons` (the shape is always the kinematic one). [1]
    pub ripple_amplitude_ratio: f64,
    /// Internal (port-to-port) leakage C_ip. [(m³/s)/Pa]
    pub internal_leakage_m3_s_pa: f64,
    /// External (port-to-case) leakage C_ep. [(m³/s)/Pa]
    pub external_leakage_m3_s_pa: f64,
    /// Extra leakage from the high-pressure port A to the case beyond C_ep (effect
    /// `extra_leakage`); 0 is off. [(m³/s)/Pa]
    pub extra_leakage_m3_s_pa: f64,
}

impl PumpParams {
    /// Displacement per radian D_p/(2π). [m³/rad]
    pub fn displacement_m3_per_rad(&self) -> f64 {
        self.displacement_m3_per_rev / (2.0 * PI)
    }
}

/// Double-acting symmetric cylinder and its load (eq. 11–12).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CylinderParams {
    /// Effective piston area, each side, A_p. [m²]
    pub area_m2: f64,
    /// Chamber 1 (port A side) volume at mid-stroke, lines included, V_10. [m³]
    pub chamber_a_volume_m3: f64,
    /// Chamber 2 (port B side) volume at mid-stroke, lines included, V_20. [m³]
    pub chamber_b_volume_m3: f64,
    /// Cross-piston leakage C_ic. [(m³/s)/Pa]
    pub internal_leakage_m3_s_pa: f64,
    /// Viscous damping B_p. [N·s/m]
    pub viscous_n_s_per_m: f64,
    /// Static (breakaway) friction F_s. [N]
    pub static_friction_n: f64,
    /// Coulomb (sliding) friction F_c. [N]
    pub coulomb_friction_n: f64,
    /// Payload mass referred to the piston m_t. [kg]
    pub mass_kg: f64,
    /// Half stroke: hard end stops at ±this about mid-stroke (*assumed*). [m]
    pub half_stroke_m: f64,
    /// End-stop contact stiffness (*assumed*). [N/m]
    pub end_stop_stiffness_n_per_m: f64,
    /// End-stop contact damping (*assumed*). [N·s/m]
    pub end_stop_damping_n_s_per_m: f64,
    /// Load spring K of eq. 12; 0 is off. [N/m]
    pub spring_n_per_m: f64,
    /// Inclination of the stroke axis from horizontal; gravity pulls the load towards −x
    /// with m·g·sin(angle). 0 is off. [rad]
    pub gravity_angle_rad: f64,
    /// Pressure-holding configuration: the piston is held at mid-stroke.
    pub blocked: bool,
}

/// Hydraulic oil.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct OilParams {
    /// Effective bulk modulus β_e. [Pa]
    pub bulk_modulus_pa: f64,
    /// Density ρ (*assumed*). [kg/m³]
    pub density_kg_m3: f64,
}

/// Gas-loaded bladder pulsation absorber on port A (eq. 22–26).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AbsorberParams {
    /// Absorber fitted (false: the "without accumulator" reference run).
    pub enabled: bool,
    /// Shell volume = gas volume at precharge V_0. [m³]
    pub shell_volume_m3: f64,
    /// Gas precharge p_0 (gauge). [Pa]
    pub precharge_pa: f64,
    /// Polytropic exponent n. [1]
    pub polytropic_exponent: f64,
    /// Oil inertance of the inlet, ρ·l/A (*assumed*: 12 mm port, 50 mm long). [kg/m⁴]
    pub inlet_inertance_kg_m4: f64,
    /// Linearised inlet and bladder loss resistance (*assumed*: damping ratio ≈ 0.15 at the
    /// nominal precharge and 5 MPa). [Pa·s/m³]
    pub inlet_resistance_pa_s_m3: f64,
}

/// Low-side fill (boost) accumulator with its check valves, and the relief valves.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FillParams {
    /// Fill pressure p_r at the start of a run (*assumed*). [Pa]
    pub pressure_pa: f64,
    /// Gas precharge of the fill accumulator (*assumed*). [Pa]
    pub precharge_pa: f64,
    /// Shell volume of the fill accumulator (*assumed*). [m³]
    pub shell_volume_m3: f64,
    /// Polytropic exponent of its gas. [1]
    pub polytropic_exponent: f64,
    /// Check-valve cracking pressure, fill to port (*assumed*). [Pa]
    pub check_cracking_pa: f64,
    /// Check-valve conductance above cracking (*assumed*). [(m³/s)/Pa]
    pub check_conductance_m3_s_pa: f64,
    /// Relief-valve cracking pressure, each port to the fill side (*assumed*). [Pa]
    pub relief_cracking_pa: f64,
    /// Relief-valve conductance above cracking (*assumed*). [(m³/s)/Pa]
    pub relief_conductance_m3_s_pa: f64,
}

/// Phase-current sensing: shunt amplifiers into 12-bit ADC channels.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CurrentSensorParams {
    /// Scale. [A/LSB]
    pub a_per_lsb: f64,
    /// ADC count at zero current. [LSB]
    pub zero_lsb: f64,
    /// ADC resolution. [bit]
    pub bits: u32,
    /// Offset error per phase a, b, c (effect `current_sensor_offset` on phase a). [A]
    pub offset_a: [f64; 3],
    /// White noise, rms, per sample. [A]
    pub noise_a_rms: f64,
}

/// Pressure transducer on port A into an oversampled 16-bit ADC result.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PressureSensorParams {
    /// Scale. [Pa/LSB]
    pub pa_per_lsb: f64,
    /// ADC count at zero gauge pressure. [LSB]
    pub zero_lsb: f64,
    /// ADC resolution after oversampling. [bit]
    pub bits: u32,
    /// Offset error. [Pa]
    pub offset_pa: f64,
    /// White noise, rms, per sample. [Pa]
    pub noise_pa_rms: f64,
    /// First-order lag time constant; 0 is off. [s]
    pub lag_time_constant_s: f64,
}

/// DC-link voltage divider into a 12-bit ADC channel.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct VoltageSensorParams {
    /// Scale. [V/LSB]
    pub v_per_lsb: f64,
    /// ADC resolution. [bit]
    pub bits: u32,
    /// White noise, rms, per sample. [V]
    pub noise_v_rms: f64,
}

/// Incremental quadrature encoder with index.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct EncoderParams {
    /// Counts per mechanical revolution (4 × lines). [1]
    pub counts_per_rev: u32,
    /// Electrical angle by which the encoder's zero leads the rotor d-axis: the controller
    /// computes θ_e = p_n·θ_count − offset. [rad]
    pub offset_rad: f64,
}

/// All sensors.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SensorParams {
    /// Phase currents.
    pub current: CurrentSensorParams,
    /// Port-A pressure.
    pub pressure: PressureSensorParams,
    /// DC link.
    pub dc_link: VoltageSensorParams,
    /// Shaft encoder.
    pub encoder: EncoderParams,
}

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

/// Standard gravity. [m/s²]
pub const GRAVITY_M_S2: f64 = 9.80665;

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

    /// Checks every parameter once; the plant is only built from a rig that passes.
    pub fn validate(&self) -> Result<(), RigError> {
        let m = &self.motor;
        count("motor.pole_pairs", m.pole_pairs, 64)?;
        within!("motor.r_s_ohm", m.r_s_ohm, 1e-4, 1e3, "Ω")?;
        within!("motor.l_d_h", m.l_d_h, 1e-6, 10.0, "H")?;
        within!("motor.l_q_h", m.l_q_h, 1e-6, 10.0, "H")?;
        within!("motor.psi_f_wb", m.psi_f_wb, 1e-4, 10.0, "Wb")?;
        count("motor.stator_slots", m.stator_slots, 1024)?;
        for c in &m.cogging {
            within!(
                "motor.cogging.amplitude_nm",
                c.amplitude_nm,
                0.0,
                1e3,
                "N·m"
            )?;
            within!("motor.cogging.phase_rad", c.phase_rad, -1e3, 1e3, "rad")?;
            if c.amplitude_nm > 0.0 && c.order == 0 {
                return Err(RigError::new("motor.cogging.order", "must be at least 1"));
            }
        }
        for h in &m.flux_harmonics {
            within!(
                "motor.flux_harmonics.amplitude_wb",
                h.amplitude_wb,
                -10.0,
                10.0,
                "Wb"
            )?;
            within!(
                "motor.flux_harmonics.phase_rad",
                h.phase_rad,
                -1e3,
                1e3,
                "rad"
            )?;
            if h.amplitude_wb != 0.0 && (h.order < 5 || h.order % 6 != 1 && h.order % 6 != 5) {
                return Err(RigError::new(
                    "motor.flux_harmonics.order",
                    "must be 6k±1 (5, 7, 11, 13, …): even and triplen harmonics do not appear in a star-connected winding",
                ));
            }
        }
        let i = &self.inverter;
        within!("inverter.u_dc_v", i.u_dc_v, 1.0, 1e4, "V")?;
        within!(
            "inverter.pwm_frequency_hz",
            i.pwm_frequency_hz,
            1e3,
            1e6,
            "Hz"
        )?;
        within!("inverter.dead_time_s", i.dead_time_s, 0.0, 1e-4, "s")?;
        if i.dead_time_s * i.pwm_frequency_hz >= 0.25 {
            return Err(RigError::new(
                "inverter.dead_time_s",
                "must be under a quarter of the PWM period",
            ));
        }
        within!(
            "inverter.dead_time_current_band_a",
            i.dead_time_current_band_a,
            1e-6,
            1e3,
            "A"
        )?;
        let s = &self.shaft;
        within!(
            "shaft.motor_inertia_kg_m2",
            s.motor_inertia_kg_m2,
            1e-7,
            10.0,
            "kg·m²"
        )?;
        within!(
            "shaft.pump_inertia_kg_m2",
            s.pump_inertia_kg_m2,
            0.0,
            10.0,
            "kg·m²"
        )?;
        within!("shaft.viscous_nm_s", s.viscous_nm_s, 0.0, 1e2, "N·m·s")?;
        within!("shaft.coulomb_nm", s.coulomb_nm, 0.0, 1e3, "N·m")?;
        within!("shaft.static_nm", s.static_nm, 0.0, 1e3, "N·m")?;
        let p = &self.pump;
        within!(
            "pump.displacement_m3_per_rev",
            p.displacement_m3_per_rev,
            1e-8,
            1e-3,
            "m³"
        )?;
        if p.pistons < 3 || p.pistons as usize > crate::pump::MAX_PISTONS {
            return Err(RigError::new("pump.pistons", "must be 3 to 31"));
        }
        within!(
            "pump.ripple_amplitude_ratio",
            p.ripple_amplitude_ratio,
            0.0,
            0.99,
            "(peak-to-peak over mean flow)"
        )?;
        within!(
            "pump.internal_leakage_m3_s_pa",
            p.internal_leakage_m3_s_pa,
            0.0,
            1e-9,
            "(m³/s)/Pa"
        )?;
        within!(
            "pump.external_leakage_m3_s_pa",
            p.external_leakage_m3_s_pa,
            0.0,
            1e-9,
            "(m³/s)/Pa"
        )?;
        within!(
            "pump.extra_leakage_m3_s_pa",
            p.extra_leakage_m3_s_pa,
            0.0,
            1e-9,
            "(m³/s)/Pa"
        )?;
        let c = &self.cylinder;
        within!("cylinder.area_m2", c.area_m2, 1e-6, 1.0, "m²")?;
        within!(
            "cylinder.chamber_a_volume_m3",
            c.chamber_a_volume_m3,
            1e-7,
            1.0,
            "m³"
        )?;
        within!(
            "cylinder.chamber_b_volume_m3",
            c.chamber_b_volume_m3,
            1e-7,
            1.0,
            "m³"
        )?;
        within!(
            "cylinder.internal_leakage_m3_s_pa",
            c.internal_leakage_m3_s_pa,
            0.0,
            1e-9,
            "(m³/s)/Pa"
        )?;
        within!(
            "cylinder.viscous_n_s_per_m",
            c.viscous_n_s_per_m,
            0.0,
            1e8,
            "N·s/m"
        )?;
        within!(
            "cylinder.static_friction_n",
            c.static_friction_n,
            0.0,
            1e7,
            "N"
        )?;
        within!(
            "cylinder.coulomb_friction_n",
            c.coulomb_friction_n,
            0.0,
            1e7,
            "N"
        )?;
        within!("cylinder.mass_kg", c.mass_kg, 1e-3, 1e6, "kg")?;
        within!("cylinder.half_stroke_m", c.half_stroke_m, 1e-4, 10.0, "m")?;
        within!(
            "cylinder.end_stop_stiffness_n_per_m",
            c.end_stop_stiffness_n_per_m,
            1e3,
            1e12,
            "N/m"
        )?;
        within!(
            "cylinder.end_stop_damping_n_s_per_m",
            c.end_stop_damping_n_s_per_m,
            0.0,
            1e9,
            "N·s/m"
        )?;
        within!("cylinder.spring_n_per_m", c.spring_n_per_m, 0.0, 1e9, "N/m")?;
        within!(
            "cylinder.gravity_angle_rad",
            c.gravity_angle_rad,
            -1e3,
            1e3,
            "rad"
        )?;
        // The swept volume must leave oil in each chamber at the end stops.
        let swept = c.area_m2 * c.half_stroke_m;
        if swept >= c.chamber_a_volume_m3 {
            return Err(RigError::new(
                "cylinder.chamber_a_volume_m3",
                "must exceed area × half stroke (the chamber would vanish at the end stop)",
            ));
        }
        if swept >= c.chamber_b_volume_m3 {
            return Err(RigError::new(
                "cylinder.chamber_b_volume_m3",
                "must exceed area × half stroke (the chamber would vanish at the end stop)",
            ));
        }
        within!(
            "oil.bulk_modulus_pa",
            self.oil.bulk_modulus_pa,
            1e6,
            1e11,
            "Pa"
        )?;
        within!(
            "oil.density_kg_m3",
            self.oil.density_kg_m3,
            1e2,
            1e4,
            "kg/m³"
        )?;
        let a = &self.absorber;
        within!(
            "absorber.shell_volume_m3",
            a.shell_volume_m3,
            1e-6,
            1.0,
            "m³"
        )?;
        within!("absorber.precharge_pa", a.precharge_pa, 1e3, 1e8, "Pa")?;
        polytropic("absorber.polytropic_exponent", a.polytropic_exponent)?;
        within!(
            "absorber.inlet_inertance_kg_m4",
            a.inlet_inertance_kg_m4,
            1.0,
            1e12,
            "kg/m⁴"
        )?;
        within!(
            "absorber.inlet_resistance_pa_s_m3",
            a.inlet_resistance_pa_s_m3,
            0.0,
            1e13,
            "Pa·s/m³"
        )?;
        let f = &self.fill;
        within!("fill.pressure_pa", f.pressure_pa, 1e3, 1e8, "Pa")?;
        within!("fill.precharge_pa", f.precharge_pa, 1e3, 1e8, "Pa")?;
        if f.precharge_pa >= f.pressure_pa {
            return Err(RigError::new(
                "fill.precharge_pa",
                "must be below fill.pressure_pa (the fill accumulator must hold oil)",
            ));
        }
        within!("fill.shell_volume_m3", f.shell_volume_m3, 1e-6, 1.0, "m³")?;
        polytropic("fill.polytropic_exponent", f.polytropic_exponent)?;
        within!(
            "fill.check_cracking_pa",
            f.check_cracking_pa,
            0.0,
            1e7,
            "Pa"
        )?;
        within!(
            "fill.check_conductance_m3_s_pa",
            f.check_conductance_m3_s_pa,
            1e-15,
            1e-3,
            "(m³/s)/Pa"
        )?;
        within!(
            "fill.relief_cracking_pa",
            f.relief_cracking_pa,
            1e4,
            2e8,
            "Pa"
        )?;
        within!(
            "fill.relief_conductance_m3_s_pa",
            f.relief_conductance_m3_s_pa,
            1e-15,
            1e-3,
            "(m³/s)/Pa"
        )?;
        let cs = &self.sensors.current;
        within!("sensors.current.a_per_lsb", cs.a_per_lsb, 1e-6, 10.0, "A")?;
        adc_bits("sensors.current.bits", cs.bits)?;
        in_adc_range("sensors.current.zero_lsb", cs.zero_lsb, cs.bits)?;
        for o in &cs.offset_a {
            within!("sensors.current.offset_a", *o, -1e3, 1e3, "A")?;
        }
        within!("sensors.current.noise_a_rms", cs.noise_a_rms, 0.0, 1e2, "A")?;
        let ps = &self.sensors.pressure;
        within!(
            "sensors.pressure.pa_per_lsb",
            ps.pa_per_lsb,
            1e-3,
            1e6,
            "Pa"
        )?;
        adc_bits("sensors.pressure.bits", ps.bits)?;
        in_adc_range("sensors.pressure.zero_lsb", ps.zero_lsb, ps.bits)?;
        within!("sensors.pressure.offset_pa", ps.offset_pa, -1e8, 1e8, "Pa")?;
        within!(
            "sensors.pressure.noise_pa_rms",
            ps.noise_pa_rms,
            0.0,
            1e8,
            "Pa"
        )?;
        within!(
            "sensors.pressure.lag_time_constant_s",
            ps.lag_time_constant_s,
            0.0,
            10.0,
            "s"
        )?;
        let vs = &self.sensors.dc_link;
        within!("sensors.dc_link.v_per_lsb", vs.v_per_lsb, 1e-4, 10.0, "V")?;
        adc_bits("sensors.dc_link.bits", vs.bits)?;
        within!("sensors.dc_link.noise_v_rms", vs.noise_v_rms, 0.0, 1e3, "V")?;
        if !(4..=1 << 24).contains(&self.sensors.encoder.counts_per_rev) {
            return Err(RigError::new(
                "sensors.encoder.counts_per_rev",
                "must lie between 4 and 16777216",
            ));
        }
        within!(
            "sensors.encoder.offset_rad",
            self.sensors.encoder.offset_rad,
            -1e3,
            1e3,
            "rad"
        )?;
        within!(
            "integration.max_step_s",
            self.integration.max_step_s,
            1e-6,
            1e-3,
            "s"
        )?;
        Ok(())
    }
}

/// A rig parameter that failed validation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RigError {
    /// The parameter's path in the rig file, e.g. `pump.pistons`.
    pub parameter: &'static str,
    /// What is wrong with it.
    pub reason: &'static str,
}

impl RigError {
    /// A new error for `parameter`.
    pub const fn new(parameter: &'static str, reason: &'static str) -> RigError {
        RigError { parameter, reason }
    }
}

impl core::fmt::Display for RigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "rig parameter `{}` {}", self.parameter, self.reason)
    }
}

#[cfg(feature = "std")]
impl std::error::Error for RigError {}

/// Checks that `$v` is finite and within `[$lo, $hi]` (SI units `$unit`), the reason naming
/// the range: wide enough for any actuator of this kind, narrow enough that the model's
/// integration stays finite and its cost bounded.
macro_rules! within {
    ($name:expr, $v:expr, $lo:literal, $hi:literal, $unit:literal) => {
        in_range(
            $name,
            $v,
            $lo,
            $hi,
            concat!(
                "must lie between ",
                stringify!($lo),
                " and ",
                stringify!($hi),
                " ",
                $unit
            ),
        )
    };
}
use within;

fn in_range(
    name: &'static str,
    v: f64,
    lo: f64,
    hi: f64,
    reason: &'static str,
) -> Result<(), RigError> {
    finite(name, v)?;
    if (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(RigError::new(name, reason))
    }
}

fn count(name: &'static str, v: u32, most: u32) -> Result<(), RigError> {
    positive_int(name, v)?;
    if v <= most {
        Ok(())
    } else {
        Err(RigError::new(name, "is beyond any motor of this kind"))
    }
}

fn finite(name: &'static str, v: f64) -> Result<(), RigError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(RigError::new(name, "must be a finite number"))
    }
}

fn positive_int(name: &'static str, v: u32) -> Result<(), RigError> {
    if v > 0 {
        Ok(())
    } else {
        Err(RigError::new(name, "must be at least 1"))
    }
}

fn polytropic(name: &'static str, v: f64) -> Result<(), RigError> {
    finite(name, v)?;
    if (1.0..=1.67).contains(&v) {
        Ok(())
    } else {
        Err(RigError::new(
            name,
            "must lie between 1 (isothermal) and 1.67 (adiabatic monatomic)",
        ))
    }
}

fn adc_bits(name: &'static str, bits: u32) -> Result<(), RigError> {
    if (8..=16).contains(&bits) {
        Ok(())
    } else {
        Err(RigError::new(name, "must be 8 to 16 bits"))
    }
}

fn in_adc_range(name: &'static str, v: f64, bits: u32) -> Result<(), RigError> {
    finite(name, v)?;
    let full = ((1u32 << bits) - 1) as f64;
    if (0.0..=full).contains(&v) {
        Ok(())
    } else {
        Err(RigError::new(name, "must lie within the ADC's range"))
    }
}

fn gcd(mut a: u32, mut b: u32) -> u32 {
    while b != 0 {
        let t = a % b;
        a = b;
        b = t;
    }
    a
}

/// Least common multiple (0 if either is 0).
pub fn lcm(a: u32, b: u32) -> u32 {
    if a == 0 || b == 0 {
        0
    } else {
        a / gcd(a, b) * b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nominal_rig_is_valid_and_matches_the_contract() {
        let r = Rig::nominal();
        assert_eq!(r.validate(), Ok(()));
        // nominal-rig.md: K_t = 1.5·p_n·ψ_f = 1.0962 N·m/A; J = 8.0e-4 kg·m²; N_cog = 72.
        assert!((r.motor.torque_constant_nm_per_a() - 1.0962).abs() < 1e-4);
        assert!((r.shaft.inertia_kg_m2() - 8.0e-4).abs() < 1e-9);
        assert_eq!(r.motor.cogging_fundamental_order(), 72);
        // U_dc/√3 is Table 1's 161.6 V current-PI limit.
        assert!((r.inverter.u_dc_v / 3f64.sqrt() - 161.6).abs() < 0.1);
    }

    #[test]
    fn invalid_parameters_are_named() {
        let mut r = Rig::nominal();
        r.cylinder.chamber_a_volume_m3 = -1e-4;
        assert_eq!(
            r.validate().unwrap_err().parameter,
            "cylinder.chamber_a_volume_m3"
        );
        let mut r = Rig::nominal();
        r.pump.pistons = 0;
        assert_eq!(r.validate().unwrap_err().parameter, "pump.pistons");
        let mut r = Rig::nominal();
        r.oil.bulk_modulus_pa = f64::NAN;
        let e = r.validate().unwrap_err();
        assert_eq!(e.parameter, "oil.bulk_modulus_pa");
        assert!(e.reason.contains("finite"));
        let mut r = Rig::nominal();
        r.motor.flux_harmonics[0].amplitude_wb = 0.01;
        r.motor.flux_harmonics[0].order = 3;
        assert_eq!(
            r.validate().unwrap_err().parameter,
            "motor.flux_harmonics.order"
        );
        let mut r = Rig::nominal();
        r.absorber.precharge_pa = f64::INFINITY;
        assert_eq!(r.validate().unwrap_err().parameter, "absorber.precharge_pa");
    }

    #[test]
    fn values_beyond_any_actuator_are_named() {
        // A step far below a microsecond makes a simulated second cost millions of steps.
        for step in [1e-30, 1e-9] {
            let mut r = Rig::nominal();
            r.integration.max_step_s = step;
            let e = r.validate().unwrap_err();
            assert_eq!(e.parameter, "integration.max_step_s");
            assert!(e.reason.contains("1e-6"), "{}", e.reason);
        }
        let mut r = Rig::nominal();
        r.absorber.precharge_pa = 1e30;
        assert_eq!(r.validate().unwrap_err().parameter, "absorber.precharge_pa");
        let mut r = Rig::nominal();
        r.cylinder.mass_kg = 1e30;
        assert_eq!(r.validate().unwrap_err().parameter, "cylinder.mass_kg");
        let mut r = Rig::nominal();
        r.motor.cogging[0].phase_rad = -1e30;
        assert_eq!(
            r.validate().unwrap_err().parameter,
            "motor.cogging.phase_rad"
        );
    }
}
