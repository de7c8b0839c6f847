//! The CAN side: the frame decoder for both directions, and the drive's parameter server
//! fed frame after frame while its control step runs.

use firmware::can_protocol::{
    decode_command, decode_reply, encode_command, encode_reply, Frame, NodeId, Rejection,
};
use firmware::can_server::{serve, Response};
use firmware::{Config, Controller, Measurements};

/// An 11-bit identifier and up to 8 bytes from `data`: (id, payload, rest).
fn frame_of(data: &[u8]) -> Option<(Frame, &[u8])> {
    let (&[hi, lo, len], rest) = data.split_first_chunk::<3>()?;
    let id = u16::from_le_bytes([lo, hi]) & 0x7FF;
    let n = usize::from(len % 9).min(rest.len());
    let frame = Frame::new(id, &rest[..n]).expect("an 11-bit id and at most 8 bytes");
    Some((frame, &rest[n..]))
}

/// The frame decoder: any identifier and payload, as a command to and a reply from any
/// node; a decoded message encodes to a frame that decodes to the same message.
pub fn can_frame(data: &[u8]) {
    let Some((&node, data)) = data.split_first() else {
        return;
    };
    let Ok(node) = NodeId::new(node) else {
        return;
    };
    let Some((frame, _)) = frame_of(data) else {
        return;
    };
    match decode_command(&frame, node) {
        Ok(request) => {
            // Compared as printed: a NaN value is unequal to itself but must survive.
            let again = encode_command(&request, node);
            let back = decode_command(&again, node).expect("an encoded command decodes");
            assert_eq!(format!("{back:?}"), format!("{request:?}"), "{frame}");
        }
        Err(e) => {
            let _ = Rejection::for_decode_error(&e);
        }
    }
    if let Ok(reply) = decode_reply(&frame, node) {
        let again = encode_reply(&reply, node);
        let back = decode_reply(&again, node).expect("an encoded reply decodes");
        // A NaN parameter value compares unequal to itself; its bits must survive.
        assert_eq!(format!("{back:?}"), format!("{reply:?}"), "{frame}");
    }
}

/// The drive's parameter server: frames decoded and served one after another on a
/// controller whose control step runs between them on measurements from the input; every
/// reply encodes, and the step's duties stay finite in [0, 1].
pub fn can_server(data: &[u8]) {
    let node = NodeId::new(1).expect("node 1");
    let mut controller = Controller::new(&Config::nominal());
    let mut rest = data;
    while let Some((frame, after)) = frame_of(rest) {
        rest = after;
        // Between frames, a few control steps on measurements drawn from the input.
        let (steps, after) = rest.split_first().map_or((0, rest), |(n, r)| (n % 8, r));
        rest = after;
        for _ in 0..steps {
            let (m, after) = measurements(rest);
            rest = after;
            let out = controller.on_current_sample(&m);
            assert!(
                out.duties
                    .iter()
                    .all(|d| d.is_finite() && (0.0..=1.0).contains(d)),
                "duties {:?}",
                out.duties
            );
        }
        let Ok(request) = decode_command(&frame, node) else {
            continue;
        };
        match serve(&request, &mut controller) {
            Response::Reply(reply) => {
                let _ = encode_reply(&reply, node);
            }
            Response::Save(values) => {
                assert!(
                    controller.load_parameters(&values).is_ok(),
                    "a saved table reloads"
                );
            }
            Response::Silent | Response::Ack(_) => {}
        }
        let _ = controller.telemetry();
    }
}

/// Measurements from the next 13 bytes of `data` (zeros past its end), and the rest.
fn measurements(data: &[u8]) -> (Measurements, &[u8]) {
    let mut b = [0u8; 13];
    let n = data.len().min(13);
    b[..n].copy_from_slice(&data[..n]);
    let u16_at = |i: usize| u16::from_le_bytes([b[i], b[i + 1]]);
    let m = Measurements {
        adc_phase_current: [u16_at(0) & 0xFFF, u16_at(2) & 0xFFF, u16_at(4) & 0xFFF],
        adc_dc_link: u16_at(6) & 0xFFF,
        adc_pressure: u16_at(8),
        encoder_count: u32::from(u16_at(10)),
        encoder_index: b[12] & 1 == 1,
        // The index captured where the counter stands.
        encoder_index_count: u32::from(u16_at(10)),
    };
    (m, &data[n..])
}
