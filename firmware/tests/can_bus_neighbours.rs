//! Drives sharing one bus: a drive answers no frame addressed to another node. Before, the
//! codec checked the function before the node, so another drive's status (`0x183`) or
//! reject (`0x193`), unknown as commands, came back as `UnknownFunction` — a reject the
//! application sends — and two drives answered each other's rejects for ever; the fault
//! campaign's garbage and flood frames for other nodes drew rejects from the drive too.

use firmware::can_protocol::{
    decode_command, encode_reply, DecodeError, Frame, NodeId, RejectReason, Rejection, Reply,
    Status,
};
use firmware::Mode;

fn node(n: u8) -> NodeId {
    NodeId::new(n).unwrap()
}

#[test]
fn another_drives_status_and_rejects_draw_no_reply() {
    let (me, other) = (node(1), node(3));
    let status = encode_reply(
        &Reply::Status(Status::from_si(Mode::Pressure, 0, 5e6, 5.7, 0x11, 7)),
        other,
    );
    let reject = encode_reply(
        &Reply::Reject(Rejection::with_si_bound(
            firmware::can_protocol::Function::SetPressure,
            RejectReason::AboveMaximum,
            18e6,
            0,
        )),
        other,
    );
    for f in [status, reject] {
        let err = decode_command(&f, me).unwrap_err();
        assert_eq!(err, DecodeError::OtherNode { node: 3 }, "{f}");
        assert_eq!(Rejection::for_decode_error(&err), None, "{f}");
    }
}

#[test]
fn every_identifier_of_another_node_is_ignored_silently() {
    let me = node(1);
    for id in 0..=0x7FFu16 {
        if id & 0xF == 1 {
            continue;
        }
        for len in [0usize, 1, 4, 8] {
            let f = Frame::new(id, &[0x5A; 8][..len]).unwrap();
            let err = decode_command(&f, me).unwrap_err();
            assert_eq!(Rejection::for_decode_error(&err), None, "{f}");
        }
    }
    // The drive's own node still gets its reject for an unknown function.
    let err = decode_command(&Frame::new(0x151, &[]).unwrap(), me).unwrap_err();
    assert_eq!(err, DecodeError::UnknownFunction { id: 0x151 });
    assert!(Rejection::for_decode_error(&err).is_some());
}
