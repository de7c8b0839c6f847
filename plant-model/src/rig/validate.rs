//! The rig's validation, once before a plant is built ([`Rig::validate`]): each parameter
//! finite and within a range wide enough for any actuator of this kind and narrow enough that
//! the model's integration stays finite and its cost bounded, the failure ([`RigError`])
//! naming the parameter's path in the rig file.
//!
//! [`Rig::validate`] checks the parts in the rig file's order, one private function each
//! (motor, inverter, shaft, pump, cylinder and its chambers, oil, absorber, fill accumulator,
//! each sensor, integration), and returns the first failure.

use super::hydraulics::{AbsorberParams, CylinderParams, FillParams, OilParams, PumpParams};
use super::motor::{InverterParams, MotorParams, ShaftParams};
use super::nominal::{IntegrationParams, Rig};
use super::sensors::{
    CurrentSensorParams, EncoderParams, PressureSensorParams, VoltageSensorParams,
};

impl Rig {
    /// Checks every parameter once, part by part in the rig file's order; the plant is only
    /// built from a rig that passes.
    pub fn validate(&self) -> Result<(), RigError> {
        check_motor(&self.motor)?;
        check_inverter(&self.inverter)?;
        check_shaft(&self.shaft)?;
        check_pump(&self.pump)?;
        check_cylinder(&self.cylinder)?;
        check_cylinder_chambers(&self.cylinder)?;
        check_oil(&self.oil)?;
        check_absorber(&self.absorber)?;
        check_fill(&self.fill)?;
        check_current_sensor(&self.sensors.current)?;
        check_pressure_sensor(&self.sensors.pressure)?;
        check_dc_link_sensor(&self.sensors.dc_link)?;
        check_encoder(&self.sensors.encoder)?;
        check_integration(&self.integration)?;
        Ok(())
    }
}

/// The motor: pole pairs, resistance, inductances, flux linkage, slots, cogging, flux harmonics.
fn check_motor(m: &MotorParams) -> Result<(), RigError> {
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
    Ok(())
}

/// The inverter: DC-link voltage, PWM frequency, dead time (under a quarter period), its band.
fn check_inverter(i: &InverterParams) -> Result<(), RigError> {
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
    Ok(())
}

/// The shaft: motor and pump inertia, viscous, Coulomb and static friction.
fn check_shaft(s: &ShaftParams) -> Result<(), RigError> {
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
    Ok(())
}

/// The pump: displacement, piston count, flow ripple and leakages.
fn check_pump(p: &PumpParams) -> Result<(), RigError> {
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
    Ok(())
}

/// The cylinder and load: area, chambers, leakage, friction, mass, stroke, end stops, spring, tilt.
fn check_cylinder(c: &CylinderParams) -> Result<(), RigError> {
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
    Ok(())
}

/// Cross-check: the swept volume (area × half stroke) leaves oil in each chamber at the end stops.
fn check_cylinder_chambers(c: &CylinderParams) -> Result<(), RigError> {
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
    Ok(())
}

/// The oil: bulk modulus and density.
fn check_oil(o: &OilParams) -> Result<(), RigError> {
    within!("oil.bulk_modulus_pa", o.bulk_modulus_pa, 1e6, 1e11, "Pa")?;
    within!("oil.density_kg_m3", o.density_kg_m3, 1e2, 1e4, "kg/m³")?;
    Ok(())
}

/// The pulsation absorber: shell, precharge, polytropic exponent, inlet inertance and resistance.
fn check_absorber(a: &AbsorberParams) -> Result<(), RigError> {
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
    Ok(())
}

/// The fill accumulator (pressure above precharge, shell, polytropic exponent), check and relief.
fn check_fill(f: &FillParams) -> Result<(), RigError> {
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
    Ok(())
}

/// The phase-current sensors: scale, ADC bits and zero, offsets, noise.
fn check_current_sensor(cs: &CurrentSensorParams) -> Result<(), RigError> {
    within!("sensors.current.a_per_lsb", cs.a_per_lsb, 1e-6, 10.0, "A")?;
    adc_bits("sensors.current.bits", cs.bits)?;
    in_adc_range("sensors.current.zero_lsb", cs.zero_lsb, cs.bits)?;
    for o in &cs.offset_a {
        within!("sensors.current.offset_a", *o, -1e3, 1e3, "A")?;
    }
    within!("sensors.current.noise_a_rms", cs.noise_a_rms, 0.0, 1e2, "A")?;
    Ok(())
}

/// The pressure sensor: scale, ADC bits and zero, offset, noise, lag.
fn check_pressure_sensor(ps: &PressureSensorParams) -> Result<(), RigError> {
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
    Ok(())
}

/// The DC-link voltage sensor: scale, ADC bits, noise.
fn check_dc_link_sensor(vs: &VoltageSensorParams) -> Result<(), RigError> {
    within!("sensors.dc_link.v_per_lsb", vs.v_per_lsb, 1e-4, 10.0, "V")?;
    adc_bits("sensors.dc_link.bits", vs.bits)?;
    within!("sensors.dc_link.noise_v_rms", vs.noise_v_rms, 0.0, 1e3, "V")?;
    Ok(())
}

/// The encoder: counts per revolution and offset.
fn check_encoder(e: &EncoderParams) -> Result<(), RigError> {
    if !(4..=1 << 24).contains(&e.counts_per_rev) {
        return Err(RigError::new(
            "sensors.encoder.counts_per_rev",
            "must lie between 4 and 16777216",
        ));
    }
    within!("sensors.encoder.offset_rad", e.offset_rad, -1e3, 1e3, "rad")?;
    Ok(())
}

/// The integration: the largest RK4 step.
fn check_integration(n: &IntegrationParams) -> Result<(), RigError> {
    within!("integration.max_step_s", n.max_step_s, 1e-6, 1e-3, "s")?;
    Ok(())
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
