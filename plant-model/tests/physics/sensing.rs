//! The inputs and outputs at the plant's edge: bad inputs never panic, the sensors quantise
//! and wrap as the peripherals do, the dead time costs one dead interval per PWM period, and
//! the transducer's lag trails a ramp by its time constant.

use super::*;

#[test]
fn step_never_panics_on_bad_inputs() {
    let rig = Rig::nominal();
    let mut plant = Plant::new(&rig, &InitialConditions::at_rest(&rig), 3).unwrap();
    for inputs in [
        Inputs::duties([f64::NAN, 2.0, -1.0], true),
        Inputs::duties([0.5; 3], false),
        Inputs {
            drive: Drive::Currents {
                i_d: f64::INFINITY,
                i_q: f64::NAN,
            },
            piston: None,
            external_force_n: f64::NAN,
            external_torque_nm: 0.0,
        },
        Inputs {
            drive: Drive::ShaftSpeed {
                omega_rad_s: f64::NEG_INFINITY,
            },
            piston: Some((f64::NAN, 1e9)),
            external_force_n: 0.0,
            external_torque_nm: 0.0,
        },
    ] {
        for dt in [-1.0, 0.0, f64::NAN, 1e-4] {
            plant.advance(dt, &inputs);
            let _ = plant.sample();
        }
    }
    let o = plant.observe();
    assert!(o.p_a_pa.is_finite() && o.i_q_a.is_finite());
}

#[test]
fn sensors_quantise_and_wrap_like_the_peripherals() {
    let mut rig = quiet(Rig::nominal());
    rig.cylinder.blocked = true;
    let mut plant = Plant::new(&rig, &InitialConditions::holding(&rig, 5e6), 1).unwrap();
    let s = plant.sample();
    // 5 MPa at 476.84 Pa/LSB above 6554 counts; zero current at mid-scale; 280 V at 0.1 V/LSB.
    assert_eq!(
        s.adc_pressure,
        (6554.0f64 + 5e6 / (25e6 / 52428.8)).round() as u16
    );
    assert_eq!(s.adc_phase_current, [2048; 3]);
    assert_eq!(s.adc_dc_link, 2800);
    // Turning one and a half revolutions passes the index once and wraps the counter.
    let mut index_seen = 0;
    for _ in 0..150 {
        plant.advance(0.01, &speed_drive(2.0 * PI));
        if plant.sample().encoder_index {
            index_seen += 1;
        }
    }
    assert_eq!(index_seen, 1);
    let count = plant.sample().encoder_count;
    assert!((count as i64 - 5000).abs() <= 2, "count {count}");
}

#[test]
fn dead_time_costs_one_dead_interval_per_pwm_period() {
    // A switching-level leg over one centre-aligned PWM period, independent of the average
    // model: the upper switch's gate is on while the triangular carrier is below the duty,
    // each turn-on delayed by t_d; while both gates are off, a positive current flows
    // through the lower diode (pole at 0 V). The pole's mean voltage falls short of
    // d·U_dc by t_d·f·U_dc: the falling edge loses nothing.
    use plant_model::inverter::Inverter;
    let rig = Rig::nominal();
    let mut p = rig.inverter.clone();
    p.dead_time_s = 1.5e-6;
    let (t_pwm, t_d, u_dc, duty) = (1.0 / p.pwm_frequency_hz, p.dead_time_s, p.u_dc_v, 0.6);
    let n = 200_000;
    let mut sum = 0.0;
    for k in 0..n {
        let t = (k as f64 + 0.5) / n as f64 * t_pwm;
        // The upper gate's command: the carrier 0 → 1 → 0 over the period below the duty.
        let upper_cmd = |t: f64| {
            let c = 1.0 - (2.0 * t.rem_euclid(t_pwm) / t_pwm - 1.0).abs();
            c < duty
        };
        // The upper switch conducts only if commanded now and for the last t_d.
        let upper_on = upper_cmd(t) && upper_cmd(t - t_d);
        // The lower switch conducts when commanded off now and for the last t_d; otherwise
        // (dead time) the positive current takes the lower diode: pole at 0 either way.
        sum += if upper_on { u_dc } else { 0.0 };
    }
    let mean = sum / n as f64;
    let loss_switching = duty * u_dc - mean;
    let average = Inverter::new(&p).pole_voltages(&[duty; 3], &[10.0, -5.0, -5.0])[0];
    let loss_average = duty * u_dc - average;
    let textbook = t_d / t_pwm * u_dc;
    assert!(
        (loss_switching - textbook).abs() < 0.01 * textbook,
        "{loss_switching} vs {textbook}"
    );
    assert!(
        (loss_average - textbook).abs() < 1e-9 * textbook,
        "{loss_average} vs {textbook}"
    );
}

#[test]
fn pressure_sensor_lag_trails_a_ramp_by_one_time_constant() {
    // A first-order lag τ·ṗ_s = p − p_s driven by a ramp settles to p − p_s = τ·ṗ. The pump
    // turned at a fixed speed into the blocked cylinder ramps port A; time constants from
    // twenty steps down to a fiftieth of one (where an explicit integration of the lag would
    // diverge) all trail it by τ·ṗ.
    for tau in [1e-3, 50e-6, 1e-6] {
        let mut rig = quiet(Rig::nominal());
        rig.cylinder.blocked = true;
        rig.sensors.pressure.lag_time_constant_s = tau;
        let mut plant = Plant::new(&rig, &InitialConditions::holding(&rig, 2e6), 1).unwrap();
        let h = 50e-6;
        let mut p = Vec::new();
        let mut lag = Vec::new();
        for _ in 0..400 {
            plant.advance(h, &speed_drive(20.0));
            let o = plant.observe();
            p.push(o.p_a_pa);
            lag.push(o.p_a_pa - o.p_sensor_pa);
        }
        // After 20 ms (twenty time constants of the slowest), against the central difference.
        let k = 398;
        let slope = (p[k + 1] - p[k - 1]) / (2.0 * h);
        assert!(slope > 1e6, "τ = {tau}: the port ramps ({slope} Pa/s)");
        let expected = tau * slope;
        let err = (lag[k] - expected).abs() / expected;
        eprintln!(
            "τ = {tau}: p − p_s = {:.4e} Pa, τ·ṗ = {expected:.4e} Pa",
            lag[k]
        );
        assert!(
            err < 0.02,
            "τ = {tau}: trails by {} Pa, τ·ṗ = {expected} Pa",
            lag[k]
        );
    }
}
