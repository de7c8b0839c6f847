//! The configuration's check, done once before a controller is built ([`Config::validate`]):
//! every field's range and the rules between fields (whole loop-rate ratios, the shunt
//! sampling window, limits ordered against each other), then the commissioning's and the
//! torque feed-forward's own rules. The control step never re-checks.

use super::error::ConfigError;
use super::sections::Config;

fn err(field: &'static str, problem: &'static str) -> ConfigError {
    ConfigError { field, problem }
}

fn positive(field: &'static str, v: f32) -> Result<(), ConfigError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(err(field, "must be finite and > 0"))
    }
}

fn non_negative(field: &'static str, v: f32) -> Result<(), ConfigError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(err(field, "must be finite and >= 0"))
    }
}

/// Ratio `fast / slow` as a whole number ≥ 1, if it is one (within 1e-4 relative).
pub fn whole_ratio(fast: f32, slow: f32) -> Option<u32> {
    if !(fast.is_finite() && slow.is_finite() && fast > 0.0 && slow > 0.0 && slow <= fast) {
        return None;
    }
    let r = fast / slow;
    let n = (r + 0.5) as u32;
    if n >= 1 && (r - n as f32).abs() <= 1e-4 * r {
        Some(n)
    } else {
        None
    }
}

impl Config {
    /// Checks every field, part by part in a fixed order; the error names the first
    /// offending one.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.validate_rates()?;
        self.validate_sensors()?;
        self.validate_motor()?;
        self.validate_current()?;
        self.validate_speed()?;
        self.validate_pressure()?;
        self.validate_hydraulics()?;
        self.validate_limits()?;
        self.validate_calibration()?;
        self.commissioning.validate(
            self.limits.over_current_a,
            self.current.voltage_limit_v,
            self.speed.speed_limit_rad_s,
            self.rates.pwm_hz,
        )?;
        self.compensation.validate()
    }

    /// The loop rates: PWM range, whole loop-rate ratios, pressure-loop margin, decimation.
    fn validate_rates(&self) -> Result<(), ConfigError> {
        let r = &self.rates;
        if !(r.pwm_hz.is_finite() && (1_000.0..=100_000.0).contains(&r.pwm_hz)) {
            return Err(err("rates.pwm_hz", "must be within 1 kHz..=100 kHz"));
        }
        positive("rates.speed_loop_hz", r.speed_loop_hz)?;
        if whole_ratio(r.pwm_hz, r.speed_loop_hz).is_none() {
            return Err(err(
                "rates.speed_loop_hz",
                "must divide rates.pwm_hz a whole number of times",
            ));
        }
        positive("rates.pressure_loop_hz", r.pressure_loop_hz)?;
        if whole_ratio(r.pwm_hz, r.pressure_loop_hz).is_none() {
            return Err(err(
                "rates.pressure_loop_hz",
                "must divide rates.pwm_hz a whole number of times",
            ));
        }
        if r.pressure_loop_hz < 10.0 * self.pressure.bandwidth_rad_s / core::f32::consts::TAU {
            return Err(err(
                "rates.pressure_loop_hz",
                "must be at least 10x the pressure-loop bandwidth",
            ));
        }

        if !(1..=10_000).contains(&r.telemetry_decimation) {
            return Err(err(
                "rates.telemetry_decimation",
                "must be within 1..=10000",
            ));
        }
        Ok(())
    }

    /// The sensor scalings: scales and zeros, the shunt window, pressure wiring, encoder.
    fn validate_sensors(&self) -> Result<(), ConfigError> {
        let r = &self.rates;
        let s = &self.sensors;
        positive("sensors.current_a_per_lsb", s.current_a_per_lsb)?;
        if !(s.current_zero_lsb.is_finite() && (0.0..=4095.0).contains(&s.current_zero_lsb)) {
            return Err(err("sensors.current_zero_lsb", "must be within 0..=4095"));
        }
        non_negative("sensors.shunt_settling_s", s.shunt_settling_s)?;
        if crate::shunt::max_sampled_duty(s.shunt_settling_s, r.pwm_hz) < 0.5 {
            return Err(err(
                "sensors.shunt_settling_s",
                "must be at most a quarter of the PWM period",
            ));
        }
        positive("sensors.dc_link_v_per_lsb", s.dc_link_v_per_lsb)?;
        positive("sensors.pressure_pa_per_lsb", s.pressure_pa_per_lsb)?;
        if !(s.pressure_zero_lsb.is_finite() && (0.0..=65535.0).contains(&s.pressure_zero_lsb)) {
            return Err(err("sensors.pressure_zero_lsb", "must be within 0..=65535"));
        }
        if s.pressure_open_wire_lsb >= s.pressure_short_lsb {
            return Err(err(
                "sensors.pressure_open_wire_lsb",
                "must be below sensors.pressure_short_lsb",
            ));
        }
        if !(4..=(1 << 24)).contains(&s.encoder_counts_per_rev) {
            return Err(err(
                "sensors.encoder_counts_per_rev",
                "must be within 4..=16777216",
            ));
        }
        if !s.encoder_offset_rad.is_finite() {
            return Err(err("sensors.encoder_offset_rad", "must be finite"));
        }
        Ok(())
    }

    /// The motor's nameplate constants.
    fn validate_motor(&self) -> Result<(), ConfigError> {
        let m = &self.motor;
        if !(1..=64).contains(&m.pole_pairs) {
            return Err(err("motor.pole_pairs", "must be within 1..=64"));
        }
        positive("motor.stator_resistance_ohm", m.stator_resistance_ohm)?;
        positive("motor.d_inductance_h", m.d_inductance_h)?;
        positive("motor.q_inductance_h", m.q_inductance_h)?;
        non_negative("motor.flux_linkage_wb", m.flux_linkage_wb)?;
        positive("motor.dc_link_nominal_v", m.dc_link_nominal_v)?;
        Ok(())
    }

    /// The current loop's gains and voltage limit.
    fn validate_current(&self) -> Result<(), ConfigError> {
        let c = &self.current;
        positive("current.kp_d", c.kp_d)?;
        non_negative("current.ki_d", c.ki_d)?;
        positive("current.kp_q", c.kp_q)?;
        non_negative("current.ki_q", c.ki_q)?;
        positive("current.voltage_limit_v", c.voltage_limit_v)?;
        Ok(())
    }

    /// The speed loop's gains, limits and speed observer.
    fn validate_speed(&self) -> Result<(), ConfigError> {
        let r = &self.rates;
        let sp = &self.speed;
        positive("speed.kp", sp.kp)?;
        non_negative("speed.ki", sp.ki)?;
        non_negative("speed.active_damping", sp.active_damping)?;
        positive("speed.iq_limit_a", sp.iq_limit_a)?;
        positive("speed.speed_limit_rad_s", sp.speed_limit_rad_s)?;
        positive(
            "speed.observer_bandwidth_rad_s",
            sp.observer_bandwidth_rad_s,
        )?;
        if sp.observer_bandwidth_rad_s > 0.25 * r.pwm_hz {
            return Err(err(
                "speed.observer_bandwidth_rad_s",
                "must be at most 0.25 * rates.pwm_hz (omega_n * T <= 0.25)",
            ));
        }
        Ok(())
    }

    /// The pressure loop's bandwidth, filter, ramp and setpoint range.
    fn validate_pressure(&self) -> Result<(), ConfigError> {
        let p = &self.pressure;
        positive("pressure.bandwidth_rad_s", p.bandwidth_rad_s)?;
        if !(p.integral_corner_ratio.is_finite() && (0.0..=1.0).contains(&p.integral_corner_ratio))
        {
            return Err(err(
                "pressure.integral_corner_ratio",
                "must be within 0..=1",
            ));
        }
        positive("pressure.feedback_filter_rad_s", p.feedback_filter_rad_s)?;
        if p.feedback_filter_rad_s < 2.0 * p.bandwidth_rad_s {
            return Err(err(
                "pressure.feedback_filter_rad_s",
                "must be at least 2x pressure.bandwidth_rad_s",
            ));
        }
        positive("pressure.ramp_pa_per_s", p.ramp_pa_per_s)?;
        non_negative("pressure.setpoint_min_pa", p.setpoint_min_pa)?;
        positive("pressure.setpoint_max_pa", p.setpoint_max_pa)?;
        if p.setpoint_min_pa >= p.setpoint_max_pa {
            return Err(err(
                "pressure.setpoint_min_pa",
                "must be below pressure.setpoint_max_pa",
            ));
        }
        Ok(())
    }

    /// The hydraulics' constants.
    fn validate_hydraulics(&self) -> Result<(), ConfigError> {
        let h = &self.hydraulics;
        positive(
            "hydraulics.pump_displacement_m3_per_rev",
            h.pump_displacement_m3_per_rev,
        )?;
        positive("hydraulics.oil_volume_m3", h.oil_volume_m3)?;
        positive("hydraulics.bulk_modulus_pa", h.bulk_modulus_pa)?;
        non_negative("hydraulics.absorber_volume_m3", h.absorber_volume_m3)?;
        non_negative("hydraulics.absorber_precharge_pa", h.absorber_precharge_pa)?;
        if !(h.polytropic_exponent.is_finite() && (1.0..=2.0).contains(&h.polytropic_exponent)) {
            return Err(err(
                "hydraulics.polytropic_exponent",
                "must be within 1..=2",
            ));
        }
        non_negative("hydraulics.leakage_m3_per_s_pa", h.leakage_m3_per_s_pa)?;
        Ok(())
    }

    /// The fault limits, each against the range it must exceed or fit in.
    fn validate_limits(&self) -> Result<(), ConfigError> {
        let r = &self.rates;
        let s = &self.sensors;
        let sp = &self.speed;
        let p = &self.pressure;
        let l = &self.limits;
        positive("limits.over_current_a", l.over_current_a)?;
        if l.over_current_a <= sp.iq_limit_a {
            return Err(err("limits.over_current_a", "must exceed speed.iq_limit_a"));
        }
        positive("limits.hardware_over_current_a", l.hardware_over_current_a)?;
        if l.hardware_over_current_a <= l.over_current_a {
            return Err(err(
                "limits.hardware_over_current_a",
                "must exceed limits.over_current_a",
            ));
        }
        if l.hardware_over_current_a / s.current_a_per_lsb >= s.current_zero_lsb {
            return Err(err(
                "limits.hardware_over_current_a",
                "must be within the current sensor's range below its zero",
            ));
        }
        positive("limits.under_voltage_v", l.under_voltage_v)?;
        positive("limits.over_voltage_v", l.over_voltage_v)?;
        if l.under_voltage_v >= l.over_voltage_v {
            return Err(err(
                "limits.under_voltage_v",
                "must be below limits.over_voltage_v",
            ));
        }
        positive("limits.over_pressure_pa", l.over_pressure_pa)?;
        if l.over_pressure_pa <= p.setpoint_max_pa {
            return Err(err(
                "limits.over_pressure_pa",
                "must exceed pressure.setpoint_max_pa",
            ));
        }
        positive("limits.over_speed_rad_s", l.over_speed_rad_s)?;
        if l.over_speed_rad_s <= sp.speed_limit_rad_s {
            return Err(err(
                "limits.over_speed_rad_s",
                "must exceed speed.speed_limit_rad_s",
            ));
        }
        positive(
            "limits.encoder_plausible_speed_rad_s",
            l.encoder_plausible_speed_rad_s,
        )?;
        if l.encoder_plausible_speed_rad_s <= l.over_speed_rad_s {
            return Err(err(
                "limits.encoder_plausible_speed_rad_s",
                "must exceed limits.over_speed_rad_s",
            ));
        }
        // Half a revolution per sample is the largest step the wrapped difference can tell
        // from its opposite.
        let max_step_rev = l.encoder_plausible_speed_rad_s / core::f32::consts::TAU / r.pwm_hz;
        if max_step_rev >= 0.25 {
            return Err(err(
                "limits.encoder_plausible_speed_rad_s",
                "must be below a quarter revolution per PWM period",
            ));
        }
        positive("limits.command_timeout_s", l.command_timeout_s)?;
        if l.command_timeout_s > 3600.0 {
            return Err(err("limits.command_timeout_s", "must be at most 3600 s"));
        }
        positive("limits.current_sum_a", l.current_sum_a)?;
        positive("limits.stall_time_s", l.stall_time_s)?;
        if l.stall_time_s > 3600.0 {
            return Err(err("limits.stall_time_s", "must be at most 3600 s"));
        }
        Ok(())
    }

    /// The calibration's times and currents.
    fn validate_calibration(&self) -> Result<(), ConfigError> {
        let r = &self.rates;
        let l = &self.limits;
        let k = &self.calibration;
        positive("calibration.offset_time_s", k.offset_time_s)?;
        if k.offset_time_s * r.pwm_hz < 16.0 || k.offset_time_s > 10.0 {
            return Err(err(
                "calibration.offset_time_s",
                "must cover at least 16 samples and at most 10 s",
            ));
        }
        positive("calibration.offset_max_lsb", k.offset_max_lsb)?;
        positive("calibration.alignment_current_a", k.alignment_current_a)?;
        if k.alignment_current_a >= l.over_current_a {
            return Err(err(
                "calibration.alignment_current_a",
                "must be below limits.over_current_a",
            ));
        }
        non_negative("calibration.bootstrap_precharge_s", k.bootstrap_precharge_s)?;
        if k.bootstrap_precharge_s > 10e-3 {
            return Err(err(
                "calibration.bootstrap_precharge_s",
                "must be at most 10 ms",
            ));
        }
        positive("calibration.alignment_time_s", k.alignment_time_s)?;
        if k.alignment_time_s > 60.0 {
            return Err(err("calibration.alignment_time_s", "must be at most 60 s"));
        }
        Ok(())
    }
}
