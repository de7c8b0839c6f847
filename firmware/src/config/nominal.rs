//! The nominal rig's configuration (`contracts/nominal-rig.md`) with the Table 1 gains
//! of the paper (Section 3.1), the bring-up configuration for a first power-up on a
//! current-limited supply, and the same configuration at another PWM rate.

use super::sections::{
    CalibrationConfig, Config, CurrentLoopConfig, FaultLimits, Hydraulics, Motor,
    PressureLoopConfig, Rates, SensorScaling, SpeedLoopConfig,
};
use crate::commissioning::config::CommissioningConfig;
use crate::compensation::config::CompensationConfig;

impl Config {
    /// The nominal rig with the Table 1 gains (`contracts/nominal-rig.md`).
    pub fn nominal() -> Config {
        Config {
            rates: Rates {
                pwm_hz: 20_000.0,
                speed_loop_hz: 2_000.0,
                pressure_loop_hz: 1_000.0,
                telemetry_decimation: 20,
            },
            sensors: SensorScaling {
                current_a_per_lsb: 100.0 / 4096.0,
                current_zero_lsb: 2048.0,
                shunt_settling_s: 2e-6,
                dc_link_v_per_lsb: 0.1,
                pressure_pa_per_lsb: 25e6 / 52428.8,
                pressure_zero_lsb: 6554.0,
                pressure_open_wire_lsb: 3277,
                pressure_short_lsb: 62259,
                encoder_counts_per_rev: 10_000,
                encoder_offset_rad: 0.0,
                encoder_referenced_at_start: false,
            },
            motor: Motor {
                pole_pairs: 4,
                stator_resistance_ohm: 0.958,
                d_inductance_h: 5.25e-3,
                q_inductance_h: 12e-3,
                flux_linkage_wb: 0.1827,
                dc_link_nominal_v: 280.0,
            },
            current: CurrentLoopConfig {
                kp_d: 5.775,
                ki_d: 1053.8,
                kp_q: 13.2,
                ki_q: 1053.8,
                voltage_limit_v: 161.6,
                decoupling: true,
            },
            speed: SpeedLoopConfig {
                kp: 0.14,
                ki: 7.0,
                active_damping: 0.013,
                iq_limit_a: 30.0,
                speed_limit_rad_s: 200.0,
                observer_bandwidth_rad_s: 1000.0,
            },
            pressure: PressureLoopConfig {
                bandwidth_rad_s: 20.0,
                integral_corner_ratio: 0.25,
                feedback_filter_rad_s: 150.0,
                ramp_pa_per_s: 10e6,
                setpoint_min_pa: 0.0,
                setpoint_max_pa: 18e6,
            },
            hydraulics: Hydraulics {
                pump_displacement_m3_per_rev: 1.5e-6,
                oil_volume_m3: 450e-6,
                bulk_modulus_pa: 6.5e8,
                absorber_volume_m3: 400e-6,
                absorber_precharge_pa: 3e6,
                polytropic_exponent: 1.3,
                leakage_m3_per_s_pa: 3e-13,
            },
            limits: FaultLimits {
                over_current_a: 45.0,
                hardware_over_current_a: 47.0,
                over_voltage_v: 360.0,
                under_voltage_v: 200.0,
                over_pressure_pa: 20e6,
                over_speed_rad_s: 260.0,
                encoder_plausible_speed_rad_s: 600.0,
                command_timeout_s: 0.1,
                // A tenth of the q-current limit: 75 times the sum's noise (three
                // channels at 0.02 A rms and a count each, 0.04 A rms) and three times what
                // a 2 % gain mismatch of one channel makes at the 45 A trip.
                current_sum_a: 3.0,
                // Ten times the longest saturated acceleration of the loaded shaft
                // (0 -> 200 rad/s at 30 A: 5 ms).
                stall_time_s: 0.1,
            },
            calibration: CalibrationConfig {
                offset_time_s: 0.05,
                offsets_at_boot: true,
                offset_max_lsb: 200.0,
                alignment_current_a: 5.0,
                bootstrap_precharge_s: 0.5e-3,
                alignment_time_s: 0.5,
            },
            commissioning: CommissioningConfig::nominal(),
            compensation: CompensationConfig::nominal(),
        }
    }

    /// The first power-up on a current-limited bench supply of 24‥48 V
    /// (`docs/bring-up.md`; the firmware's `bring-up` feature): the nominal motor and
    /// loops, with the DC-link window, the PI voltage limit and every current and speed
    /// limit lowered, so a wiring, sign or offset error trips at a few amperes and a few
    /// tens of rad/s instead of the nominal 45 A and 260 rad/s.
    pub fn bring_up() -> Config {
        let mut c = Config::nominal();
        c.motor.dc_link_nominal_v = 48.0;
        // 48 V / √3, the SVPWM linear limit at 48 V.
        c.current.voltage_limit_v = 27.0;
        c.speed.iq_limit_a = 3.0;
        c.speed.speed_limit_rad_s = 30.0;
        c.limits.over_current_a = 6.0;
        c.limits.hardware_over_current_a = 8.0;
        c.limits.under_voltage_v = 18.0;
        c.limits.over_voltage_v = 60.0;
        c.limits.over_speed_rad_s = 40.0;
        c.calibration.alignment_current_a = 2.0;
        let k = &mut c.commissioning;
        k.current_a = 4.0;
        k.spin_current_a = 2.0;
        k.pulse_voltage_v = 12.0;
        // Back-EMF at 20 rad/s: 4 · 20 · 0.1827 = 14.6 V, inside the 27 V limit.
        k.spin_speed_rad_s = 20.0;
        c
    }

    /// The same configuration at another PWM (current-loop) rate, keeping the speed- and
    /// pressure-loop rates (for example 100 kHz, Table 1's 1e-5 s).
    pub fn with_pwm_hz(mut self, pwm_hz: f32) -> Config {
        self.rates.pwm_hz = pwm_hz;
        self
    }
}
