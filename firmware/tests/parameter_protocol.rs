//! The parameter protocol end to end on the host: frames built by the host-side encoder,
//! decoded and served by the drive-side code the MCU application runs
//! ([`firmware::can_server::serve`]), replies decoded by the host again. Every parameter's
//! set/get round trip, every out-of-range set refused naming the parameter and the bound,
//! and a table set over CAN, saved, and found again after a reboot.

mod common;

use common::{power_up, RamFlash};
use firmware::can_protocol::{
    decode_command, decode_reply, encode_command, encode_get_parameter, encode_reply,
    encode_set_parameter, Frame, NodeId, RejectReason, Rejection, Reply, Request,
};
use firmware::can_server::{serve, Response};
use firmware::compensation::record::source;
use firmware::param_store::{boot, boot_config, BootOutcome, ParamStore};
use firmware::parameters::{ParamId, COUNT};
use firmware::{Command, Config, Controller, Mode};

const NODE: u8 = 3;

fn node() -> NodeId {
    NodeId::new(NODE).expect("node")
}

/// The drive: decodes a frame, serves it, encodes what it answers (None: silent).
fn drive(c: &mut Controller, frame: &Frame) -> Option<Frame> {
    let reply = match decode_command(frame, node()) {
        Ok(request) => match serve(&request, c) {
            Response::Reply(r) => r,
            Response::Ack(_) | Response::Silent | Response::Save(_) => return None,
        },
        Err(e) => Reply::Reject(Rejection::for_decode_error(&e)?),
    };
    Some(encode_reply(&reply, node()))
}

/// Host sends `frame`, returns the decoded answer.
fn ask(c: &mut Controller, frame: &Frame) -> Reply {
    let answer = drive(c, frame).expect("the drive answers");
    decode_reply(&answer, node()).expect("a well-formed reply")
}

/// A value inside the parameter's bounds, other than its default, that the rest of the
/// nominal configuration accepts.
fn other_valid_value(p: ParamId) -> f32 {
    let d = p.default_value();
    let candidates = [
        d * 1.1,
        d * 0.9,
        d + 1.0,
        0.5 * (p.min() + p.max()),
        p.max(),
        // `compensation.flow_ratio`: a depth within the default `max_flow_ratio`.
        p.min() + 0.1 * (p.max() - p.min()),
    ];
    candidates
        .into_iter()
        .find(|v| {
            *v != d && p.min() <= *v && *v <= p.max() && p.set(&mut Config::nominal(), *v).is_ok()
        })
        .unwrap_or_else(|| panic!("{p}: no valid test value"))
}

#[test]
fn every_parameter_round_trips_bit_exactly() {
    let mut c = Controller::new(&Config::nominal());
    // An action (`compensation.clear`) acts and reads 0: not a stored value.
    for p in ParamId::ALL.into_iter().filter(|p| !p.is_action()) {
        let v = other_valid_value(p);
        let set = ask(&mut c, &encode_set_parameter(p, v, node()));
        assert_eq!(set, Reply::Parameter { id: p, value: v }, "{p}");
        let got = ask(&mut c, &encode_get_parameter(p, node()));
        match got {
            Reply::Parameter { id, value } => {
                assert_eq!(id, p);
                assert_eq!(value.to_bits(), v.to_bits(), "{p}");
            }
            other => panic!("{p}: {other:?}"),
        }
        assert_eq!(c.parameter(p), v);
        // Back to the default so the next parameter is set on the nominal table.
        ask(&mut c, &encode_set_parameter(p, p.default_value(), node()));
    }
    assert_eq!(*c.config(), Config::nominal());
}

#[test]
fn every_out_of_range_set_is_refused_naming_the_parameter_and_the_bound() {
    let mut c = Controller::new(&Config::nominal());
    for p in ParamId::ALL {
        let below = if p.min() == 0.0 { -1e-6 } else { p.min() * 0.5 };
        for (value, reason, bound) in [
            (below, RejectReason::BelowMinimum, p.min()),
            (p.max() * 2.0, RejectReason::AboveMaximum, p.max()),
        ] {
            let reply = ask(&mut c, &encode_set_parameter(p, value, node()));
            let Reply::Reject(r) = reply else {
                panic!("{p} = {value} accepted: {reply:?}");
            };
            assert_eq!(r.function, 0x20, "{p}");
            assert_eq!(r.reason, reason, "{p} = {value}");
            assert_eq!(r.parameter, p.code(), "{p}");
            assert_eq!(r.si_bound().map(f32::to_bits), Some(bound.to_bits()), "{p}");
        }
        let nan = ask(&mut c, &encode_set_parameter(p, f32::NAN, node()));
        assert!(
            matches!(nan, Reply::Reject(r) if r.reason == RejectReason::Invalid && r.parameter == p.code()),
            "{p}: {nan:?}"
        );
        // Nothing was changed by the refusals.
        assert_eq!(c.parameter(p), p.default_value(), "{p}");
    }
}

#[test]
fn a_value_in_conflict_with_another_is_refused_as_invalid() {
    let mut c = Controller::new(&Config::nominal());
    // 50 A is within speed.iq_limit_a's bounds but above the 45 A over-current trip.
    let reply = ask(
        &mut c,
        &encode_set_parameter(ParamId::SpeedIqLimit, 50.0, node()),
    );
    assert!(
        matches!(reply, Reply::Reject(r) if r.reason == RejectReason::Invalid && r.parameter == 13),
        "{reply:?}"
    );
    assert_eq!(c.parameter(ParamId::SpeedIqLimit), 30.0);
}

#[test]
fn unknown_parameter_ids_are_rejected_with_the_id() {
    let mut c = Controller::new(&Config::nominal());
    for code in [0u8, 6, 99, 255] {
        let frame = Frame::new(0x213, &[code]).expect("frame");
        let reply = ask(&mut c, &frame);
        let Reply::Reject(r) = reply else {
            panic!("{code}: {reply:?}");
        };
        assert_eq!(
            (r.function, r.reason, r.parameter),
            (0x21, RejectReason::UnknownCode, code)
        );
    }
}

#[test]
fn the_set_parameter_frame_is_the_documented_layout() {
    // 0x200 + node; id 10 (speed.kp); 0.25 = 0x3E800000 little endian.
    let f = encode_set_parameter(ParamId::SpeedKp, 0.25, node());
    assert_eq!(f.id(), 0x203);
    assert_eq!(f.payload(), &[10, 0x00, 0x00, 0x80, 0x3E]);
    let f = encode_get_parameter(ParamId::AbsorberPrechargePa, node());
    assert_eq!((f.id(), f.payload()), (0x213, &[34u8][..]));
    // Reply: 0x1A0 + node, id, f32, three reserved zero bytes.
    let r = encode_reply(
        &Reply::Parameter {
            id: ParamId::SpeedKp,
            value: 0.25,
        },
        node(),
    );
    assert_eq!(r.id(), 0x1A3);
    assert_eq!(r.payload(), &[10, 0x00, 0x00, 0x80, 0x3E, 0, 0, 0]);
    // Printed for `cansend can0 …`.
    assert_eq!(f_text(ParamId::SpeedKp, 0.25), "203#0A0000803E");
    assert_eq!(
        encode_command(&Request::SaveParameters, node()).to_string(),
        "223#"
    );
}

fn f_text(id: ParamId, value: f32) -> String {
    encode_set_parameter(id, value, node()).to_string()
}

#[test]
fn a_table_set_over_can_and_saved_is_there_after_a_reboot() {
    let mut c = Controller::new(&Config::nominal());
    let mut store = ParamStore::new(RamFlash(vec![0xFF; 8192]), 0, 4096, 4096).expect("store");
    ask(&mut c, &encode_set_parameter(ParamId::SpeedKp, 0.2, node()));
    ask(
        &mut c,
        &encode_set_parameter(ParamId::AbsorberPrechargePa, 2.5e6, node()),
    );
    // Not while running.
    power_up(&mut c);
    c.command(Command::SetMode(Mode::Speed))
        .expect("speed mode");
    let save = encode_command(&Request::SaveParameters, node());
    let refused = ask(&mut c, &save);
    assert!(
        matches!(refused, Reply::Reject(r) if r.reason == RejectReason::NotAllowed && r.si_bound() == Some(0.0)),
        "{refused:?}"
    );
    c.command(Command::SetMode(Mode::Disabled))
        .expect("disabled");
    let request = decode_command(&save, node()).expect("decodes");
    let Response::Save(values) = serve(&request, &mut c) else {
        panic!("save not served");
    };
    assert_eq!(values.len(), COUNT);
    store
        .save(&values, source(c.compensation().table()))
        .expect("saved");

    // Reboot as the application does: the nominal controller, then the stored table.
    let mut rebooted = Controller::new(&Config::nominal());
    let outcome = boot(&mut store, |v| rebooted.load_parameters(v).is_ok());
    assert_eq!(outcome, BootOutcome::Stored { sequence: 1 });
    let (cfg, _) = boot_config(&mut store, &Config::nominal());
    assert_eq!(*rebooted.config(), cfg);
    for (p, v) in [
        (ParamId::SpeedKp, 0.2),
        (ParamId::AbsorberPrechargePa, 2.5e6),
    ] {
        assert_eq!(
            ask(&mut rebooted, &encode_get_parameter(p, node())),
            Reply::Parameter { id: p, value: v }
        );
    }
}

#[test]
fn a_commission_frame_starts_the_commissioning_sequence() {
    // 0x240 + node, no payload, as `cansend can0 243#` sends it.
    let frame = encode_command(&Request::Commission, node());
    assert_eq!(frame.to_string(), "243#");
    assert_eq!(decode_command(&frame, node()), Ok(Request::Commission));
    let mut c = Controller::new(&Config::nominal());
    power_up(&mut c);
    assert_eq!(c.mode(), Mode::Disabled);
    match serve(&Request::Commission, &mut c) {
        Response::Ack(code) => assert_eq!(code, 0x24),
        other => panic!("a commission request is acknowledged, got {other:?}"),
    }
    assert_eq!(c.mode(), Mode::Calibrating);
    // A frame with a payload is not a Commission command.
    let bad = Frame::new(0x243, &[0]).unwrap();
    assert!(decode_command(&bad, node()).is_err());
}
