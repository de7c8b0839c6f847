//! Fault injection in closed loop: every supervisor fault of the drive trips within one
//! current-loop period of its cause (the very call that sees it returns the bridge
//! disabled), latches (stays after the cause is gone, the bridge stays off), and is cleared
//! only by the ClearFaults command once the cause is gone; out-of-range commands are
//! refused with an error naming the bound.
//!
//! The faults are injected where the MCU would see them: in the ADC results and encoder
//! count the controller receives ([`closed_loop::ClosedLoop::step_with`]), by the
//! application's overrun report, or by the bench PC going silent. The drive is holding
//! 5 MPa on the blocked cylinder (scenario `pressure-hold`) when a fault is injected, so
//! the bridge is on and carrying the holding current.

use closed_loop::{by_name, controller_config, ClosedLoop, Sample};
use firmware::supervisor::ModeRefusal;
use firmware::{Command, CommandError, Config, Controller, FaultCode, Measurements, Mode};
use plant_model::{InitialConditions, Inputs, Plant, Rig};
use std::f64::consts::TAU;

/// Settling of the holding loop before a fault is injected. [s]
const T_INJECT: f64 = 0.2;

fn holding() -> (ClosedLoop, Config) {
    let rig = Rig::nominal();
    let config = controller_config(&rig);
    let scenario = by_name("pressure-hold").expect("scenario pressure-hold");
    let mut l = ClosedLoop::new(&rig, &config, scenario, 5).expect("nominal closed loop");
    let mut last = None;
    l.run(T_INJECT, 1, |s| last = Some(s.outputs.pwm_enabled));
    assert_eq!(last, Some(true), "the bridge is on while holding");
    assert_eq!(l.controller_mut().fault(), None);
    (l, config)
}

fn assert_tripped(s: &Sample, f: FaultCode, what: &str) {
    assert!(
        !s.outputs.pwm_enabled,
        "{what}: PWM still enabled in the call that saw the cause"
    );
    assert_eq!(s.telemetry.fault, Some(f), "{what}: latched fault");
    assert_eq!(s.telemetry.mode, Mode::Disabled, "{what}: mode");
}

/// Injects `tamper` for one call (event causes) or for that call and five more
/// (lasting causes), then checks the trip, the latch, the clear and the restart.
fn trip_latch_clear(f: FaultCode, tamper: impl Fn(Measurements) -> Measurements, lasting: bool) {
    let what = format!("{f}");
    let (mut l, _) = holding();
    let s = l.step_with(&tamper);
    assert_tripped(&s, f, &what);
    if lasting {
        for _ in 0..5 {
            let s = l.step_with(&tamper);
            assert_tripped(&s, f, &what);
        }
        assert_eq!(
            l.command(Command::ClearFaults),
            Err(CommandError::CausePresent(f)),
            "{what}: clear must be refused while the cause is present"
        );
        assert_eq!(
            l.command(Command::SetMode(Mode::Pressure)),
            Err(CommandError::Mode(ModeRefusal::Faulted(f))),
            "{what}: a mode request must be refused while latched"
        );
    }
    // The cause is gone: the fault stays latched and the bridge off (1 ms).
    for _ in 0..20 {
        let s = l.step();
        assert_tripped(&s, f, &format!("{what} (cause gone)"));
    }
    assert_eq!(l.command(Command::ClearFaults), Ok(()), "{what}: clear");
    assert_eq!(l.controller_mut().fault(), None, "{what}: cleared");
    // Clearing does not restart the drive: that takes a mode command.
    let s = l.step();
    assert!(!s.outputs.pwm_enabled, "{what}: PWM on after clear alone");
    assert_eq!(
        l.command(Command::SetMode(Mode::Pressure)),
        Ok(()),
        "{what}: restart"
    );
    let s = l.step();
    assert!(s.outputs.pwm_enabled, "{what}: PWM off after restart");
    println!("{what}: tripped in the injecting call, latched 20 calls after the cause, cleared");
}

/// ADC count of a phase current [A] with the nominal sensor scaling, saturated to 12 bit.
fn current_counts(c: &Config, a: f32) -> u16 {
    (c.sensors.current_zero_lsb + a / c.sensors.current_a_per_lsb).clamp(0.0, 4095.0) as u16
}

#[test]
fn phase_over_current() {
    let (_, c) = holding();
    // 49.98 A on phase a (the ADC's full scale), above the 45 A trip.
    let counts = current_counts(&c, 60.0);
    assert!((counts as f32 - c.sensors.current_zero_lsb) * c.sensors.current_a_per_lsb > 45.0);
    trip_latch_clear(
        FaultCode::PhaseOverCurrent,
        |mut m| {
            m.adc_phase_current[0] = counts;
            m
        },
        true,
    );
}

#[test]
fn dc_link_over_voltage() {
    // 370 V on the 0.1 V/LSB divider, above the 360 V trip.
    trip_latch_clear(
        FaultCode::DcLinkOverVoltage,
        |mut m| {
            m.adc_dc_link = 3700;
            m
        },
        true,
    );
}

#[test]
fn dc_link_under_voltage() {
    // 180 V, below the 200 V trip.
    trip_latch_clear(
        FaultCode::DcLinkUnderVoltage,
        |mut m| {
            m.adc_dc_link = 1800;
            m
        },
        true,
    );
}

#[test]
fn over_pressure() {
    let (_, c) = holding();
    // 20.5 MPa: above the 20 MPa trip, below the 21 MPa relief valve and the short level.
    let counts = (c.sensors.pressure_zero_lsb + 20.5e6 / c.sensors.pressure_pa_per_lsb) as u16;
    assert!(counts < c.sensors.pressure_short_lsb);
    trip_latch_clear(
        FaultCode::OverPressure,
        |mut m| {
            m.adc_pressure = counts;
            m
        },
        true,
    );
}

#[test]
fn pressure_sensor_open_wire() {
    // A 4–20 mA loop with an open wire reads below 4 mA: far below the live zero.
    trip_latch_clear(
        FaultCode::PressureSensorOpenWire,
        |mut m| {
            m.adc_pressure = 1000;
            m
        },
        true,
    );
}

#[test]
fn pressure_sensor_short() {
    trip_latch_clear(
        FaultCode::PressureSensorShort,
        |mut m| {
            m.adc_pressure = 65_000;
            m
        },
        true,
    );
}

#[test]
fn encoder_jump() {
    // A quarter revolution in one 50 µs period = 31 000 rad/s, against 600 rad/s plausible.
    trip_latch_clear(
        FaultCode::EncoderJump,
        |mut m| {
            m.encoder_count = (m.encoder_count + 2_500) % 10_000;
            m
        },
        false,
    );
}

#[test]
fn encoder_index_far_from_count_zero() {
    // The index is at count 0; one reported far from it means lost or spurious counts.
    let (l, _) = holding();
    let theta = l.plant().observe().theta_m_rad.rem_euclid(TAU);
    assert!(
        (0.1..TAU - 0.1).contains(&theta),
        "precondition: the shaft is away from the index ({theta} rad)"
    );
    trip_latch_clear(
        FaultCode::EncoderIndexLost,
        |mut m| {
            m.encoder_index = true;
            m
        },
        false,
    );
}

#[test]
fn encoder_index_missing_for_a_revolution() {
    // Speed mode at 50 rad/s; from 0.3 s every index pulse is suppressed. The fault must
    // come when the shaft has turned one revolution past the last index the controller saw
    // (plus at most the plausibility margin of a few tens of counts: 1 %).
    let rig = Rig::nominal();
    let config = controller_config(&rig);
    let scenario = by_name("speed-step").expect("scenario speed-step");
    let mut l = ClosedLoop::new(&rig, &config, scenario, 5).expect("closed loop");
    let mut last_index_theta = None;
    while l.time_s() < 0.3 {
        let mut seen = false;
        let s = l.step_with(|m| {
            seen = m.encoder_index;
            m
        });
        if seen {
            last_index_theta = Some(s.truth.theta_m_rad);
        }
        assert!(s.outputs.pwm_enabled);
    }
    let last = last_index_theta.expect("the index was seen while turning");
    let mut trip = None;
    while l.time_s() < 0.6 {
        let s = l.step_with(|mut m| {
            m.encoder_index = false;
            m
        });
        if !s.outputs.pwm_enabled {
            trip = Some(s);
            break;
        }
    }
    let s = trip.expect("the missing index trips");
    assert_eq!(s.telemetry.fault, Some(FaultCode::EncoderIndexLost));
    let travel = s.truth.theta_m_rad - last;
    println!(
        "missing index: tripped after {:.4} rev since the last index seen",
        travel / TAU
    );
    assert!(
        (TAU..=1.01 * TAU).contains(&travel),
        "tripped after {travel} rad without an index, expected just over one revolution"
    );
}

#[test]
fn over_speed() {
    // The encoder reports the shaft racing at 40 counts per period (503 rad/s, plausible
    // per step but above the 260 rad/s trip). The speed is measured once per speed-loop
    // period, so the cause appears in the call whose speed estimate exceeds the limit: that
    // call must return the bridge off.
    let (mut l, c) = holding();
    let limit = c.limits.over_speed_rad_s;
    let n = c.sensors.encoder_counts_per_rev;
    let mut offset = 0u32;
    let mut tripped = None;
    for k in 0..40 {
        offset += 40;
        let o = offset;
        let s = l.step_with(|mut m| {
            m.encoder_count = (m.encoder_count + o) % n;
            m
        });
        let seen = s.telemetry.speed_rad_s.abs() > limit;
        if seen {
            tripped = Some(k);
            assert_tripped(&s, FaultCode::OverSpeed, "over-speed");
            break;
        }
        assert!(
            s.outputs.pwm_enabled,
            "PWM off at {k} before over-speed was measured"
        );
    }
    let k = tripped.expect("over-speed measured within two speed periods");
    // Still racing: clear refused.
    for _ in 0..20 {
        offset += 40;
        let o = offset;
        l.step_with(|mut m| {
            m.encoder_count = (m.encoder_count + o) % n;
            m
        });
    }
    assert_eq!(
        l.command(Command::ClearFaults),
        Err(CommandError::CausePresent(FaultCode::OverSpeed))
    );
    // The encoder agrees with the shaft again (the offset stays, no jump): the next speed
    // estimates are the true slow speed; the fault stays latched until cleared.
    for _ in 0..40 {
        let o = offset;
        let s = l.step_with(|mut m| {
            m.encoder_count = (m.encoder_count + o) % n;
            m
        });
        assert_tripped(&s, FaultCode::OverSpeed, "over-speed (cause gone)");
    }
    assert_eq!(l.command(Command::ClearFaults), Ok(()));
    assert_eq!(l.command(Command::SetMode(Mode::Pressure)), Ok(()));
    println!("over-speed: tripped in call {k} of the racing encoder, the first whose speed estimate exceeded {limit} rad/s");
}

#[test]
fn watchdog_overrun() {
    let (mut l, _) = holding();
    l.controller_mut().report_overrun();
    let s = l.step();
    assert_tripped(&s, FaultCode::Watchdog, "watchdog");
    for _ in 0..20 {
        let s = l.step();
        assert_tripped(&s, FaultCode::Watchdog, "watchdog (latched)");
    }
    assert_eq!(l.command(Command::ClearFaults), Ok(()));
    assert_eq!(l.command(Command::SetMode(Mode::Pressure)), Ok(()));
    assert!(l.step().outputs.pwm_enabled);
}

/// One current-loop call of a controller driving the plant directly (no harness, so no
/// heartbeats).
fn isr(plant: &mut Plant, c: &mut Controller, period: f64) -> firmware::Outputs {
    let r = plant.sample();
    let out = c.on_current_sample(&Measurements {
        adc_phase_current: r.adc_phase_current,
        adc_dc_link: r.adc_dc_link,
        adc_pressure: r.adc_pressure,
        encoder_count: r.encoder_count,
        encoder_index: r.encoder_index,
        encoder_index_count: 0,
    });
    let d = out.duties;
    plant.advance(
        period,
        &Inputs::duties([d[0] as f64, d[1] as f64, d[2] as f64], out.pwm_enabled),
    );
    out
}

#[test]
fn command_timeout() {
    let mut rig = Rig::nominal();
    rig.cylinder.blocked = true;
    let config = controller_config(&rig);
    config.validate().expect("configuration");
    let mut plant =
        Plant::new(&rig, &InitialConditions::holding(&rig, 5e6), 3).expect("nominal rig");
    let mut c = Controller::new(&config);
    let period = 1.0 / config.rates.pwm_hz as f64;
    let timeout = config.limits.command_timeout_s as f64;
    assert_eq!(c.command(Command::SetPressure { pa: 5e6 }), Ok(()));
    assert_eq!(c.command(Command::SetMode(Mode::Pressure)), Ok(()));
    // The bench PC falls silent after its last command. Calls 1..=k after it.
    let mut trip_call = None;
    for k in 1..=(2.0 * timeout / period) as u32 {
        let out = isr(&mut plant, &mut c, period);
        if !out.pwm_enabled {
            trip_call = Some(k);
            break;
        }
    }
    let k = trip_call.expect("the drive stops without commands");
    let silent = k as f64 * period;
    println!(
        "command timeout: tripped after {:.5} s of silence (timeout {timeout} s, period {period} s)",
        silent
    );
    assert!(
        silent > timeout && silent <= timeout + period + 1e-12,
        "tripped after {silent} s of silence; timeout {timeout} s"
    );
    assert_eq!(c.fault(), Some(FaultCode::CommandTimeout));
    assert_eq!(c.mode(), Mode::Disabled);
    // Commands resume: the fault stays latched and the bridge off until cleared.
    for _ in 0..20 {
        assert_eq!(c.command(Command::Heartbeat), Ok(()));
        assert!(!isr(&mut plant, &mut c, period).pwm_enabled);
        assert_eq!(c.fault(), Some(FaultCode::CommandTimeout));
    }
    assert_eq!(c.command(Command::ClearFaults), Ok(()));
    assert_eq!(c.command(Command::SetMode(Mode::Pressure)), Ok(()));
    assert!(isr(&mut plant, &mut c, period).pwm_enabled);
}

#[test]
fn out_of_range_commands_are_refused_naming_the_bound() {
    let (mut l, c) = holding();
    let pmax = c.pressure.setpoint_max_pa;
    let pmin = c.pressure.setpoint_min_pa;
    let smax = c.speed.speed_limit_rad_s;
    let p_err = CommandError::PressureOutOfRange {
        min_pa: pmin,
        max_pa: pmax,
    };
    for pa in [pmax * 1.05, pmin - 1e5, f32::NAN, f32::INFINITY] {
        let e = l.command(Command::SetPressure { pa });
        assert_eq!(e, Err(p_err), "pressure setpoint {pa} Pa");
        let text = p_err.to_string();
        assert!(
            text.contains("pressure.setpoint_max_pa") && text.contains(&format!("{pmax}")),
            "{text}"
        );
        // The refusal's code shows in the telemetry (until the next accepted command: the
        // harness's heartbeat).
        assert_eq!(l.controller_mut().telemetry().command_status, p_err.code());
    }
    let s_err = CommandError::SpeedOutOfRange { max_rad_s: smax };
    for rad_s in [smax * 1.25, -smax * 1.25, f32::NAN, f32::NEG_INFINITY] {
        assert_eq!(
            l.command(Command::SetSpeed { rad_s }),
            Err(s_err),
            "speed setpoint {rad_s} rad/s"
        );
        let text = s_err.to_string();
        assert!(
            text.contains("speed.speed_limit_rad_s") && text.contains(&format!("{smax}")),
            "{text}"
        );
        assert_eq!(l.controller_mut().telemetry().command_status, s_err.code());
    }
    // The bounds themselves are accepted.
    assert_eq!(l.command(Command::SetSpeed { rad_s: -smax }), Ok(()));
    assert_eq!(l.command(Command::SetPressure { pa: pmax }), Ok(()));
    assert_eq!(l.command(Command::SetPressure { pa: 5e6 }), Ok(()));
    // Refusals changed nothing: the drive still holds 5 MPa without a fault.
    let mut p = 0.0;
    let mut fault = None;
    l.run(T_INJECT + 0.3, 1, |s| {
        p = s.truth.p_a_pa;
        fault = fault.or(s.telemetry.fault);
    });
    assert_eq!(fault, None);
    assert!(
        (p - 5e6).abs() < 0.02 * 5e6,
        "pressure {p} Pa after refusals"
    );
}
