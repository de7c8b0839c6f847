//! Codec tests: layouts written out by hand from the module documentation, round trips,
//! and every malformed frame refused with its reason.

use super::*;
use crate::controller::{Command, CommandError};
use crate::step_test::StepLoop;
use crate::supervisor::{FaultCode, Mode, ModeRefusal, NotReady};

fn node(n: u8) -> NodeId {
    NodeId::new(n).expect("valid node")
}

#[test]
fn command_layout_matches_the_documented_table() {
    // Bytes written out by hand from the module documentation.
    let f = encode_command(&Request::SetPressure { pa: 5_000_000 }, node(3));
    assert_eq!(f.id(), 0x113);
    assert_eq!(f.payload(), &[0x40, 0x4B, 0x4C, 0x00]);
    let f = encode_command(&Request::SetSpeed { mrad_s: -1500 }, node(0));
    assert_eq!(f.id(), 0x120);
    assert_eq!(f.payload(), &[0x24, 0xFA, 0xFF, 0xFF]);
    let f = encode_command(&Request::SetMode(Mode::Pressure), node(15));
    assert_eq!((f.id(), f.payload()), (0x10F, &[3u8][..]));
    assert_eq!(encode_command(&Request::ClearFaults, node(1)).id(), 0x131);
    assert_eq!(
        encode_command(&Request::Heartbeat, node(1)).payload(),
        &[] as &[u8]
    );
}

#[test]
fn every_command_round_trips() {
    let requests = [
        Request::SetMode(Mode::Disabled),
        Request::SetMode(Mode::Calibrating),
        Request::SetMode(Mode::Speed),
        Request::SetMode(Mode::Pressure),
        Request::SetPressure { pa: 0 },
        Request::SetPressure { pa: i32::MIN },
        Request::SetPressure { pa: i32::MAX },
        Request::SetSpeed { mrad_s: -314_159 },
        Request::ClearFaults,
        Request::Heartbeat,
    ];
    for n in [0, 7, NODE_MAX] {
        for r in requests {
            let frame = encode_command(&r, node(n));
            assert_eq!(decode_command(&frame, node(n)), Ok(r));
        }
    }
}

#[test]
fn si_constructors_round_to_the_wire_resolution() {
    assert_eq!(
        Request::pressure_from_pa(3.0e6),
        Ok(Request::SetPressure { pa: 3_000_000 })
    );
    assert_eq!(
        Request::speed_from_rad_s(-12.3456),
        Ok(Request::SetSpeed { mrad_s: -12_346 })
    );
    let back = Request::SetSpeed { mrad_s: 12_345 }
        .speed_rad_s()
        .unwrap_or(f32::NAN);
    assert!((back - 12.345).abs() < 1e-5, "{back}");
    assert!(Request::pressure_from_pa(f32::NAN).is_err());
    assert!(Request::pressure_from_pa(3.0e9).is_err());
    assert!(Request::speed_from_rad_s(f32::INFINITY).is_err());
}

#[test]
fn malformed_commands_are_rejected_with_the_reason() {
    let me = node(2);
    let f = Frame::new(0x112, &[1, 2, 3]).unwrap();
    let err = decode_command(&f, me).unwrap_err();
    assert_eq!(
        err,
        DecodeError::WrongLength {
            function: Function::SetPressure,
            expected: 4,
            got: 3
        }
    );
    assert_eq!(
        Rejection::for_decode_error(&err),
        Some(Rejection {
            function: 0x11,
            reason: RejectReason::WrongLength,
            bound: 4,
            parameter: 0,
        })
    );

    let f = Frame::new(0x132, &[0]).unwrap();
    assert!(matches!(
        decode_command(&f, me),
        Err(DecodeError::WrongLength {
            expected: 0,
            got: 1,
            ..
        })
    ));

    let f = Frame::new(0x102, &[4]).unwrap();
    let err = decode_command(&f, me).unwrap_err();
    assert_eq!(err, DecodeError::UnknownMode { code: 4 });
    assert_eq!(
        Rejection::for_decode_error(&err).map(|r| (r.reason, r.bound)),
        Some((RejectReason::UnknownMode, 3))
    );

    let f = Frame::new(0x152, &[]).unwrap();
    let err = decode_command(&f, me).unwrap_err();
    assert_eq!(err, DecodeError::UnknownFunction { id: 0x152 });
    assert_eq!(
        Rejection::for_decode_error(&err).map(|r| r.function),
        Some(0x15)
    );

    // Another node's command is ignored silently; so is a reply seen on the bus.
    let f = Frame::new(0x113, &[0; 4]).unwrap();
    let err = decode_command(&f, me).unwrap_err();
    assert_eq!(err, DecodeError::OtherNode { node: 3 });
    assert_eq!(Rejection::for_decode_error(&err), None);
    let f = Frame::new(0x182, &[0; 8]).unwrap();
    assert_eq!(
        decode_command(&f, me),
        Err(DecodeError::UnknownFunction { id: 0x182 })
    );
}

#[test]
fn frame_and_node_bounds_are_checked() {
    assert_eq!(
        Frame::new(0x800, &[]),
        Err(DecodeError::IdentifierTooLarge { id: 0x800 })
    );
    assert_eq!(
        Frame::new(0x100, &[0; 9]),
        Err(DecodeError::PayloadTooLong { len: 9 })
    );
    assert_eq!(
        NodeId::new(16),
        Err(DecodeError::NodeOutOfRange { node: 16 })
    );
    assert!(Frame::new(0x7FF, &[0; 8]).is_ok());
}

#[test]
fn status_layout_and_round_trip() {
    // 5.2 MPa -> 5200 kPa = 0x1450; -31.4 rad/s -> -314 = 0xFEC6.
    let s = Status::from_si(
        Mode::Pressure,
        4,
        5.2e6,
        -31.4,
        Function::SetPressure.code(),
        200,
    );
    let f = encode_reply(&Reply::Status(s), node(5));
    assert_eq!(f.id(), 0x185);
    assert_eq!(f.payload(), &[3, 4, 0x50, 0x14, 0xC6, 0xFE, 0x11, 200]);
    assert_eq!(decode_reply(&f, node(5)), Ok(Reply::Status(s)));
}

#[test]
fn status_fields_saturate() {
    let s = Status::from_si(Mode::Speed, 0, 1.0e9, f32::NAN, NO_COMMAND, 0);
    assert_eq!((s.pressure_kpa, s.speed_drad_s), (i16::MAX, 0));
    let s = Status::from_si(Mode::Speed, 0, -1.0e9, -1.0e6, NO_COMMAND, 0);
    assert_eq!((s.pressure_kpa, s.speed_drad_s), (i16::MIN, i16::MIN));
}

#[test]
fn reject_layout_and_round_trip() {
    // Pressure above a 16 MPa maximum: bound 16_000_000 = 0x00F42400.
    let r = Rejection {
        function: 0x11,
        reason: RejectReason::AboveMaximum,
        bound: 16_000_000,
        parameter: 0,
    };
    let f = encode_reply(&Reply::Reject(r), node(0));
    assert_eq!(f.id(), 0x190);
    assert_eq!(f.payload(), &[0x11, 2, 0x00, 0x24, 0xF4, 0x00, 0, 0]);
    assert_eq!(decode_reply(&f, node(0)), Ok(Reply::Reject(r)));
    for code in 1..=9 {
        let reason = RejectReason::from_code(code).unwrap();
        assert_eq!(reason.code(), code);
    }
}

#[test]
fn diagnostics_layout_and_round_trip() {
    let d = Diagnostics {
        stack_peak_bytes: 0x0000_0A64,
        stack_size_bytes: 0x0001_C180,
    };
    let f = encode_reply(&Reply::Diagnostics(d), node(3));
    assert_eq!(f.id(), 0x1B3);
    // u32 little endian: 2660 bytes of 115 072.
    assert_eq!(f.payload(), &[0x64, 0x0A, 0, 0, 0x80, 0xC1, 0x01, 0]);
    assert_eq!(decode_reply(&f, node(3)), Ok(Reply::Diagnostics(d)));
    // Not a command: another node's diagnostics or this node's are never served.
    assert!(decode_command(&f, node(3)).is_err());
}

#[test]
fn malformed_replies_are_rejected() {
    let me = node(1);
    assert!(matches!(
        decode_reply(&Frame::new(0x181, &[0; 7]).unwrap(), me),
        Err(DecodeError::WrongReplyLength { got: 7 })
    ));
    assert_eq!(
        decode_reply(
            &Frame::new(0x191, &[0x11, 10, 0, 0, 0, 0, 0, 0]).unwrap(),
            me
        ),
        Err(DecodeError::UnknownReason { code: 10 })
    );
    assert_eq!(
        decode_reply(
            &Frame::new(0x191, &[0x11, 1, 0, 0, 0, 0, 0, 1]).unwrap(),
            me
        ),
        Err(DecodeError::ReservedNotZero)
    );
    assert_eq!(
        decode_reply(&Frame::new(0x182, &[0; 8]).unwrap(), me),
        Err(DecodeError::OtherNode { node: 2 })
    );
    assert_eq!(
        decode_reply(&Frame::new(0x111, &[0; 4]).unwrap(), me),
        Err(DecodeError::UnknownFunction { id: 0x111 })
    );
}

#[test]
fn requests_map_to_core_commands_in_si_units() {
    assert_eq!(
        Request::SetPressure { pa: 4_500_000 }.to_command(),
        Some(Command::SetPressure { pa: 4.5e6 })
    );
    assert_eq!(
        Request::SetSpeed { mrad_s: -2_500 }.to_command(),
        Some(Command::SetSpeed { rad_s: -2.5 })
    );
    assert_eq!(
        Request::SetMode(Mode::Speed).to_command(),
        Some(Command::SetMode(Mode::Speed))
    );
    assert_eq!(Request::Heartbeat.to_command(), Some(Command::Heartbeat));
    assert_eq!(
        Request::ClearFaults.to_command(),
        Some(Command::ClearFaults)
    );
}

#[test]
fn refusals_name_the_violated_bound() {
    let range = CommandError::PressureOutOfRange {
        min_pa: 0.0,
        max_pa: 18e6,
    };
    let r = Rejection::for_command_error(&Request::SetPressure { pa: 20_000_000 }, &range);
    assert_eq!(
        r,
        Rejection {
            function: 0x11,
            reason: RejectReason::AboveMaximum,
            bound: 18_000_000,
            parameter: 0,
        }
    );
    let r = Rejection::for_command_error(&Request::SetPressure { pa: -5 }, &range);
    assert_eq!((r.reason, r.bound), (RejectReason::BelowMinimum, 0));

    let speed = CommandError::SpeedOutOfRange { max_rad_s: 200.0 };
    let r = Rejection::for_command_error(&Request::SetSpeed { mrad_s: -250_000 }, &speed);
    assert_eq!(
        (r.function, r.reason, r.bound),
        (0x12, RejectReason::BelowMinimum, -200_000)
    );
    let r = Rejection::for_command_error(&Request::SetSpeed { mrad_s: 250_000 }, &speed);
    assert_eq!((r.reason, r.bound), (RejectReason::AboveMaximum, 200_000));

    // Over-pressure is fault code 4 in the supervisor's table.
    let blocked = CommandError::CausePresent(FaultCode::OverPressure);
    let r = Rejection::for_command_error(&Request::ClearFaults, &blocked);
    assert_eq!(
        (r.function, r.reason, r.bound),
        (0x13, RejectReason::NotAllowed, 4)
    );
    let transition = CommandError::Mode(ModeRefusal::Transition {
        from: Mode::Speed,
        to: Mode::Calibrating,
    });
    let r = Rejection::for_command_error(&Request::SetMode(Mode::Calibrating), &transition);
    assert_eq!(
        (r.function, r.reason, r.bound),
        (0x10, RejectReason::NotAllowed, 0)
    );
    // Not ready: reason 9, bound 2 for an unknown rotor angle (module documentation).
    let not_ready = CommandError::Mode(ModeRefusal::NotReady(NotReady::RotorAngle));
    let r = Rejection::for_command_error(&Request::SetMode(Mode::Speed), &not_ready);
    assert_eq!(
        (r.function, r.reason, r.bound),
        (0x10, RejectReason::NotReady, 2)
    );
    let f = encode_reply(&Reply::Reject(r), node(0));
    assert_eq!(f.payload()[..3], [0x10, 9, 2]);
}

#[test]
fn acceptance_filters_pass_exactly_this_nodes_commands() {
    let commands = [
        0x100, 0x110, 0x120, 0x130, 0x140, 0x200, 0x210, 0x220, 0x230, 0x240,
    ];
    for n in 0..=15u8 {
        let me = node(n);
        let filters = acceptance_filters(me);
        let passes = |id: u16| filters.iter().any(|(f, m)| id & m == f & m);
        for base in commands {
            assert!(passes(base + u16::from(n)), "{base:#x} node {n}");
        }
        let mut passed = 0;
        for id in 0..=STANDARD_ID_MAX {
            if !passes(id) {
                continue;
            }
            passed += 1;
            // Only this node's frames in the two command blocks; never a reply.
            assert_eq!(id & 0xF, u16::from(n), "{id:#x}");
            assert!(
                (0x100..0x180).contains(&id) || (0x200..0x280).contains(&id),
                "{id:#x}"
            );
            assert!(
                decode_command(&Frame::new(id, &[]).unwrap(), me).is_ok_or_refusable(),
                "{id:#x}"
            );
        }
        // Eight function slots in each block.
        assert_eq!(passed, 16);
    }
}

trait Refusable {
    fn is_ok_or_refusable(&self) -> bool;
}

impl Refusable for Result<Request, DecodeError> {
    /// Decoded, or refused with a reply (never ignored as another node's or a reply).
    fn is_ok_or_refusable(&self) -> bool {
        match self {
            Ok(_) => true,
            Err(e) => Rejection::for_decode_error(e).is_some(),
        }
    }
}

#[test]
fn mode_codes_are_the_four_documented_ones() {
    // 0 disabled, 1 calibrating, 2 speed, 3 pressure (module documentation).
    let documented = [
        Mode::Disabled,
        Mode::Calibrating,
        Mode::Speed,
        Mode::Pressure,
    ];
    for (code, mode) in documented.into_iter().enumerate() {
        let f = encode_command(&Request::SetMode(mode), node(0));
        assert_eq!(f.payload(), &[code as u8]);
    }
    assert_eq!(usize::from(MODE_CODE_MAX) + 1, documented.len());
    let f = Frame::new(0x100, &[MODE_CODE_MAX + 1]).unwrap();
    assert!(matches!(
        decode_command(&f, node(0)),
        Err(DecodeError::UnknownMode { .. })
    ));
}

#[test]
fn function_codes_are_the_identifier_base_shifted() {
    for f in [
        Function::SetMode,
        Function::SetPressure,
        Function::SetSpeed,
        Function::ClearFaults,
        Function::Heartbeat,
    ] {
        assert_eq!(u16::from(f.code()) << 4, f.id_base());
        assert_eq!(Function::from_code(f.code()), Some(f));
    }
    assert_eq!(Function::from_code(0x18), None);
}

#[test]
fn the_all_lists_hold_every_code_the_decoders_accept() {
    // The DBC file and the host tools enumerate the protocol through these lists.
    for code in 0..=u8::MAX {
        assert_eq!(
            Function::from_code(code),
            Function::ALL.into_iter().find(|f| f.code() == code),
            "function {code:#x}"
        );
        assert_eq!(
            RejectReason::from_code(code),
            RejectReason::ALL.into_iter().find(|r| r.code() == code),
            "reason {code}"
        );
        assert_eq!(
            StepLoop::from_code(code),
            StepLoop::ALL.into_iter().find(|l| l.code() == code),
            "step loop {code}"
        );
        assert_eq!(Mode::from_code(code).is_some(), code <= MODE_CODE_MAX);
    }
}
