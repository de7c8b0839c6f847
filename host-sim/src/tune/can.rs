//! The CAN commands that apply a tuning ([`crate::can_commands`]): one `SetParameter`
//! frame per parameter, then the `SaveParameters` frame that stores them, as `cansend`
//! lines and, with `--can-log`, as a `candump -l` log `canplayer` replays.

pub use crate::can_commands::{cansend, parameter_commands, Setting, INTERFACE, NODE};

/// The command lines setting `settings` on drive [`NODE`], each with what it sets, and the
/// save. A value outside the parameter's documented bounds is an error naming both.
pub fn command_lines(settings: &[Setting]) -> Result<Vec<String>, String> {
    parameter_commands(settings).map(|c| crate::can_commands::cansend_lines(&c))
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmware::parameters::ParamId;

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
