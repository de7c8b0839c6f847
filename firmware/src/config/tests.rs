//! Tests of the configuration: the nominal and bring-up configurations are valid, each
//! bad field is named, loop-rate ratios.

use super::*;

#[test]
fn nominal_is_valid_and_matches_the_rig() {
    let c = Config::nominal();
    assert_eq!(c.validate(), Ok(()));
    // Table 1 gains are pole-zero cancellation at 1100 rad/s on the rig's motor.
    assert!((c.current.kp_q - c.motor.q_inductance_h * 1100.0).abs() < 1e-4);
    assert!((c.current.kp_d - c.motor.d_inductance_h * 1100.0).abs() < 1e-4);
    assert!((c.current.ki_q - c.motor.stator_resistance_ohm * 1100.0).abs() < 1e-2);
    // 161.6 V is U_dc/√3, the SVPWM linear limit.
    assert!((c.current.voltage_limit_v - 280.0 / libm::sqrtf(3.0)).abs() < 0.1);
    assert_eq!(c.sensors.pressure_pa_per_lsb, 476.837_16);
}

#[test]
fn each_bad_field_is_named() {
    type Case = (fn(&mut Config), &'static str);
    let cases: [Case; 25] = [
        (
            |c| c.limits.hardware_over_current_a = 44.0,
            "limits.hardware_over_current_a",
        ),
        // 2048 counts of 0.0244 A: 50 A is the end of the range.
        (
            |c| c.limits.hardware_over_current_a = 50.0,
            "limits.hardware_over_current_a",
        ),
        (
            |c| c.calibration.bootstrap_precharge_s = 0.02,
            "calibration.bootstrap_precharge_s",
        ),
        // 15 µs of a 50 µs period: the largest readable duty would be 0.4.
        (
            |c| c.sensors.shunt_settling_s = 15e-6,
            "sensors.shunt_settling_s",
        ),
        // 0.8 × the 45 A over-current trip is 36 A.
        (
            |c| c.commissioning.current_a = 40.0,
            "commissioning.current_a",
        ),
        (
            |c| c.commissioning.sweep_time_s = 0.01,
            "commissioning.sweep_time_s",
        ),
        // 0.1 × 2π × 20 kHz = 12 566 rad/s.
        (
            |c| c.commissioning.current_bandwidth_rad_s = 13_000.0,
            "commissioning.current_bandwidth_rad_s",
        ),
        (
            |c| c.commissioning.spin_speed_rad_s = 250.0,
            "commissioning.spin_speed_rad_s",
        ),
        (
            |c| c.commissioning.plausible_ratio = f32::NAN,
            "commissioning.plausible_ratio",
        ),
        (|c| c.rates.pwm_hz = 0.0, "rates.pwm_hz"),
        (|c| c.rates.pwm_hz = 200e3, "rates.pwm_hz"),
        (|c| c.rates.speed_loop_hz = 3_000.0, "rates.speed_loop_hz"),
        (
            |c| c.rates.pressure_loop_hz = f32::NAN,
            "rates.pressure_loop_hz",
        ),
        (|c| c.motor.pole_pairs = 0, "motor.pole_pairs"),
        (|c| c.motor.q_inductance_h = -1.0, "motor.q_inductance_h"),
        (|c| c.current.kp_q = 0.0, "current.kp_q"),
        (
            |c| c.speed.observer_bandwidth_rad_s = f32::NAN,
            "speed.observer_bandwidth_rad_s",
        ),
        (
            |c| c.speed.observer_bandwidth_rad_s = 6_000.0,
            "speed.observer_bandwidth_rad_s",
        ),
        (|c| c.speed.iq_limit_a = 50.0, "limits.over_current_a"),
        (
            |c| c.pressure.setpoint_max_pa = 25e6,
            "limits.over_pressure_pa",
        ),
        (
            |c| c.hydraulics.polytropic_exponent = 0.5,
            "hydraulics.polytropic_exponent",
        ),
        (
            |c| c.sensors.pressure_open_wire_lsb = 63000,
            "sensors.pressure_open_wire_lsb",
        ),
        (
            |c| c.limits.command_timeout_s = -1.0,
            "limits.command_timeout_s",
        ),
        (
            |c| c.limits.current_sum_a = f32::NAN,
            "limits.current_sum_a",
        ),
        (|c| c.limits.stall_time_s = 0.0, "limits.stall_time_s"),
    ];
    for (mutate, field) in cases {
        let mut c = Config::nominal();
        mutate(&mut c);
        let e = c.validate().expect_err(field);
        assert_eq!(e.field, field, "{e}");
    }
}

#[test]
fn the_bring_up_configuration_is_valid_and_trips_at_a_few_amperes() {
    let c = Config::bring_up();
    assert_eq!(c.validate(), Ok(()));
    // A 48 V supply sits inside the DC-link window; the nominal 280 V does not.
    assert!(c.limits.under_voltage_v < 24.0 && 48.0 < c.limits.over_voltage_v);
    assert!(c.limits.over_voltage_v < 280.0);
    assert!(c.limits.hardware_over_current_a <= 10.0);
    // Alignment and commissioning stay below the software trip.
    assert!(c.calibration.alignment_current_a < c.limits.over_current_a);
    assert!(c.commissioning.current_a < c.limits.over_current_a);
    // The loops are the nominal ones.
    let n = Config::nominal();
    assert_eq!((c.current.kp_q, c.speed.kp), (n.current.kp_q, n.speed.kp));
}

#[test]
fn rates_at_table1_sample_time_are_valid() {
    let c = Config::nominal().with_pwm_hz(100e3);
    assert_eq!(c.validate(), Ok(()));
    assert_eq!(whole_ratio(100e3, 2e3), Some(50));
    assert_eq!(whole_ratio(20e3, 3e3), None);
}
