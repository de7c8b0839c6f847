//! The rules of the configuration check that tie a live parameter to another field
//! ("the feedback filter must be at least twice the pressure bandwidth", "the over-current
//! trip must exceed the q-current limit", …), with the validator's field names and
//! messages, so a refused parameter names the conflicting field.

use crate::config::error::ConfigError;
use crate::config::sections::Config;

/// The rules of [`Config::validate`] that relate a table parameter to another field, on
/// a configuration that was valid before its table parameters were changed within their
/// bounds. Same field names and messages as the validator.
pub fn cross_check(cfg: &Config) -> Result<(), ConfigError> {
    let err = |field, problem| Err(ConfigError { field, problem });
    let (r, sp, p, l) = (&cfg.rates, &cfg.speed, &cfg.pressure, &cfg.limits);
    if r.pressure_loop_hz < 10.0 * p.bandwidth_rad_s / core::f32::consts::TAU {
        return err(
            "rates.pressure_loop_hz",
            "must be at least 10x the pressure-loop bandwidth",
        );
    }
    if sp.observer_bandwidth_rad_s > 0.25 * r.pwm_hz {
        return err(
            "speed.observer_bandwidth_rad_s",
            "must be at most 0.25 * rates.pwm_hz (omega_n * T <= 0.25)",
        );
    }
    if p.feedback_filter_rad_s < 2.0 * p.bandwidth_rad_s {
        return err(
            "pressure.feedback_filter_rad_s",
            "must be at least 2x pressure.bandwidth_rad_s",
        );
    }
    if p.setpoint_min_pa >= p.setpoint_max_pa {
        return err(
            "pressure.setpoint_min_pa",
            "must be below pressure.setpoint_max_pa",
        );
    }
    if l.over_current_a <= sp.iq_limit_a {
        return err("limits.over_current_a", "must exceed speed.iq_limit_a");
    }
    if l.over_pressure_pa <= p.setpoint_max_pa {
        return err(
            "limits.over_pressure_pa",
            "must exceed pressure.setpoint_max_pa",
        );
    }
    if l.over_speed_rad_s <= sp.speed_limit_rad_s {
        return err(
            "limits.over_speed_rad_s",
            "must exceed speed.speed_limit_rad_s",
        );
    }
    let k = &cfg.commissioning;
    if k.pulse_voltage_v > 0.5 * cfg.current.voltage_limit_v {
        return err(
            "commissioning.pulse_voltage_v",
            "must be > 0 and at most 0.5 * current.voltage_limit_v",
        );
    }
    if k.spin_speed_rad_s > sp.speed_limit_rad_s {
        return err(
            "commissioning.spin_speed_rad_s",
            "must be > 0 and at most speed.speed_limit_rad_s",
        );
    }
    let c = &cfg.compensation;
    if (1..crate::compensation::flow::MIN_PISTONS).contains(&c.flow_pistons) {
        return err(
            "compensation.flow_pistons",
            "must be 0 (off) or within 3..=31",
        );
    }
    if c.scale * c.flow_ratio > c.max_flow_ratio {
        return err(
            "compensation.flow_ratio",
            "scale * flow_ratio must be at most compensation.max_flow_ratio",
        );
    }
    Ok(())
}
