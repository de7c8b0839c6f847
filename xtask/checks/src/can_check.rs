//! The DBC file against the firmware's codec, with Python's `cantools` as the other side:
//!
//! 1. every frame kind, with every mode, fault code, function, reject reason, step-test
//!    loop and parameter id, encoded by `firmware::can_protocol`; `cantools` decodes each
//!    (raw values exactly, physical values, value-table names) and compares it with the
//!    values the frame was built from;
//! 2. `cantools` encodes the same messages from their physical values and names, and the
//!    firmware's decoder must give back the very message (and the same bytes);
//! 3. `python3 -m cantools decode --single-line eha.dbc` on `candump` lines, the
//!    README's command, names the message and its values.
//!
//! The Python side is `xtask/can_check.py`, run with the interpreter of the virtual
//! environment `.ci/run` and [`xtask::setup`] make (`cantools` missing is a failure).

use crate::dbc::{parameter_signal, words, DEFAULT_NODE};
use anyhow::{bail, Context, Result};
use firmware::can_protocol::{
    decode_command, decode_reply, encode_command, encode_reply, Diagnostics, Frame, Function,
    NodeId, RejectReason, Rejection, Reply, Request, Status, NO_COMMAND, SETPOINT_RAD_S_PER_LSB,
    STATUS_RAD_S_PER_LSB,
};
use firmware::parameters::ParamId;
use firmware::step_test::StepLoop;
use firmware::{FaultCode, Mode};
use serde_json::{json, Map, Value};
use std::process::Command;

/// A message the check sends both ways.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Sample {
    Command(Request),
    Reply(Reply),
}

/// What cantools must read in a frame: raw field values, physical values, value-table
/// names.
struct Expected {
    raw: Map<String, Value>,
    physical: Map<String, Value>,
    names: Map<String, Value>,
}

impl Expected {
    fn new() -> Expected {
        Expected {
            raw: Map::new(),
            physical: Map::new(),
            names: Map::new(),
        }
    }

    /// An integer field scaled by `factor` (the DBC's decimal text of the constant).
    fn int(mut self, signal: &str, raw: i64, factor: f64) -> Expected {
        self.raw.insert(signal.into(), json!(raw));
        self.physical
            .insert(signal.into(), json!(raw as f64 * factor));
        self
    }

    /// An `f32` field.
    fn float(mut self, signal: &str, v: f32) -> Expected {
        self.raw.insert(signal.into(), json!(f64::from(v)));
        self.physical.insert(signal.into(), json!(f64::from(v)));
        self
    }

    /// A coded field and the name its value table gives the code.
    fn coded(mut self, signal: &str, code: u8, name: Option<String>) -> Expected {
        self = self.int(signal, i64::from(code), 1.0);
        if let Some(n) = name {
            self.names.insert(signal.into(), json!(n));
        }
        self
    }
}

fn ms_factor() -> f64 {
    crate::dbc::shortest(1e-3)
}

/// The values of a command, from the request itself.
fn expected_command(r: &Request) -> Expected {
    let e = Expected::new();
    match *r {
        Request::SetMode(m) => e.coded("Mode", m.code(), Some(m.name().into())),
        Request::SetPressure { pa } => e.int(
            "PressureSetpoint",
            i64::from(pa),
            crate::dbc::shortest(firmware::can_protocol::SETPOINT_PA_PER_LSB),
        ),
        Request::SetSpeed { mrad_s } => e.int(
            "SpeedSetpoint",
            i64::from(mrad_s),
            crate::dbc::shortest(SETPOINT_RAD_S_PER_LSB),
        ),
        Request::SetParameter { id, value } => e
            .coded("ParameterId", id.code(), Some(id.name().into()))
            .float(&parameter_signal(id), value),
        Request::GetParameter { id } => e.coded("ParameterId", id.code(), Some(id.name().into())),
        Request::StepTest {
            target,
            amplitude,
            duration_ms,
        } => {
            let name = crate::dbc::ascii(&format!("{target:?}")).to_lowercase();
            e.coded("Loop", target.code(), Some(name.clone()))
                .float(&format!("Amplitude_{name}"), amplitude)
                .int("Duration", i64::from(duration_ms), ms_factor())
        }
        Request::ClearFaults
        | Request::Heartbeat
        | Request::SaveParameters
        | Request::Commission => e,
        Request::CompensationHeader { exponents, bins } => {
            let [e0, e1, e2] = exponents.map(|x| x as u8);
            e.int("Bin", 0xFFFF, 1.0)
                .int("Raw0", i64::from(i16::from_le_bytes([e0, e1])), 1.0)
                .int("Raw1", i64::from(i16::from_le_bytes([e2, 0])), 1.0)
                .int("Raw2", i64::from(bins as i16), 1.0)
        }
        Request::CompensationBin { bin, raw } => e
            .int("Bin", i64::from(bin), 1.0)
            .int("Raw0", i64::from(raw[0]), 1.0)
            .int("Raw1", i64::from(raw[1]), 1.0)
            .int("Raw2", i64::from(raw[2]), 1.0),
        Request::CompensationCommit { crc } => e.int("Crc", i64::from(crc), 1.0),
        Request::CompensationSweep {
            speed_rad_s,
            leg_ms,
        } => e
            .float("SweepSpeed", speed_rad_s)
            .int("LegDuration", i64::from(leg_ms), ms_factor()),
    }
}

fn function_name(code: u8) -> Option<String> {
    Function::from_code(code).map(|f| format!("{f:?}"))
}

/// The values of a reply, from the reply itself.
fn expected_reply(r: &Reply) -> Expected {
    let e = Expected::new();
    match *r {
        Reply::Status(s) => {
            let last = if s.last_command == NO_COMMAND {
                Some("none".to_string())
            } else {
                function_name(s.last_command)
            };
            let fault = match s.fault {
                0 => Some("none".to_string()),
                c => FaultCode::from_code(c).map(|f| crate::dbc::ascii(f.description())),
            };
            e.coded(
                "Mode",
                s.mode,
                Mode::from_code(s.mode).map(|m| m.name().into()),
            )
            .coded("Fault", s.fault, fault)
            .int(
                "Pressure",
                i64::from(s.pressure_kpa),
                crate::dbc::shortest(firmware::can_protocol::STATUS_PA_PER_LSB),
            )
            .int(
                "Speed",
                i64::from(s.speed_drad_s),
                crate::dbc::shortest(STATUS_RAD_S_PER_LSB),
            )
            .coded("LastCommand", s.last_command, last)
            .coded("Sequence", s.sequence, None)
        }
        Reply::Reject(j) => {
            let f = Function::from_code(j.function).expect("samples reject known functions");
            let bound = format!("Bound_{f:?}");
            let e = e
                .coded("Function", j.function, function_name(j.function))
                .coded(
                    "Reason",
                    j.reason.code(),
                    Some(words(&format!("{:?}", j.reason))),
                )
                .coded(
                    "Parameter",
                    j.parameter,
                    ParamId::from_code(j.parameter).map(|p| p.name().into()),
                );
            match f {
                Function::SetParameter
                | Function::GetParameter
                | Function::SaveParameters
                | Function::StepTest
                | Function::CompensationBin
                | Function::CompensationCommit
                | Function::CompensationSweep => e.float(&bound, f32::from_bits(j.bound as u32)),
                Function::SetPressure => e.int(
                    &bound,
                    i64::from(j.bound),
                    crate::dbc::shortest(firmware::can_protocol::SETPOINT_PA_PER_LSB),
                ),
                Function::SetSpeed => e.int(
                    &bound,
                    i64::from(j.bound),
                    crate::dbc::shortest(SETPOINT_RAD_S_PER_LSB),
                ),
                Function::SetMode
                | Function::ClearFaults
                | Function::Heartbeat
                | Function::Commission => e.int(&bound, i64::from(j.bound), 1.0),
            }
        }
        Reply::Parameter { id, value } => e
            .coded("ParameterId", id.code(), Some(id.name().into()))
            .float(&parameter_signal(id), value),
        Reply::Diagnostics(d) => e.int("StackPeak", i64::from(d.stack_peak_bytes), 1.0).int(
            "StackSize",
            i64::from(d.stack_size_bytes),
            1.0,
        ),
    }
}

/// Every frame kind, with every code of every value table: the commands, then the replies.
fn samples() -> Vec<Sample> {
    let mut v: Vec<Sample> = Function::ALL
        .into_iter()
        .flat_map(|f| requests(f).into_iter().map(Sample::Command))
        .collect();
    v.extend(replies());
    v
}

/// The command `f` with samples of its values (its value tables whole, its numbers at
/// zero, typical values and the ends of their ranges).
fn requests(f: Function) -> Vec<Request> {
    // Exhaustive: a new command breaks the build here until it has samples.
    match f {
        Function::SetMode => Mode::ALL.iter().map(|m| Request::SetMode(*m)).collect(),
        Function::SetPressure => [0, 5_000_000, -101_325, i32::MAX, i32::MIN]
            .iter()
            .map(|pa| Request::SetPressure { pa: *pa })
            .collect(),
        Function::SetSpeed => [0, 1_234, -52_360, i32::MAX, i32::MIN]
            .iter()
            .map(|m| Request::SetSpeed { mrad_s: *m })
            .collect(),
        Function::ClearFaults => vec![Request::ClearFaults],
        Function::Heartbeat => vec![Request::Heartbeat],
        Function::SetParameter => ParamId::ALL
            .iter()
            .map(|id| Request::SetParameter {
                id: *id,
                // A value inside the bounds that is not a round number.
                value: id.min() + (id.max() - id.min()) * 0.3141,
            })
            .collect(),
        Function::GetParameter => ParamId::ALL
            .iter()
            .map(|id| Request::GetParameter { id: *id })
            .collect(),
        Function::SaveParameters => vec![Request::SaveParameters],
        Function::StepTest => StepLoop::ALL
            .iter()
            .zip([(-2.5f32, 1u16), (12.75, 250), (1.5e6, 65_535)])
            .map(|(l, (a, ms))| Request::StepTest {
                target: *l,
                amplitude: a,
                duration_ms: ms,
            })
            .collect(),
        Function::Commission => vec![Request::Commission],
        Function::CompensationBin => vec![
            Request::CompensationHeader {
                exponents: [19, 40, -3],
                bins: 512,
            },
            Request::CompensationBin {
                bin: 0,
                raw: [0, 0, 0],
            },
            Request::CompensationBin {
                bin: 511,
                raw: [i16::MIN, -1234, i16::MAX],
            },
        ],
        Function::CompensationCommit => [0u32, 0x8123_FB45, u32::MAX]
            .iter()
            .map(|crc| Request::CompensationCommit { crc: *crc })
            .collect(),
        Function::CompensationSweep => [(10.0f32, 6000u16), (-2.5, 1), (1e3, 65_535)]
            .iter()
            .map(|(w, ms)| Request::CompensationSweep {
                speed_rad_s: *w,
                leg_ms: *ms,
            })
            .collect(),
    }
}

/// Every reply: a status in every mode, with every fault code and after every command;
/// every rejection of every command; every parameter; the diagnostics' extremes.
fn replies() -> Vec<Sample> {
    let mut v = Vec::new();
    let mut status = |mode: Mode, fault: u8, kpa: i16, drad: i16, last: u8, seq: u8| {
        v.push(Sample::Reply(Reply::Status(Status {
            mode: mode.code(),
            fault,
            pressure_kpa: kpa,
            speed_drad_s: drad,
            last_command: last,
            sequence: seq,
        })));
    };
    for (k, m) in Mode::ALL.iter().enumerate() {
        status(*m, 0, 5000, -123, NO_COMMAND, k as u8);
    }
    for (k, f) in FaultCode::ALL.iter().enumerate() {
        status(
            Mode::Disabled,
            f.code(),
            i16::MIN,
            i16::MAX,
            0x13,
            200 + k as u8,
        );
    }
    for f in Function::ALL {
        status(Mode::Pressure, 0, 25_000, 1, f.code(), 255);
    }
    for f in Function::ALL {
        for r in RejectReason::ALL {
            let configuration = matches!(
                f,
                Function::SetParameter
                    | Function::GetParameter
                    | Function::SaveParameters
                    | Function::StepTest
            );
            let rejection = if configuration {
                Rejection::with_si_bound(f, r, 10.0, ParamId::SpeedKp.code())
            } else {
                Rejection {
                    function: f.code(),
                    reason: r,
                    bound: -25_000_000 + i32::from(r.code()),
                    parameter: 0,
                }
            };
            v.push(Sample::Reply(Reply::Reject(rejection)));
        }
    }
    for id in ParamId::ALL {
        v.push(Sample::Reply(Reply::Parameter {
            id,
            value: id.default_value(),
        }));
    }
    for (peak, size) in [(0, 0), (2_660, 115_072), (u32::MAX, u32::MAX)] {
        v.push(Sample::Reply(Reply::Diagnostics(Diagnostics {
            stack_peak_bytes: peak,
            stack_size_bytes: size,
        })));
    }
    v
}

fn encode(s: &Sample, node: NodeId) -> Frame {
    match s {
        Sample::Command(r) => encode_command(r, node),
        Sample::Reply(r) => encode_reply(r, node),
    }
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// Runs the check with `python` (an interpreter that has `cantools`).
pub fn check(python: &std::path::Path) -> Result<()> {
    let node = NodeId::new(DEFAULT_NODE).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let samples = samples();
    for kind in crate::dbc::ReplyKind::ALL {
        let covered = samples
            .iter()
            .any(|s| matches!(s, Sample::Reply(r) if crate::dbc::ReplyKind::of(r) == kind));
        if !covered {
            bail!("the check has no {kind:?} frame");
        }
    }
    let vectors: Vec<Value> = samples
        .iter()
        .map(|s| {
            let f = encode(s, node);
            let e = match s {
                Sample::Command(r) => expected_command(r),
                Sample::Reply(r) => expected_reply(r),
            };
            json!({
                "frame_id": f.id(), "data": hex(f.payload()),
                "raw": e.raw, "physical": e.physical, "names": e.names,
            })
        })
        .collect();
    let dir = xtask::workspace::target_dir().join("can-check");
    std::fs::create_dir_all(&dir)?;
    let input = dir.join("firmware-frames.json");
    let output = dir.join("cantools-frames.json");
    std::fs::write(&input, serde_json::to_string_pretty(&vectors)?)?;
    let _ = std::fs::remove_file(&output);
    xtask::workspace::run(
        "CAN: cantools against the firmware's codec",
        Command::new(python)
            .arg(xtask::workspace::root().join("xtask").join("can_check.py"))
            .arg(xtask::workspace::root().join(crate::dbc::FILE))
            .arg(&input)
            .arg(&output),
    )?;
    let text = std::fs::read_to_string(&output)
        .with_context(|| format!("reading {}", output.display()))?;
    let encoded: Vec<String> = serde_json::from_str(&text)?;
    if encoded.len() != samples.len() {
        bail!(
            "cantools encoded {} frames of {}",
            encoded.len(),
            samples.len()
        );
    }
    for (s, data) in samples.iter().zip(&encoded) {
        let own = encode(s, node);
        let bytes = (0..data.len() / 2)
            .map(|k| u8::from_str_radix(&data[2 * k..2 * k + 2], 16))
            .collect::<Result<Vec<u8>, _>>()?;
        let frame = Frame::new(own.id(), &bytes).map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let back = match s {
            Sample::Command(_) => decode_command(&frame, node).map(Sample::Command),
            Sample::Reply(_) => decode_reply(&frame, node).map(Sample::Reply),
        };
        match back {
            Ok(b) if b == *s && bytes == own.payload() => {}
            Ok(b) => bail!("{s:?}: cantools encoded {frame} ({b:?}), the firmware {own}"),
            Err(e) => bail!("{s:?}: the firmware cannot decode cantools' {frame}: {e:?}"),
        }
    }
    eprintln!(
        "CAN: {} frames of {} kinds agree both ways between the firmware and cantools",
        samples.len(),
        crate::dbc::messages().len()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_samples_cover_every_message_of_the_dbc() {
        let node = NodeId::new(DEFAULT_NODE).unwrap();
        let ids: std::collections::BTreeSet<u16> =
            samples().iter().map(|s| encode(s, node).id()).collect();
        for m in crate::dbc::messages() {
            assert!(
                ids.contains(&(m.base + u16::from(DEFAULT_NODE))),
                "{}",
                m.name
            );
        }
    }
}
