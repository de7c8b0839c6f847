//! Each fault's latch/disable/clear cycle, the command timeout and watchdog, and command
//! refusals with their bounds.

use super::*;
use crate::config::Config;
use crate::io::Measurements;
use crate::supervisor::{FaultCode, Mode, ModeRefusal};

/// Feeds `bad` until the fault latches; asserts the latching call already returned
/// disabled PWM; then checks the clear cycle with `good`.
fn trips(
    mut c: Controller,
    want: FaultCode,
    bad: impl Fn(u32) -> Measurements,
    good: Measurements,
) {
    let mut tripped_at = None;
    for k in 0..5000u32 {
        let out = c.on_current_sample(&bad(k));
        if c.fault().is_some() {
            assert!(
                !out.pwm_enabled,
                "{want:?}: PWM still on in the detecting call"
            );
            assert_eq!(out.duties, [0.5; 3]);
            tripped_at = Some(k);
            break;
        }
        assert!(
            out.pwm_enabled,
            "{want:?}: PWM off before the fault at call {k}"
        );
        c.command(Command::Heartbeat).unwrap();
    }
    assert!(tripped_at.is_some(), "{want:?} never tripped");
    assert_eq!(c.fault(), Some(want));
    assert_eq!(c.mode(), Mode::Disabled);
    assert_eq!(c.telemetry().fault, Some(want));
    // Latched: stays off, mode requests refused.
    let out = c.on_current_sample(&bad(0));
    assert!(!out.pwm_enabled);
    assert_eq!(
        c.command(Command::SetMode(Mode::Speed)),
        Err(CommandError::Mode(ModeRefusal::Faulted(want)))
    );
    if !want.is_event() {
        // Cause still present: clear refused.
        assert_eq!(
            c.command(Command::ClearFaults),
            Err(CommandError::CausePresent(want))
        );
        assert_eq!(c.fault(), Some(want));
        assert_eq!(c.telemetry().command_status, 6);
    }
    // Cause gone (25 calls: over-speed needs two speed periods to see the shaft at rest):
    // still latched until cleared.
    for _ in 0..25 {
        assert!(!c.on_current_sample(&good).pwm_enabled);
    }
    assert_eq!(c.fault(), Some(want));
    assert_eq!(c.command(Command::ClearFaults), Ok(()));
    assert_eq!(c.fault(), None);
    assert_eq!(c.mode(), Mode::Disabled);
    // After an encoder fault the counter needs the index again; for the others this is
    // one more healthy sample.
    c.on_current_sample(&index_at(good.encoder_count));
    assert_eq!(c.command(Command::SetMode(Mode::Speed)), Ok(()));
    assert!(c.on_current_sample(&good).pwm_enabled);
}

#[test]
fn phase_over_current() {
    let bad = |_| Measurements {
        adc_phase_current: [2048 + (46.0 / A_PER_LSB) as u16, 2048, 2048],
        ..healthy(0)
    };
    trips(
        running(Mode::Speed),
        FaultCode::PhaseOverCurrent,
        bad,
        healthy(0),
    );
}

#[test]
fn dc_link_over_and_under_voltage() {
    let over = |_| Measurements {
        adc_dc_link: 3650,
        ..healthy(0)
    };
    trips(
        running(Mode::Speed),
        FaultCode::DcLinkOverVoltage,
        over,
        healthy(0),
    );
    let under = |_| Measurements {
        adc_dc_link: 1990,
        ..healthy(0)
    };
    trips(
        running(Mode::Pressure),
        FaultCode::DcLinkUnderVoltage,
        under,
        healthy(0),
    );
}

#[test]
fn over_pressure_and_sensor_range() {
    let over = |_| Measurements {
        adc_pressure: pressure_counts(20.2e6),
        ..healthy(0)
    };
    trips(
        running(Mode::Pressure),
        FaultCode::OverPressure,
        over,
        healthy(0),
    );
    let open = |_| Measurements {
        adc_pressure: 3000,
        ..healthy(0)
    };
    trips(
        running(Mode::Pressure),
        FaultCode::PressureSensorOpenWire,
        open,
        healthy(0),
    );
    let short = |_| Measurements {
        adc_pressure: 62_500,
        ..healthy(0)
    };
    trips(
        running(Mode::Speed),
        FaultCode::PressureSensorShort,
        short,
        healthy(0),
    );
}

#[test]
fn encoder_jump_and_lost_index() {
    // 600 rad/s plausible → 50 counts per 50 µs: a 300-count step is a jump.
    let jump = |k: u32| healthy(if k < 3 { 0 } else { 300 });
    trips(
        running(Mode::Speed),
        FaultCode::EncoderJump,
        jump,
        healthy(300),
    );
    // Turning at 10 counts per sample through count 0 without an index.
    let lost = |k: u32| healthy((k * 10) % 10_000);
    trips(
        running(Mode::Speed),
        FaultCode::EncoderIndexLost,
        lost,
        healthy(0),
    );
}

#[test]
fn over_speed() {
    // 25 counts per sample = 25·20 000/10 000 rev/s = 314 rad/s > 260 rad/s, with the index
    // at each wrap so only the speed is wrong.
    let fast = |k: u32| {
        let c = k * 25;
        Measurements {
            encoder_index: k > 0 && c % 10_000 < 25,
            ..healthy(c % 10_000)
        }
    };
    trips(running(Mode::Speed), FaultCode::OverSpeed, fast, healthy(0));
}

#[test]
fn command_timeout_and_watchdog() {
    let mut c = running(Mode::Speed);
    // 0.1 s at 20 kHz = 2000 calls without a command.
    let mut off_at = None;
    for k in 0..3000 {
        if !c.on_current_sample(&healthy(0)).pwm_enabled {
            off_at = Some(k);
            break;
        }
    }
    let k = off_at.expect("timeout never tripped");
    assert!((1995..=2005).contains(&k), "tripped after {k} calls");
    assert_eq!(c.fault(), Some(FaultCode::CommandTimeout));
    assert_eq!(c.command(Command::ClearFaults), Ok(()));

    let mut c = running(Mode::Pressure);
    c.report_overrun();
    assert_eq!(c.mode(), Mode::Disabled);
    assert!(!c.on_current_sample(&healthy(0)).pwm_enabled);
    assert_eq!(c.fault(), Some(FaultCode::Watchdog));
    assert_eq!(c.command(Command::ClearFaults), Ok(()));
}

#[test]
fn disabled_drive_does_not_latch_but_refuses_to_start() {
    let mut c = Controller::new(&Config::nominal());
    let no_dc = Measurements {
        adc_dc_link: 0,
        ..healthy(0)
    };
    assert!(!c.on_current_sample(&no_dc).pwm_enabled);
    assert_eq!(c.fault(), None);
    assert_eq!(
        c.command(Command::SetMode(Mode::Speed)),
        Err(CommandError::Mode(ModeRefusal::ConditionPresent(
            FaultCode::DcLinkUnderVoltage
        )))
    );
    assert_eq!(c.telemetry().command_status, 4);
}

#[test]
fn out_of_range_commands_are_refused_with_their_bound() {
    let mut c = Controller::new(&Config::nominal());
    let e = c.command(Command::SetPressure { pa: 19e6 }).unwrap_err();
    assert_eq!(
        e,
        CommandError::PressureOutOfRange {
            min_pa: 0.0,
            max_pa: 18e6
        }
    );
    assert!(std::format!("{e}").contains("pressure.setpoint_max_pa"));
    assert_eq!(c.telemetry().command_status, 1);
    assert!(c.command(Command::SetPressure { pa: -1.0 }).is_err());
    assert!(c.command(Command::SetPressure { pa: f32::NAN }).is_err());
    let e = c.command(Command::SetSpeed { rad_s: -201.0 }).unwrap_err();
    assert_eq!(e, CommandError::SpeedOutOfRange { max_rad_s: 200.0 });
    assert!(std::format!("{e}").contains("speed.speed_limit_rad_s"));
    assert_eq!(c.telemetry().command_status, 2);
    assert!(c
        .command(Command::SetSpeed {
            rad_s: f32::INFINITY
        })
        .is_err());
    assert_eq!(c.command(Command::SetSpeed { rad_s: -200.0 }), Ok(()));
    assert_eq!(c.telemetry().command_status, 0);
    assert_eq!(c.command(Command::SetPressure { pa: 18e6 }), Ok(()));
}
