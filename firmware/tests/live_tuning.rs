//! Live parameter changes and step tests on the running controller: a gain change moves
//! the PI output by one sample's integration only (bumpless), a step test holds its step
//! for exactly its duration with telemetry at full rate, then restores both.
//!
//! The drive is at rest (encoder still, zero phase currents): the speed error and the
//! current error are then constant, so each PI's output grows by exactly Ki·T·e per step
//! (the sampled continuous PI), the independent number the tests hold the output to.

use firmware::parameters::ParamId;
use firmware::step_test::StepLoop;
use firmware::{Command, CommandError, Config, Controller, Measurements, Mode};

/// At rest: 0 A (ADC mid-scale), 280 V, 3 MPa, encoder still.
fn at_rest() -> Measurements {
    Measurements {
        adc_phase_current: [2048; 3],
        adc_dc_link: 2800,
        // 3 MPa with the nominal transducer scaling (6554 counts at 0 Pa, 476.837 Pa/LSB).
        adc_pressure: 6554 + 6291,
        encoder_count: 0,
        encoder_index: false,
        encoder_index_count: 0,
    }
}

fn running(mode: Mode) -> Controller {
    // The encoder stands still while the loops ask for torque, for seconds: a stall to the
    // supervisor, which these tests of the loops' arithmetic keep out of the way.
    let mut cfg = Config::nominal();
    cfg.limits.stall_time_s = 3600.0;
    let mut c = Controller::new(&cfg);
    // Power-up as on the board: the current offsets measured at rest (0.05 s at 20 kHz),
    // then the encoder index passes (captured at counter 0).
    for _ in 0..1000 {
        c.on_current_sample(&at_rest());
    }
    c.on_current_sample(&Measurements {
        encoder_index: true,
        ..at_rest()
    });
    c.command(Command::SetMode(mode)).expect("mode");
    // The first active period resets the loops for a start from rest.
    c.on_current_sample(&at_rest());
    c
}

/// The changes of the q-current reference between consecutive periods (the speed loop
/// moves it once per speed period).
fn reference_steps(s: &[(f32, f32)]) -> Vec<f32> {
    s.windows(2)
        .map(|w| w[1].0 - w[0].0)
        .filter(|d| d.abs() > 1e-6)
        .collect()
}

/// Runs `n` PWM periods, returning (q-current reference, q voltage) after each.
fn run(c: &mut Controller, n: usize) -> Vec<(f32, f32)> {
    (0..n)
        .map(|_| {
            let out = c.on_current_sample(&at_rest());
            assert!(out.pwm_enabled, "{:?}", c.fault());
            let t = c.telemetry();
            (t.iq_ref_a, t.uq_v)
        })
        .collect()
}

#[test]
fn a_speed_gain_change_moves_the_current_reference_by_one_integration_step_only() {
    let mut c = running(Mode::Speed);
    c.command(Command::SetSpeed { rad_s: 10.0 }).unwrap();
    // Speed loop every 10th period (2 kHz of 20 kHz); e = 10 rad/s at rest:
    // Ki·T·e = 7 A/rad · 0.5 ms · 10 rad/s = 0.035 A per speed period.
    let per_tick = 7.0 * 0.5e-3 * 10.0;
    let mut s = run(&mut c, 400);
    // Double Kp between two periods: a plain PI would jump by ΔKp·e = 1.4 A.
    c.command(Command::SetParameter {
        id: ParamId::SpeedKp,
        value: 0.28,
    })
    .unwrap();
    s.extend(run(&mut c, 40));
    let steps = reference_steps(&s);
    // 440 periods = 44 speed periods; the first is the proportional kick from rest,
    // Kp·e = 0.14 · 10 = 1.4 A, every later one the integration alone.
    assert_eq!(steps.len(), 44, "{steps:?}");
    assert!((steps[0] - 1.4).abs() < 1e-4, "{}", steps[0]);
    for (k, d) in steps.iter().enumerate().skip(1) {
        assert!((d - per_tick).abs() < 2e-4, "speed period {k}: step {d} A");
    }
}

#[test]
fn a_current_gain_change_moves_the_voltage_by_one_integration_step_only() {
    let mut c = running(Mode::Speed);
    // A 2 A current step holds i_q* constant (speed loop suspended).
    c.command(Command::StepTest {
        target: StepLoop::Current,
        amplitude: 2.0,
        duration_s: 0.1,
    })
    .unwrap();
    let s = run(&mut c, 50);
    assert!(s.iter().all(|(iq, _)| *iq == 2.0));
    // u_q grows by Ki·T·e = 1053.8 · 50 µs · 2 A = 0.10538 V per period.
    let per_step = 1053.8 * 50e-6 * 2.0;
    let growth = s[49].1 - s[48].1;
    assert!((growth - per_step).abs() < 1e-3, "{growth}");
    c.command(Command::SetParameter {
        id: ParamId::CurrentKpQ,
        value: 20.0,
    })
    .unwrap();
    let after = run(&mut c, 1);
    // A plain PI would jump by (20 − 13.2)·2 = 13.6 V.
    let jump = after[0].1 - s[49].1 - per_step;
    assert!(jump.abs() < 1e-3, "bump {jump} V at the gain change");
}

#[test]
fn a_speed_step_lasts_its_duration_at_full_telemetry_rate_then_restores() {
    let mut c = running(Mode::Speed);
    c.command(Command::SetSpeed { rad_s: 5.0 }).unwrap();
    run(&mut c, 10);
    assert_eq!(c.telemetry_decimation(), 20);
    c.command(Command::StepTest {
        target: StepLoop::Speed,
        amplitude: 20.0,
        duration_s: 0.05,
    })
    .unwrap();
    // 0.05 s at 20 kHz = 1000 periods with the stepped reference and decimation 1.
    let mut stepped = 0;
    for k in 0..1200 {
        let active = c.telemetry_decimation() == 1;
        run(&mut c, 1);
        if active {
            stepped += 1;
            // The speed reference follows at the next speed tick; the setpoint is 25.
            if k >= 10 {
                assert_eq!(c.telemetry().speed_ref_rad_s, 25.0, "period {k}");
            }
        }
        if k % 500 == 0 {
            c.command(Command::Heartbeat).unwrap();
        }
    }
    assert_eq!(stepped, 1000);
    assert_eq!(c.telemetry_decimation(), 20);
    assert_eq!(c.telemetry().speed_ref_rad_s, 5.0);
    assert!(c.step_test().is_none());
}

#[test]
fn a_pressure_step_needs_pressure_mode_and_stays_within_the_setpoint_range() {
    let mut c = running(Mode::Speed);
    let step = |amplitude| Command::StepTest {
        target: StepLoop::Pressure,
        amplitude,
        duration_s: 1.0,
    };
    assert!(matches!(
        c.command(step(1e6)),
        Err(CommandError::StepTest(_))
    ));
    c.command(Command::SetMode(Mode::Pressure)).unwrap();
    c.command(Command::SetPressure { pa: 5e6 }).unwrap();
    // 5 MPa + 14 MPa passes the 18 MPa maximum: 13 MPa is the largest step.
    let e = c.command(step(14e6)).unwrap_err();
    assert_eq!(
        e.to_string(),
        "step test refused: amplitude above 13000000 (loop limit)"
    );
    c.command(step(1e6)).unwrap();
    run(&mut c, 1);
    assert_eq!(c.telemetry_decimation(), 1);
    // A new setpoint ends the test and wins.
    c.command(Command::SetPressure { pa: 4e6 }).unwrap();
    assert!(c.step_test().is_none());
    assert_eq!(c.telemetry_decimation(), 20);
}

#[test]
fn parameters_reach_the_running_drive() {
    let mut c = running(Mode::Pressure);
    c.command(Command::SetPressure { pa: 15e6 }).unwrap();
    // Lowering the setpoint maximum below the held target brings the target down to it.
    c.command(Command::SetParameter {
        id: ParamId::PressureSetpointMax,
        value: 12e6,
    })
    .unwrap();
    // The ramp (10 MPa/s from the 3 MPa measured at entry) would pass 15 MPa after 1.2 s;
    // clamped, it stops at 12 MPa.
    for _ in 0..24 {
        run(&mut c, 1000);
        c.command(Command::Heartbeat).unwrap();
    }
    let p_ref = c.telemetry().p_ref_pa;
    assert!((p_ref - 12e6).abs() < 1.0, "{p_ref}");
    assert_eq!(
        c.command(Command::SetPressure { pa: 15e6 }),
        Err(CommandError::PressureOutOfRange {
            min_pa: 0.0,
            max_pa: 12e6
        })
    );
    c.command(Command::SetParameter {
        id: ParamId::TelemetryDecimation,
        value: 5.0,
    })
    .unwrap();
    assert_eq!(c.telemetry_decimation(), 5);
}

#[test]
fn the_encoder_offset_changes_only_with_the_bridge_off() {
    let mut c = running(Mode::Speed);
    let set = Command::SetParameter {
        id: ParamId::EncoderOffset,
        value: 1.0,
    };
    assert_eq!(
        c.command(set),
        Err(CommandError::Parameter(
            firmware::parameters::ParamError::NotWhileRunning {
                id: ParamId::EncoderOffset
            }
        ))
    );
    c.command(Command::SetMode(Mode::Disabled)).unwrap();
    c.command(set).unwrap();
    assert_eq!(c.encoder_offset(), 1.0);
    assert_eq!(c.parameter(ParamId::EncoderOffset), 1.0);
}
