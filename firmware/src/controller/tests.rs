//! Façade tests: start-up (the board's power-up measurements and the encoder's reference),
//! each fault's latch/disable/clear cycle, command refusals, calibration. Sensor values are
//! built from the nominal scaling written out here.

use super::*;
use crate::config::Config;
use crate::io::Measurements;
use crate::parameters::ParamId;
use crate::supervisor::{FaultCode, Mode, ModeRefusal, NotReady, Readiness};

const A_PER_LSB: f32 = 100.0 / 4096.0;
const PA_PER_LSB: f32 = 25e6 / 52428.8;

fn pressure_counts(p: f32) -> u16 {
    (6554.0 + p / PA_PER_LSB + 0.5) as u16
}

/// A healthy drive at rest: 0 A, 280 V, 3 MPa, encoder at `count`.
fn healthy(count: u32) -> Measurements {
    Measurements {
        adc_phase_current: [2048; 3],
        adc_dc_link: 2800,
        adc_pressure: pressure_counts(3e6),
        encoder_count: count,
        encoder_index: false,
        encoder_index_count: 0,
    }
}

/// An index pulse captured at counter `count`, the counter still there.
fn index_at(count: u32) -> Measurements {
    Measurements {
        encoder_index: true,
        encoder_index_count: count,
        ..healthy(count)
    }
}

/// Power samples of the nominal configuration's offset measurement (0.05 s at 20 kHz).
const BOOT_CALLS: usize = 1000;
/// Periods of the nominal bootstrap precharge (0.5 ms at 20 kHz).
const PRECHARGE_CALLS: usize = 10;

/// A board's power-up: the offset measurement at rest with the bridge off, then the shaft
/// turned past the encoder index (captured at counter 0).
fn boot(c: &mut Controller) {
    for _ in 0..BOOT_CALLS {
        c.on_current_sample(&healthy(0));
    }
    c.on_current_sample(&index_at(0));
    assert_eq!(c.readiness(), Readiness::READY);
}

fn running(mode: Mode) -> Controller {
    let mut c = Controller::new(&Config::nominal());
    boot(&mut c);
    c.command(Command::SetMode(mode)).unwrap();
    let out = c.on_current_sample(&healthy(0));
    assert!(
        out.pwm_enabled,
        "{mode:?} should start after the power-up checks"
    );
    assert_eq!(c.mode(), mode);
    c
}

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

#[test]
fn calibration_measures_offsets_and_aligns_the_encoder() {
    let mut c = Controller::new(&Config::nominal());
    // Power-up offsets, no index yet: Calibrating is allowed, Speed is not.
    let at_boot = Measurements {
        adc_phase_current: [2058, 2042, 2050],
        ..healthy(1234)
    };
    for _ in 0..BOOT_CALLS {
        c.on_current_sample(&at_boot);
    }
    assert_eq!(c.current_offsets(), [2058.0, 2042.0, 2050.0]);
    assert_eq!(
        c.command(Command::SetMode(Mode::Speed)),
        Err(CommandError::Mode(ModeRefusal::NotReady(
            NotReady::RotorAngle
        )))
    );
    let m = Measurements {
        adc_phase_current: [2060, 2040, 2051],
        ..healthy(1234)
    };
    c.command(Command::SetMode(Mode::Calibrating)).unwrap();
    // 0.05 s of offsets with the bridge off, then 0.5 s of alignment with it on.
    let mut off_calls = 0;
    let mut on_calls = 0;
    for _ in 0..12_000 {
        if c.mode() != Mode::Calibrating {
            break;
        }
        if c.on_current_sample(&m).pwm_enabled {
            on_calls += 1;
        } else {
            off_calls += 1;
        }
        c.command(Command::Heartbeat).unwrap();
    }
    assert_eq!(c.mode(), Mode::Disabled);
    assert!(c.is_calibrated());
    assert!((999..=1002).contains(&off_calls), "{off_calls}");
    assert!((9_998..=10_001).contains(&on_calls), "{on_calls}");
    assert_eq!(c.current_offsets(), [2060.0, 2040.0, 2051.0]);
    // The board's counter started wherever it powered up: the alignment's offset is in
    // the counter's frame, and the table keeps its index-relative value until the index;
    // the angle is known, so Speed may start before the index.
    assert_eq!(c.encoder_offset(), 0.0);
    assert_eq!(c.encoder_index_count(), None);
    assert_eq!(c.readiness(), Readiness::READY);
    // The index passes at counter 234 (captured), the counter now reads 240: the rotor's
    // d axis sat 1234 − 234 = 1000 counts after the index, θ_e = 4·2π·0.1 = 2.5133 rad.
    c.on_current_sample(&Measurements {
        encoder_index: true,
        encoder_index_count: 234,
        ..healthy(240)
    });
    assert_eq!(c.encoder_index_count(), Some(234));
    let want = 4.0 * core::f32::consts::TAU * 0.1;
    assert!(
        (c.encoder_offset() - want).abs() < 1e-4,
        "{}",
        c.encoder_offset()
    );
    assert_eq!(c.parameter(ParamId::EncoderOffset), c.encoder_offset());
}

#[test]
fn bad_offsets_fault() {
    let skewed = Measurements {
        adc_phase_current: [2400, 2048, 2048],
        ..healthy(0)
    };
    // At power-up: 352 counts from mid-scale (limit 200) latches fault 12 with the bridge
    // never on, and the measurement starts again.
    let mut c = Controller::new(&Config::nominal());
    for _ in 0..BOOT_CALLS {
        assert!(!c.on_current_sample(&skewed).pwm_enabled);
    }
    assert_eq!(c.fault(), Some(FaultCode::CurrentOffset));
    assert!(!c.readiness().current_offsets);
    // The amplifier comes back: the next measurement passes, the operator clears, it runs.
    for _ in 0..BOOT_CALLS {
        c.on_current_sample(&healthy(0));
    }
    assert!(c.readiness().current_offsets);
    assert_eq!(c.command(Command::ClearFaults), Ok(()));
    c.on_current_sample(&index_at(0));
    assert_eq!(c.command(Command::SetMode(Mode::Speed)), Ok(()));
    // In Calibrating the same check.
    let mut c = running(Mode::Speed);
    c.command(Command::SetMode(Mode::Disabled)).unwrap();
    c.command(Command::SetMode(Mode::Calibrating)).unwrap();
    for _ in 0..2000 {
        c.on_current_sample(&skewed);
        c.command(Command::Heartbeat).unwrap();
    }
    assert_eq!(c.fault(), Some(FaultCode::CurrentOffset));
}

#[test]
fn telemetry_reports_what_the_controller_sees() {
    let mut c = running(Mode::Pressure);
    c.command(Command::SetPressure { pa: 5e6 }).unwrap();
    for _ in 0..200 {
        c.on_current_sample(&healthy(0));
    }
    let t = c.telemetry();
    // 1001 power-up samples, then 201: the frame is stamped with the last one's instant,
    // the first at 0.
    assert!((t.t_s - 1201.0 / 20e3).abs() < 1e-9, "{}", t.t_s);
    assert!((t.p_pa - 3e6).abs() < PA_PER_LSB);
    assert!((t.udc_v - 280.0).abs() < 1e-3);
    assert_eq!(t.mode, Mode::Pressure);
    // The ramp (10 MPa/s) has moved the setpoint by 10 pressure-loop steps of 10 kPa.
    assert!(t.p_ref_pa > 3.05e6 && t.p_ref_pa < 3.15e6, "{}", t.p_ref_pa);
    // Pressure below the setpoint: the pump is asked to turn forward.
    assert!(t.speed_ref_rad_s > 0.0 && t.iq_ref_a > 0.0, "{t:?}");
}

/// xorshift32: a deterministic stream of arbitrary inputs without a dependency.
fn next(state: &mut u32) -> u32 {
    *state ^= *state << 13;
    *state ^= *state >> 17;
    *state ^= *state << 5;
    *state
}

#[test]
fn arbitrary_inputs_and_commands_never_panic_and_keep_the_outputs_sane() {
    // The ISR contract: infallible for any peripheral reading and any command sequence;
    // duties finite in [0, 1]; the bridge on only in an active mode without a latched fault.
    for (cfg_no, cfg) in [Config::nominal(), Config::nominal().with_pwm_hz(100e3)]
        .iter()
        .enumerate()
    {
        let mut c = Controller::new(cfg);
        // Powered up as on the board: offsets measured at rest, then the index passes.
        let rest = Measurements {
            adc_phase_current: [2048; 3],
            adc_dc_link: 2800,
            adc_pressure: pressure_counts(5e6),
            ..Measurements::default()
        };
        for _ in 0..2000 {
            c.on_current_sample(&rest);
        }
        c.on_current_sample(&Measurements {
            encoder_index: true,
            ..rest
        });
        let mut rng = 0x9e37_79b9u32 ^ cfg_no as u32;
        let mut count = 0u32;
        let (mut on, mut trips) = (0u32, 0u32);
        for k in 0..200_000u32 {
            let r = next(&mut rng);
            // Mostly plausible readings (so the drive runs for a while between faults),
            // sometimes anything at all.
            let wild = r % 2048 == 0;
            count = if wild {
                next(&mut rng)
            } else {
                (count + (r >> 8) % 7) % 10_000
            };
            let around = |rng: &mut u32, centre: u16, spread: u32| -> u16 {
                if wild {
                    next(rng) as u16
                } else {
                    let x = next(rng) % (2 * spread + 1);
                    (centre as u32 + x).saturating_sub(spread) as u16
                }
            };
            // Plausible phase currents sum to zero, as a star's do; wild ones anything.
            let (a, b) = (around(&mut rng, 2048, 200), around(&mut rng, 2048, 200));
            let c_phase = if wild {
                next(&mut rng) as u16
            } else {
                (3 * 2048u32).saturating_sub(a as u32 + b as u32) as u16
            };
            let m = Measurements {
                adc_phase_current: [a, b, c_phase],
                adc_dc_link: around(&mut rng, 2800, 100),
                adc_pressure: around(&mut rng, pressure_counts(5e6), 2000),
                encoder_count: count,
                encoder_index: count < 7 && r % 2 == 0,
                encoder_index_count: 0,
            };
            let out = c.on_current_sample(&m);
            for d in out.duties {
                assert!(
                    d.is_finite() && (0.0..=1.0).contains(&d),
                    "call {k}: duty {d}"
                );
            }
            if out.pwm_enabled {
                assert!(c.mode().is_active() && c.fault().is_none(), "call {k}");
                on += 1;
            }
            if c.fault().is_some() && c.telemetry().mode == Mode::Disabled {
                trips += 1;
            }
            let t = c.telemetry();
            assert!(t.t_s.is_finite() && t.iq_a.is_finite() && t.uq_v.is_finite());
            if k % 97 == 0 {
                let x = next(&mut rng);
                let f = f32::from_bits(next(&mut rng));
                let cmd = match x % 6 {
                    0 => Command::SetMode(Mode::from_code((x >> 8) as u8 % 4).unwrap()),
                    1 => Command::SetPressure { pa: f },
                    2 => Command::SetPressure {
                        pa: (x >> 8) as f32,
                    },
                    3 => Command::SetSpeed { rad_s: f },
                    4 => Command::ClearFaults,
                    _ => Command::Heartbeat,
                };
                let _ = c.command(cmd);
            } else if k % 7 == 0 {
                let _ = c.command(Command::Heartbeat);
            }
        }
        // The sweep is only worth something if it ran the loops and tripped faults.
        assert!(
            on > 10_000 && trips > 1_000,
            "bridge on {on} calls, faulted {trips}"
        );
    }
}

#[test]
fn an_unvalidated_configuration_does_not_panic() {
    // `new` is documented for validated configurations, but a wrong one must still not
    // take the MCU down from inside the ISR.
    let mut bad = Config::nominal();
    bad.rates.pwm_hz = 0.0;
    bad.rates.speed_loop_hz = f32::NAN;
    bad.rates.pressure_loop_hz = -1.0;
    bad.sensors.encoder_counts_per_rev = 0;
    bad.sensors.current_a_per_lsb = f32::INFINITY;
    bad.current.voltage_limit_v = f32::NAN;
    bad.speed.iq_limit_a = -3.0;
    bad.hydraulics.bulk_modulus_pa = 0.0;
    bad.limits.command_timeout_s = f32::NAN;
    let mut c = Controller::new(&bad);
    let _ = c.command(Command::SetMode(Mode::Pressure));
    for k in 0..2000u32 {
        let out = c.on_current_sample(&healthy(k * 3));
        for d in out.duties {
            assert!((0.0..=1.0).contains(&d), "call {k}: duty {d}");
        }
        let _ = c.telemetry();
    }
}

/// ADC counts of the phase currents for (`i_d`, `i_q`) [A] at `theta_e` [rad]: the
/// amplitude-invariant inverse Park and Clarke written out, at the nominal 100 A / 4096.
fn adc_for_dq(i_d: f32, i_q: f32, theta_e: f32) -> [u16; 3] {
    let tau3 = core::f32::consts::TAU / 3.0;
    [0.0, -tau3, tau3].map(|shift| {
        let th = theta_e + shift;
        let i = i_d * libm::cosf(th) - i_q * libm::sinf(th);
        libm::roundf(2048.0 + i / A_PER_LSB) as u16
    })
}

#[test]
fn a_board_waits_for_its_offsets_and_the_index_then_commutes_at_the_true_angle() {
    const N: u32 = 10_000;
    let mut rng = 0x6b43_a9b5u32;
    for case in 0..20 {
        // The encoder disk has its index at disk count 0; the counter started at
        // `boot_disk`. The table holds the rotor's offset from the index.
        let boot_disk = next(&mut rng) % N;
        let offset = (next(&mut rng) % 6283) as f32 * 1e-3;
        let counter = |disk: u32| (disk + N - boot_disk) % N;
        let mut cfg = Config::nominal();
        cfg.sensors.encoder_offset_rad = offset;
        let mut c = Controller::new(&cfg);
        c.on_current_sample(&healthy(0));
        for mode in [Mode::Calibrating, Mode::Speed, Mode::Pressure] {
            assert_eq!(
                c.command(Command::SetMode(mode)),
                Err(CommandError::Mode(ModeRefusal::NotReady(
                    NotReady::CurrentOffsets
                ))),
                "case {case}"
            );
            assert_eq!(c.telemetry().command_status, 9);
        }
        for _ in 1..BOOT_CALLS {
            assert!(!c.on_current_sample(&healthy(0)).pwm_enabled);
        }
        assert!(c.readiness().current_offsets, "case {case}");
        for mode in [Mode::Speed, Mode::Pressure] {
            assert_eq!(
                c.command(Command::SetMode(mode)),
                Err(CommandError::Mode(ModeRefusal::NotReady(
                    NotReady::RotorAngle
                ))),
                "case {case}"
            );
        }
        // Turn forwards by hand, 7 counts per period, until the index passes.
        let mut disk = boot_disk;
        loop {
            let next_disk = disk + 7;
            let index = next_disk % N < disk % N;
            disk = next_disk;
            c.on_current_sample(&Measurements {
                encoder_index: index,
                encoder_index_count: counter(0),
                ..healthy(counter(disk % N))
            });
            if index {
                break;
            }
        }
        assert_eq!(c.encoder_index_count(), Some(counter(0)), "case {case}");
        assert_eq!(c.command(Command::SetMode(Mode::Speed)), Ok(()));
        for _ in 0..PRECHARGE_CALLS {
            c.on_current_sample(&healthy(counter(disk % N)));
        }
        // 10 A on the q axis at the true electrical angle reads as i_q = 10 A, i_d = 0: the
        // current loop's Park uses the rotor's angle, wherever the counter started.
        let d = disk % N;
        let theta_e = 4.0 * core::f32::consts::TAU * d as f32 / N as f32 - offset;
        let out = c.on_current_sample(&Measurements {
            adc_phase_current: adc_for_dq(0.0, 10.0, theta_e),
            ..healthy(counter(d))
        });
        assert!(out.pwm_enabled);
        let t = c.telemetry();
        assert!(
            (t.iq_a - 10.0).abs() < 0.1 && t.id_a.abs() < 0.1,
            "case {case}: i_d {} i_q {}",
            t.id_a,
            t.iq_a
        );
        // The logged shaft angle is the angle from the index.
        let theta_m = core::f32::consts::TAU * d as f32 / N as f32;
        assert!((t.theta_m_rad - theta_m).abs() < 1e-4, "case {case}");
    }
}

#[test]
fn each_start_of_the_bridge_begins_with_the_bootstrap_precharge() {
    // 0.5 ms at 20 kHz: ten periods with all low sides on (duty 0 on every phase), then
    // the current loop, started from rest.
    let mut c = Controller::new(&Config::nominal());
    boot(&mut c);
    let start = |c: &mut Controller, mode: Mode| {
        c.command(Command::SetMode(mode)).unwrap();
        for k in 0..PRECHARGE_CALLS {
            let out = c.on_current_sample(&healthy(0));
            assert!(out.pwm_enabled, "{mode:?} period {k}");
            assert_eq!(out.duties, [0.0; 3], "{mode:?} period {k}");
            assert_eq!(c.telemetry().uq_v, 0.0);
        }
        let out = c.on_current_sample(&healthy(0));
        assert!(out.pwm_enabled);
        // At rest with zero references the modulator is centred again.
        for d in out.duties {
            assert!((d - 0.5).abs() < 0.05, "{:?}", out.duties);
        }
    };
    start(&mut c, Mode::Speed);
    // Speed to Pressure keeps the bridge on: no second precharge.
    c.command(Command::SetMode(Mode::Pressure)).unwrap();
    assert_ne!(c.on_current_sample(&healthy(0)).duties, [0.0; 3]);
    // After the bridge was off, again.
    c.command(Command::SetMode(Mode::Disabled)).unwrap();
    assert!(!c.on_current_sample(&healthy(0)).pwm_enabled);
    start(&mut c, Mode::Speed);
    // Calibrating: the offsets with the bridge off first, then the precharge right before
    // the alignment current.
    c.command(Command::SetMode(Mode::Disabled)).unwrap();
    c.on_current_sample(&healthy(0));
    c.command(Command::SetMode(Mode::Calibrating)).unwrap();
    for _ in 0..BOOT_CALLS {
        assert!(!c.on_current_sample(&healthy(0)).pwm_enabled);
        c.command(Command::Heartbeat).unwrap();
    }
    for _ in 0..PRECHARGE_CALLS {
        assert_eq!(c.on_current_sample(&healthy(0)).duties, [0.0; 3]);
    }
    assert_ne!(c.on_current_sample(&healthy(0)).duties, [0.0; 3]);
    // The simulator's configuration has none.
    let mut cfg = Config::nominal();
    cfg.calibration.bootstrap_precharge_s = 0.0;
    let mut c = Controller::new(&cfg);
    boot(&mut c);
    c.command(Command::SetMode(Mode::Speed)).unwrap();
    assert_ne!(c.on_current_sample(&healthy(0)).duties, [0.0; 3]);
}
