//! The controller's configuration for a rig: what the drive engineer would enter for this
//! actuator — the sensor scalings, the motor's nameplate and the hydraulics the pressure
//! loop's schedule is computed from — on top of the control core's nominal design (Table 1
//! gains, rates, limits). Effects switched on in a simulated plant are *not* seen here: the
//! controller is configured from the rig file the engineer believes in.

use firmware::config::Config;
use plant_model::Rig;

/// The controller configuration for `rig` (not validated here; [`crate::ClosedLoop::new`]
/// validates it).
pub fn controller_config(rig: &Rig) -> Config {
    let mut c = Config::nominal();
    c.rates.pwm_hz = rig.inverter.pwm_frequency_hz as f32;
    let s = &rig.sensors;
    c.sensors.current_a_per_lsb = s.current.a_per_lsb as f32;
    c.sensors.current_zero_lsb = s.current.zero_lsb as f32;
    c.sensors.dc_link_v_per_lsb = s.dc_link.v_per_lsb as f32;
    c.sensors.pressure_pa_per_lsb = s.pressure.pa_per_lsb as f32;
    c.sensors.pressure_zero_lsb = s.pressure.zero_lsb as f32;
    c.sensors.encoder_counts_per_rev = s.encoder.counts_per_rev;
    c.sensors.encoder_offset_rad = s.encoder.offset_rad as f32;
    // The simulated encoder reads ⌊θ/2π·N⌋ from the start: its count 0 is the index.
    c.sensors.encoder_referenced_at_start = true;
    // The simulated current sensors' offset is an effect under study: the controller keeps
    // the configured zero until a Calibrating run measures it.
    c.calibration.offsets_at_boot = false;
    // The plant's inverter has ideal switches: no bootstrap supply to charge.
    c.calibration.bootstrap_precharge_s = 0.0;
    let m = &rig.motor;
    c.motor.pole_pairs = m.pole_pairs;
    c.motor.stator_resistance_ohm = m.r_s_ohm as f32;
    c.motor.d_inductance_h = m.l_d_h as f32;
    c.motor.q_inductance_h = m.l_q_h as f32;
    c.motor.flux_linkage_wb = m.psi_f_wb as f32;
    c.motor.dc_link_nominal_v = rig.inverter.u_dc_v as f32;
    let h = &mut c.hydraulics;
    h.pump_displacement_m3_per_rev = rig.pump.displacement_m3_per_rev as f32;
    h.oil_volume_m3 = rig.cylinder.chamber_a_volume_m3 as f32;
    h.bulk_modulus_pa = rig.oil.bulk_modulus_pa as f32;
    h.absorber_volume_m3 = if rig.absorber.enabled {
        rig.absorber.shell_volume_m3 as f32
    } else {
        0.0
    };
    h.absorber_precharge_pa = rig.absorber.precharge_pa as f32;
    h.polytropic_exponent = rig.absorber.polytropic_exponent as f32;
    h.leakage_m3_per_s_pa = (rig.pump.internal_leakage_m3_s_pa
        + rig.pump.external_leakage_m3_s_pa
        + rig.cylinder.internal_leakage_m3_s_pa) as f32;
    c
}
