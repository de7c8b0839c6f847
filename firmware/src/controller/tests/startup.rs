//! Start-up and calibration: the power-up offset measurement, the encoder's reference at
//! the index, the bootstrap precharge at each start of the bridge, calibration and its
//! offset fault, and the telemetry of what the controller sees.

use super::*;
use crate::config::Config;
use crate::io::Measurements;
use crate::parameters::ParamId;
use crate::supervisor::{FaultCode, Mode, ModeRefusal, NotReady, Readiness};

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
