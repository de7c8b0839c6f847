//! The host's commands, one message per `can_protocol::Function`: setpoints in the
//! protocol's wire scalings, the live-parameter commands multiplexed by the parameter id,
//! the step test multiplexed by the loop, and the compensation table's load frames.

use super::signal::{ascii, signal, Kind, Message, Mux, Sender, Signal};
use super::values::{loop_choices, mode_choices, parameter_choices, parameter_values, words};
use firmware::can_protocol::{Function, SETPOINT_PA_PER_LSB, SETPOINT_RAD_S_PER_LSB};
use firmware::step_test::StepLoop;

/// The step amplitude's unit per loop.
fn step_unit(l: StepLoop) -> &'static str {
    match l {
        StepLoop::Current => "A",
        StepLoop::Speed => "rad/s",
        StepLoop::Pressure => "Pa",
    }
}

/// A command's message.
pub(super) fn command(f: Function) -> Message {
    let u8s = |n: &str| signal(n, 0, 8, Kind::Unsigned);
    let (name, comment, signals) = match f {
        Function::SetMode => (
            "SetMode",
            "switch the operating mode; answered by Status, or Reject",
            vec![u8s("Mode").choices(mode_choices()).about("mode code")],
        ),
        Function::SetPressure => (
            "SetPressure",
            "pressure setpoint (gauge); answered by Status, or Reject",
            vec![signal("PressureSetpoint", 0, 32, Kind::Signed)
                .scaled(SETPOINT_PA_PER_LSB, "Pa")
                .about("pressure setpoint, gauge")],
        ),
        Function::SetSpeed => (
            "SetSpeed",
            "speed setpoint; answered by Status, or Reject",
            vec![signal("SpeedSetpoint", 0, 32, Kind::Signed)
                .scaled(SETPOINT_RAD_S_PER_LSB, "rad/s")
                .about("speed setpoint")],
        ),
        Function::ClearFaults => (
            "ClearFaults",
            "clear the latched faults whose cause is gone",
            Vec::new(),
        ),
        Function::Heartbeat => ("Heartbeat", "feed the command watchdog", Vec::new()),
        Function::SetParameter => (
            "SetParameter",
            "set a live parameter; answered by Parameter with the value in use, or Reject",
            parameter_values(),
        ),
        Function::GetParameter => (
            "GetParameter",
            "read a live parameter; answered by Parameter",
            vec![u8s("ParameterId")
                .choices(parameter_choices())
                .about("parameter id (firmware::parameters)")],
        ),
        Function::SaveParameters => (
            "SaveParameters",
            "store the live parameters in flash (drive disabled only)",
            Vec::new(),
        ),
        Function::StepTest => (
            "StepTest",
            "step one loop's reference with telemetry at full rate",
            step_test_signals(),
        ),
        Function::Commission => (
            "Commission",
            "run the commissioning sequence (motor identification) in Calibrating",
            Vec::new(),
        ),
        Function::CompensationBin => (
            "CompensationBin",
            "one bin of the torque feed-forward table, in order from 0 after the header \
             (bin 65535: bytes 2-4 the three channels' LSB exponents as i8, byte 5 zero, \
             bytes 6-7 the bin count)",
            compensation_bin_signals(),
        ),
        Function::CompensationCommit => (
            "CompensationCommit",
            "end the table load; the table takes effect if its CRC and amplitude pass",
            vec![signal("Crc", 0, 32, Kind::Unsigned)
                .about("CRC-32 of the table's record (firmware::compensation::record)")],
        ),
        Function::CompensationSweep => (
            "CompensationSweep",
            "the feed-forward's bench sweep: constant speed both ways, in Speed mode",
            vec![
                signal("SweepSpeed", 0, 32, Kind::Float)
                    .unit("rad/s")
                    .about("speed of the first leg"),
                signal("LegDuration", 4, 16, Kind::Unsigned)
                    .scaled(1e-3, "s")
                    .about("duration of each leg (ms on the wire)"),
            ],
        ),
    };
    Message {
        base: f.id_base(),
        name,
        dlc: f.dlc(),
        sender: Sender::Host,
        comment: ascii(comment),
        signals,
    }
}

/// The step test's signals, multiplexed by the stepped loop: each loop's amplitude in its
/// own unit, then the step's duration.
fn step_test_signals() -> Vec<Signal> {
    let mut s = vec![signal("Loop", 0, 8, Kind::Unsigned)
        .mux(Mux::Switch)
        .choices(loop_choices())
        .about("the stepped loop")];
    s.extend(StepLoop::ALL.iter().map(|l| {
        signal(
            &format!("Amplitude_{}", words(&format!("{l:?}"))),
            1,
            32,
            Kind::Float,
        )
        .unit(step_unit(*l))
        .mux(Mux::Case(l.code()))
        .about("step added to the present reference")
    }));
    s.push(
        signal("Duration", 5, 16, Kind::Unsigned)
            .scaled(1e-3, "s")
            .about("how long the step is held (ms on the wire)"),
    );
    s
}

/// A compensation-table bin's signals: its index and the three channels' raw values (the
/// header bin's exponents and bin count in the same places).
fn compensation_bin_signals() -> Vec<Signal> {
    vec![
        signal("Bin", 0, 16, Kind::Unsigned).about("bin index; 65535 the header"),
        signal("Raw0", 2, 16, Kind::Signed)
            .about("constant channel, LSB 2^-e0 A (header: exponents e0, e1)"),
        signal("Raw1", 4, 16, Kind::Signed)
            .about("per-pressure channel, LSB 2^-e1 A/Pa (header: exponent e2)"),
        signal("Raw2", 6, 16, Kind::Signed)
            .about("per-current channel, LSB 2^-e2 A/A (header: bin count)"),
    ]
}
