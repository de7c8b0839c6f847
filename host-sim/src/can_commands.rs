//! Parameter changes as CAN frames for the bench, built with the firmware's own encoder
//! (`firmware::can_protocol`): one `SetParameter` frame per parameter, then the
//! `SaveParameters` frame that stores them (accepted with the drive disabled). They go out
//! in the two forms of Linux can-utils:
//!
//! - `cansend` lines (`can0 201#0A0000803E`), to paste one by one;
//! - a `candump -l` log (`(1700000000.000000) can0 201#0A0000803E`), which
//!   `canplayer -I FILE` replays in order, [`FRAME_GAP_S`] apart (the drive answers each
//!   with a `Parameter` frame; the save comes last).
//!
//! `eha tune` writes its proposal through this module; any other tool that changes
//! parameters (a compensation table, a commissioning result) does the same.

use crate::output::{CliError, Outputs};
use firmware::can_protocol::{encode_command, encode_set_parameter, Frame, NodeId, Request};
use firmware::parameters::ParamId;
use std::fmt::Write as _;
use std::path::Path;

/// The drive's node number (the application's `board::CAN_NODE`).
pub const NODE: u8 = 1;
/// The SocketCAN interface the commands name.
pub const INTERFACE: &str = "can0";
/// Time between two frames of a replayed log: the drive has answered the previous one
/// long before (a `SetParameter` is applied between two control steps). [s]
pub const FRAME_GAP_S: f64 = 0.05;

/// One parameter to set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setting {
    /// The parameter.
    pub id: ParamId,
    /// Its new value. [the parameter's unit]
    pub value: f64,
}

/// A frame and what it does.
#[derive(Clone, Debug, PartialEq)]
pub struct CanCommand {
    /// The frame.
    pub frame: Frame,
    /// What it does, in words.
    pub what: String,
}

/// The frames that set `settings` on drive [`NODE`] and then save them. A value outside
/// the parameter's documented bounds is an error naming both.
pub fn parameter_commands(settings: &[Setting]) -> Result<Vec<CanCommand>, String> {
    let node = NodeId::new(NODE).map_err(|e| format!("CAN node {NODE}: {e:?}"))?;
    let mut out = Vec::with_capacity(settings.len() + 1);
    for s in settings {
        let v = s.value as f32;
        s.id.check(v)
            .map_err(|e| format!("{} = {v}: {e}", s.id.name()))?;
        out.push(CanCommand {
            frame: encode_set_parameter(s.id, v, node),
            what: format!("set {} = {v} {}", s.id.name(), s.id.unit()),
        });
    }
    out.push(CanCommand {
        frame: encode_command(&Request::SaveParameters, node),
        what: "save the parameters (drive disabled)".into(),
    });
    Ok(out)
}

/// `cansend` argument text of `frame` on [`INTERFACE`].
pub fn cansend(frame: &Frame) -> String {
    format!("{INTERFACE} {frame}")
}

/// The commands as `cansend` lines, each with what it does.
pub fn cansend_lines(commands: &[CanCommand]) -> Vec<String> {
    commands
        .iter()
        .map(|c| format!("{:<26} # {}", cansend(&c.frame), c.what))
        .collect()
}

/// The commands as a `candump -l` log starting at `start_s` (seconds since the Unix epoch,
/// microsecond resolution), [`FRAME_GAP_S`] apart.
pub fn candump_log(commands: &[CanCommand], start_s: f64) -> String {
    let start_us = (start_s * 1e6).round() as u64;
    let gap_us = (FRAME_GAP_S * 1e6).round() as u64;
    let mut s = String::new();
    for (k, c) in commands.iter().enumerate() {
        let t = start_us + gap_us * k as u64;
        let _ = writeln!(
            s,
            "({}.{:06}) {INTERFACE} {}",
            t / 1_000_000,
            t % 1_000_000,
            c.frame
        );
    }
    s
}

/// Stages the commands as a `candump -l` log, stamped from now, as the output `--can-log
/// path`.
pub fn stage_candump_log(
    out: &mut Outputs,
    path: &Path,
    commands: &[CanCommand],
) -> Result<(), CliError> {
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64());
    out.file("--can-log", path, candump_log(commands, now).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmware::can_protocol::decode_command;

    /// A candump line's identifier and payload, read back by hand.
    fn parse(line: &str) -> (f64, u16, Vec<u8>) {
        let (stamp, rest) = line.split_once(") ").unwrap();
        let t: f64 = stamp.trim_start_matches('(').parse().unwrap();
        let frame = rest.strip_prefix("can0 ").unwrap();
        let (id, data) = frame.split_once('#').unwrap();
        let bytes = (0..data.len() / 2)
            .map(|k| u8::from_str_radix(&data[2 * k..2 * k + 2], 16).unwrap())
            .collect();
        (t, u16::from_str_radix(id, 16).unwrap(), bytes)
    }

    #[test]
    fn the_candump_log_replays_the_settings_then_the_save_in_order() {
        let commands = parameter_commands(&[
            Setting {
                id: ParamId::SpeedKp,
                value: 0.25,
            },
            Setting {
                id: ParamId::AbsorberPrechargePa,
                value: 1e7,
            },
        ])
        .unwrap();
        let log = candump_log(&commands, 1_700_000_000.0);
        let lines: Vec<&str> = log.lines().collect();
        assert_eq!(lines.len(), 3);
        // candump -l's layout, written out by hand: 0.25f32 = 0x3E800000, speed.kp = 10.
        assert_eq!(lines[0], "(1700000000.000000) can0 201#0A0000803E");
        let node = NodeId::new(NODE).unwrap();
        let mut last = 0.0;
        for (k, l) in lines.iter().enumerate() {
            let (t, id, data) = parse(l);
            assert!(t > last, "timestamps increase");
            if k > 0 {
                assert!((t - last - FRAME_GAP_S).abs() < 1e-6);
            }
            last = t;
            let frame = Frame::new(id, &data).unwrap();
            let request = decode_command(&frame, node).unwrap();
            let expected = match k {
                0 => Request::SetParameter {
                    id: ParamId::SpeedKp,
                    value: 0.25,
                },
                1 => Request::SetParameter {
                    id: ParamId::AbsorberPrechargePa,
                    value: 1e7,
                },
                _ => Request::SaveParameters,
            };
            assert_eq!(request, expected);
        }
        let bad = parameter_commands(&[Setting {
            id: ParamId::SpeedKp,
            value: 50.0,
        }])
        .unwrap_err();
        assert!(bad.contains("speed.kp"), "{bad}");
    }
}
