//! The CAN frames that load a table into a drive, built with the firmware's own encoder
//! (`firmware::can_protocol`): the header, the bins in order, the commit with the record's
//! CRC, the speed modulation's parameters if there are any ([`crate::feedforward::flow`]), then
//! `compensation.enabled = 1`; `SaveParameters` (in Disabled) keeps it over a
//! power cycle. Printed in `cansend` notation.

use crate::feedforward::Feedforward;
use firmware::can_protocol::{encode_command, encode_set_parameter, Frame, NodeId, Request};
use firmware::compensation::{record, BINS};
use firmware::parameters::ParamId;

/// The frames loading `ff` into drive `node`, enabling it and saving it.
pub fn frames(ff: &Feedforward, node: NodeId) -> Vec<Frame> {
    let table = &ff.table;
    let mut out = Vec::with_capacity(BINS + 8);
    out.push(encode_command(
        &Request::CompensationHeader {
            exponents: table.exponents(),
            bins: BINS as u16,
        },
        node,
    ));
    for b in 0..BINS {
        out.push(encode_command(
            &Request::CompensationBin {
                bin: b as u16,
                raw: table.raw(b),
            },
            node,
        ));
    }
    out.push(encode_command(
        &Request::CompensationCommit {
            crc: record::crc_of(table),
        },
        node,
    ));
    for (id, v) in ff.flow.iter().flat_map(|f| f.parameters()) {
        out.push(encode_set_parameter(id, v, node));
    }
    out.push(encode_set_parameter(
        ParamId::CompensationEnabled,
        1.0,
        node,
    ));
    out.push(encode_command(&Request::SaveParameters, node));
    out
}

/// The frames as shell lines, `cansend can0 <id>#<payload>` (the interface of
/// [`crate::tune::can`]).
pub fn cansend_lines(frames: &[Frame]) -> String {
    frames
        .iter()
        .map(|f| format!("cansend {}\n", crate::tune::can::cansend(f)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmware::can_protocol::decode_command;
    use firmware::can_server::serve;
    use firmware::compensation::Table;
    use firmware::{Config, Controller};

    #[test]
    fn the_printed_frames_load_the_table_into_a_drive() {
        // A table with one non-zero bin, sent through the drive's own decoder and server.
        let mut raw = Box::new([[0i16; 3]; BINS]);
        raw[10] = [1000, -20, 300];
        let t = Table::from_raw([16, 40, 18], &raw).unwrap();
        let node = NodeId::new(1).unwrap();
        let flow = crate::feedforward::flow::FlowParams {
            pistons: 9,
            ratio: 0.0152,
            phase_rad: 0.0,
            inertia_kg_m2: 8e-4,
        };
        let ff = Feedforward {
            table: t.clone(),
            flow: Some(flow),
        };
        let frames = frames(&ff, node);
        assert_eq!(frames.len(), BINS + 8);
        assert_eq!(frames[0].to_string(), "251#FFFF102812000002");
        let mut c = Controller::new(&Config::nominal());
        // The last frame (SaveParameters) is served by the application (flash).
        for f in &frames[..frames.len() - 1] {
            let req = decode_command(f, node).expect("decodes");
            let _ = serve(&req, &mut c);
        }
        assert!(c.compensation().is_committed());
        assert_eq!(c.compensation().table(), &t);
        assert_eq!(c.parameter(ParamId::CompensationEnabled), 1.0);
        assert!(c.compensation().is_active());
        assert_eq!(c.parameter(ParamId::CompensationFlowPistons), 9.0);
        assert_eq!(c.parameter(ParamId::CompensationFlowRatio), 0.0152);
        assert!(c.compensation().flow().is_active());
    }
}
