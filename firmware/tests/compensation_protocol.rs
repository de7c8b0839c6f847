//! The torque feed-forward end to end on the host, through the code the MCU application
//! runs: a table loaded over CAN and committed, refused naming the bound when its
//! amplitude (or a scale, or a limit) breaks the limit, saved and found after a reboot,
//! refused at boot with fault 21 when its stored record is wrong (the drive then runs
//! uncompensated), and acting in Speed and Pressure only; the speed modulation against the
//! pump's flow ripple likewise bounded and acting in Speed and Pressure only.

mod common;

use common::{power_up, RamFlash};
use firmware::can_protocol::{
    decode_command, encode_command, encode_set_parameter, NodeId, RejectReason, Reply, Request,
};
use firmware::can_server::{serve, Response};
use firmware::compensation::record::{crc_of, source};
use firmware::compensation::{Table, BINS, CHANNELS};
use firmware::param_store::{boot, BootOutcome, ParamStore, TABLE_AT, TABLE_LEN};
use firmware::parameters::ParamId;
use firmware::{Command, Config, Controller, FaultCode, Measurements, Mode};

fn node() -> NodeId {
    NodeId::new(1).expect("node")
}

/// A table whose constant channel is a 72/rev line of `amp` A (LSB 2^−19: ±0.0625 A),
/// the per-pressure channel `cp` LSBs of 2^−44 A/Pa, the per-current one `ci` A/A (LSB
/// 2^−17: ±0.25 A/A), both flat.
fn table(amp: f32, cp: i16, ci: f32) -> Table {
    let mut raw = Box::new([[0i16; CHANNELS]; BINS]);
    for (b, r) in raw.iter_mut().enumerate() {
        let th = b as f32 * core::f32::consts::TAU / BINS as f32;
        *r = [
            (amp * libm::sinf(72.0 * th) * 524_288.0) as i16,
            cp,
            (ci * 131_072.0) as i16,
        ];
    }
    Table::from_raw([19, 44, 17], &raw).expect("exponents in range")
}

/// Sends the loading frames of `t` (header, bins, commit) as the host prints them; the
/// commit's reply.
fn load(c: &mut Controller, t: &Table) -> Response {
    let mut frames = vec![encode_command(
        &Request::CompensationHeader {
            exponents: t.exponents(),
            bins: BINS as u16,
        },
        node(),
    )];
    for b in 0..BINS {
        frames.push(encode_command(
            &Request::CompensationBin {
                bin: b as u16,
                raw: t.raw(b),
            },
            node(),
        ));
    }
    for f in frames {
        let r = serve(&decode_command(&f, node()).expect("decodes"), c);
        assert!(matches!(r, Response::Ack(0x25)), "{r:?}");
    }
    let commit = encode_command(&Request::CompensationCommit { crc: crc_of(t) }, node());
    serve(&decode_command(&commit, node()).expect("decodes"), c)
}

fn set(c: &mut Controller, id: ParamId, v: f32) -> Response {
    let f = encode_set_parameter(id, v, node());
    serve(&decode_command(&f, node()).expect("decodes"), c)
}

#[test]
fn an_over_limit_amplitude_is_refused_naming_the_bound() {
    let mut c = Controller::new(&Config::nominal());
    // 0.05 A + 0.05 A/A over the 30 A q-current limit: 1.55 A, under the 3 A limit.
    let ok = table(0.05, 0, 0.05);
    assert!(matches!(load(&mut c, &ok), Response::Ack(0x26)));
    let bound = c.compensation().amplitude_bound();
    assert!((bound - 1.55).abs() < 2e-3, "{bound}");
    // Scale 2 would reach 3.1 A: refused, the bound is the largest scale, 3 A / bound.
    match set(&mut c, ParamId::CompensationScale, 2.0) {
        Response::Reply(Reply::Reject(r)) => {
            assert_eq!(r.reason, RejectReason::AboveMaximum);
            assert_eq!(r.parameter, ParamId::CompensationScale.code());
            let max = r.si_bound().expect("an SI bound");
            assert!((max - 3.0 / bound).abs() < 1e-4, "{max}");
        }
        other => panic!("{other:?}"),
    }
    // Lowering the limit under the table's amplitude: refused, the bound is the amplitude.
    match set(&mut c, ParamId::CompensationMaxCurrent, 1.0) {
        Response::Reply(Reply::Reject(r)) => {
            assert_eq!(r.reason, RejectReason::BelowMinimum);
            assert!((r.si_bound().unwrap() - bound).abs() < 1e-5);
        }
        other => panic!("{other:?}"),
    }
    // With 0.08 A/A, raising the q-current limit from 30 A to 44 A would take the
    // per-current share to 3.5 A: refused, the bound is the largest limit, (3 − 0.05)/0.08.
    assert!(matches!(
        load(&mut c, &table(0.05, 0, 0.08)),
        Response::Ack(0x26)
    ));
    match set(&mut c, ParamId::SpeedIqLimit, 44.0) {
        Response::Reply(Reply::Reject(r)) => {
            assert_eq!(r.reason, RejectReason::AboveMaximum);
            let max = r.si_bound().unwrap();
            assert!((max - 2.95 / 0.08).abs() < 0.1, "{max}");
        }
        other => panic!("{other:?}"),
    }
    // 0.06 A + 0.12 A/A over 30 A is 3.66 A: its commit is refused naming the 3 A limit,
    // and no table is left.
    let big = table(0.06, 0, 0.12);
    match load(&mut c, &big) {
        Response::Reply(Reply::Reject(r)) => {
            assert_eq!(r.reason, RejectReason::AboveMaximum);
            assert_eq!(r.function, 0x26);
            assert_eq!(r.si_bound(), Some(3.0));
        }
        other => panic!("{other:?}"),
    }
    assert!(c.compensation().table().is_zero());
}

#[test]
fn the_feed_forward_acts_in_speed_and_pressure_only() {
    let mut c = Controller::new(&Config::nominal());
    assert!(matches!(
        load(&mut c, &table(0.05, 0, 0.0)),
        Response::Ack(0x26)
    ));
    assert!(matches!(
        set(&mut c, ParamId::CompensationEnabled, 1.0),
        Response::Reply(Reply::Parameter { .. })
    ));
    // The encoder at 1/288 of a revolution: a quarter of a cogging cycle, the line's peak.
    let m = Measurements {
        adc_dc_link: 2800,
        adc_pressure: 6554 + 6291,
        encoder_count: 10_000 / 288,
        ..Measurements::default()
    };
    power_up(&mut c);
    for mode in [Mode::Disabled, Mode::Calibrating, Mode::Speed] {
        c.command(Command::SetMode(mode)).expect("mode");
        for _ in 0..20 {
            c.on_current_sample(&m);
        }
        let ff = c.compensation_current();
        match mode {
            Mode::Speed => assert!((ff - 0.05).abs() < 0.005, "{ff}"),
            _ => assert_eq!(ff, 0.0, "{mode:?}"),
        }
        c.command(Command::SetMode(Mode::Disabled))
            .expect("disabled");
    }
    // Disabled by its parameter: nothing, in Speed too.
    set(&mut c, ParamId::CompensationEnabled, 0.0);
    c.command(Command::SetMode(Mode::Speed)).expect("speed");
    c.on_current_sample(&m);
    assert_eq!(c.compensation_current(), 0.0);
    // Cleared: the table is gone.
    set(&mut c, ParamId::CompensationClear, 1.0);
    assert!(c.compensation().table().is_zero());
    assert_eq!(c.parameter(ParamId::CompensationClear), 0.0);
}

/// The rejection of `r`: its reason and SI bound.
fn rejected(r: Response) -> (RejectReason, f32) {
    match r {
        Response::Reply(Reply::Reject(r)) => (r.reason, r.si_bound().expect("an SI bound")),
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_flow_modulation_depth_is_refused_above_its_bound_naming_it() {
    let mut c = Controller::new(&Config::nominal());
    let accepted = |r: Response| matches!(r, Response::Reply(Reply::Parameter { .. }));
    assert!(accepted(set(&mut c, ParamId::CompensationFlowPistons, 9.0)));
    assert!(accepted(set(&mut c, ParamId::CompensationFlowRatio, 0.06)));
    // 1 and 2 pistons are no cosine cap: refused.
    assert!(!accepted(set(
        &mut c,
        ParamId::CompensationFlowPistons,
        2.0
    )));
    // A ratio of 0.2 over the default depth limit 0.1: refused, the bound is 0.1.
    let (why, max) = rejected(set(&mut c, ParamId::CompensationFlowRatio, 0.2));
    assert_eq!(why, RejectReason::AboveMaximum);
    assert!((max - 0.1).abs() < 1e-6, "{max}");
    // Scale 2 would make the depth 0.12: the largest scale is 0.1/0.06.
    let (why, max) = rejected(set(&mut c, ParamId::CompensationScale, 2.0));
    assert_eq!(why, RejectReason::AboveMaximum);
    assert!((max - 0.1 / 0.06).abs() < 1e-4, "{max}");
    // The limit under the depth: the smallest limit is the depth, 0.06.
    let (why, min) = rejected(set(&mut c, ParamId::CompensationMaxFlowRatio, 0.05));
    assert_eq!(why, RejectReason::BelowMinimum);
    assert!((min - 0.06).abs() < 1e-6, "{min}");
    assert_eq!(c.parameter(ParamId::CompensationFlowRatio), 0.06);
    assert!(!c.compensation().flow().is_active(), "off until enabled");
    assert!(accepted(set(&mut c, ParamId::CompensationEnabled, 1.0)));
    assert!(c.compensation().flow().is_active(), "on without a table");
}

#[test]
fn the_flow_modulation_acts_in_speed_and_pressure_only() {
    // Two drives fed the same samples, one modulating a 9-piston pump's ripple (at 20 %
    // peak-to-peak, so the difference shows), the other not: the q reference differs in
    // Speed only (Pressure takes the same path), never in Disabled or Calibrating.
    let mut cfg = Config::nominal();
    cfg.compensation.max_flow_ratio = 0.5;
    let mut on = Controller::new(&cfg);
    let mut off = Controller::new(&cfg);
    for (id, v) in [
        (ParamId::CompensationFlowPistons, 9.0),
        (ParamId::CompensationFlowRatio, 0.2),
        (ParamId::CompensationEnabled, 1.0),
    ] {
        on.command(Command::SetParameter { id, value: v })
            .expect("accepted");
    }
    let m = Measurements {
        adc_dc_link: 2800,
        adc_pressure: 6554 + 6291,
        encoder_count: 10_000 / 100,
        ..Measurements::default()
    };
    power_up(&mut on);
    power_up(&mut off);
    for mode in [Mode::Disabled, Mode::Calibrating, Mode::Speed] {
        for c in [&mut on, &mut off] {
            c.command(Command::SetSpeed { rad_s: 5.7 }).expect("speed");
            c.command(Command::SetMode(mode)).expect("mode");
        }
        for _ in 0..40 {
            on.on_current_sample(&m);
            off.on_current_sample(&m);
            let (a, b) = (on.telemetry().iq_ref_a, off.telemetry().iq_ref_a);
            match mode {
                Mode::Speed => {}
                _ => assert_eq!(a, b, "{mode:?}"),
            }
        }
        let (a, b) = (on.telemetry().iq_ref_a, off.telemetry().iq_ref_a);
        if mode == Mode::Speed {
            assert!((a - b).abs() > 1e-3, "{a} vs {b}");
        }
        for c in [&mut on, &mut off] {
            c.command(Command::SetMode(Mode::Disabled))
                .expect("disabled");
        }
    }
}

const SLOT: u32 = 4096;

/// Boots a controller from `flash` as the application does; the controller and whether
/// the table was loaded.
fn reboot(flash: RamFlash) -> (Controller, bool) {
    let mut store = ParamStore::new(flash, 0, SLOT, SLOT).expect("store");
    let mut c = Controller::new(&Config::nominal());
    let outcome = boot(&mut store, |v| c.load_parameters(v).is_ok());
    assert!(matches!(outcome, BootOutcome::Stored { .. }), "{outcome:?}");
    let read = |at: usize, buf: &mut [u8]| store.read_table(at, buf);
    let loaded = c.load_compensation_record(TABLE_LEN, read).is_ok();
    if !loaded {
        c.report_compensation_invalid();
    }
    (c, loaded)
}

#[test]
fn a_table_loaded_over_can_and_saved_is_there_after_a_reboot_and_a_bad_one_is_refused() {
    let mut c = Controller::new(&Config::nominal());
    let t = table(0.04, -120, 0.007);
    assert!(matches!(load(&mut c, &t), Response::Ack(0x26)));
    set(&mut c, ParamId::CompensationEnabled, 1.0);
    let save = encode_command(&Request::SaveParameters, node());
    let Response::Save(values) = serve(&decode_command(&save, node()).unwrap(), &mut c) else {
        panic!("save not served");
    };
    let mut store =
        ParamStore::new(RamFlash(vec![0xFF; 2 * SLOT as usize]), 0, SLOT, SLOT).unwrap();
    store
        .save(&values, source(c.compensation().table()))
        .expect("saved");
    let mem = store.into_inner().0;

    let (rebooted, loaded) = reboot(RamFlash(mem.clone()));
    assert!(loaded);
    assert_eq!(rebooted.compensation().table(), &t);
    assert!(rebooted.compensation().is_active());
    assert_eq!(rebooted.fault(), None);

    // The stored table's CRC, version and size broken in turn: refused at boot with fault
    // 19, the parameters still loaded, the feed-forward off though enabled.
    let corrupt = |at: usize, xor: u8| {
        let mut m = mem.clone();
        m[TABLE_AT + at] ^= xor;
        m
    };
    for (what, m) in [
        ("a value (CRC)", corrupt(400, 0x01)),
        ("the version", corrupt(4, 0x03)),
        ("the bin count", corrupt(7, 0x01)),
    ] {
        let (c, loaded) = reboot(RamFlash(m));
        assert!(!loaded, "{what}");
        assert_eq!(
            c.fault(),
            Some(FaultCode::CompensationTableInvalid),
            "{what}"
        );
        assert_eq!(c.parameter(ParamId::CompensationEnabled), 1.0, "{what}");
        assert!(!c.compensation().is_active(), "{what}");
        assert!(c.compensation().table().is_zero(), "{what}");
    }
}
