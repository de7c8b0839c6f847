//! The CAN commands that apply a tuning: one `SetParameter` frame per parameter
//! (`firmware::can_protocol`, parameter ids and names of `firmware::parameters`), printed in
//! the `cansend` format of Linux can-utils (`<iface> <id>#<payload hex>`), followed by the
//! `SaveParameters` frame that stores them (accepted with the drive disabled).

use firmware::can_protocol::{encode_command, encode_set_parameter, Frame, NodeId, Request};
use firmware::parameters::ParamId;
use std::fmt::Write as _;

/// The drive's node number (the application's `board::CAN_NODE`).
pub const NODE: u8 = 1;
/// The SocketCAN interface the printed commands name.
pub const INTERFACE: &str = "can0";

/// One parameter to set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setting {
    /// The parameter.
    pub id: ParamId,
    /// Its new value. [the parameter's unit]
    pub value: f64,
}

/// `cansend` argument text of `frame` on [`INTERFACE`].
pub fn cansend(frame: &Frame) -> String {
    let mut s = format!("{INTERFACE} {:03X}#", frame.id());
    for b in frame.payload() {
        let _ = write!(s, "{b:02X}");
    }
    s
}

/// The command lines setting `settings` on drive [`NODE`], each with what it sets, and the
/// save. A value outside the parameter's documented bounds is an error naming both.
pub fn command_lines(settings: &[Setting]) -> Result<Vec<String>, String> {
    let node = NodeId::new(NODE).map_err(|e| format!("CAN node {NODE}: {e:?}"))?;
    let mut lines = Vec::with_capacity(settings.len() + 1);
    for s in settings {
        let v = s.value as f32;
        s.id.check(v)
            .map_err(|e| format!("{} = {v}: {e}", s.id.name()))?;
        lines.push(format!(
            "{:<26} # set {} = {v} {}",
            cansend(&encode_set_parameter(s.id, v, node)),
            s.id.name(),
            s.id.unit()
        ));
    }
    lines.push(format!(
        "{:<26} # save the parameters (drive disabled)",
        cansend(&encode_command(&Request::SaveParameters, node))
    ));
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_parameter_frame_is_the_protocols_layout() {
        // can_protocol: SetParameter = 0x200 + node, DLC 5, u8 id then f32 little endian.
        let lines = command_lines(&[Setting {
            id: ParamId::SpeedKp,
            value: 0.25,
        }])
        .unwrap();
        // 0.25f32 = 0x3E800000; speed.kp is id 10 = 0x0A.
        assert!(lines[0].starts_with("can0 201#0A0000803E "), "{}", lines[0]);
        assert!(lines[0].contains("set speed.kp = 0.25"), "{}", lines[0]);
        assert!(lines[1].starts_with("can0 221# "), "{}", lines[1]);
        let bad = command_lines(&[Setting {
            id: ParamId::SpeedKp,
            value: 50.0,
        }])
        .unwrap_err();
        assert!(bad.contains("speed.kp"), "{bad}");
    }
}
