//! The drive's replies, one message per `can_protocol::Reply` kind: the status frame in
//! its wire scalings, the reject multiplexed by the refused function (the violated bound
//! in that command's unit), the parameter value, and the drive's diagnostics.

use super::signal::{ascii, signal, Kind, Message, Mux, Sender, Signal};
use super::values::{
    fault_choices, function_choices, mode_choices, parameter_choices, parameter_values,
    reason_choices,
};
use firmware::can_protocol::{
    id, Function, NO_COMMAND, SETPOINT_PA_PER_LSB, SETPOINT_RAD_S_PER_LSB, STATUS_PA_PER_LSB,
    STATUS_RAD_S_PER_LSB,
};

/// The reply kinds, one message each.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReplyKind {
    /// `Reply::Status`.
    Status,
    /// `Reply::Reject`.
    Reject,
    /// `Reply::Parameter`.
    Parameter,
    /// `Reply::Diagnostics`.
    Diagnostics,
}

impl ReplyKind {
    /// Every reply kind.
    pub const ALL: [ReplyKind; 4] = [
        ReplyKind::Status,
        ReplyKind::Reject,
        ReplyKind::Parameter,
        ReplyKind::Diagnostics,
    ];

    /// The kind of a reply (exhaustive: a new reply breaks the build here).
    pub fn of(r: &firmware::can_protocol::Reply) -> ReplyKind {
        use firmware::can_protocol::Reply;
        match r {
            Reply::Status(_) => ReplyKind::Status,
            Reply::Reject(_) => ReplyKind::Reject,
            Reply::Parameter { .. } => ReplyKind::Parameter,
            Reply::Diagnostics(_) => ReplyKind::Diagnostics,
        }
    }
}

/// The bound of a reject of `f`: its signal, unit and kind.
fn reject_bound(f: Function) -> Signal {
    let name = format!("Bound_{f:?}");
    let base = signal(&name, 2, 32, Kind::Signed).mux(Mux::Case(f.code()));
    match f {
        Function::SetPressure => base
            .scaled(SETPOINT_PA_PER_LSB, "Pa")
            .about("violated bound (Pa); for reason 5 the blocking fault's code"),
        Function::SetSpeed => base
            .scaled(SETPOINT_RAD_S_PER_LSB, "rad/s")
            .about("violated bound (rad/s); for reason 5 the blocking fault's code"),
        Function::SetParameter
        | Function::GetParameter
        | Function::SaveParameters
        | Function::StepTest
        | Function::CompensationBin
        | Function::CompensationCommit
        | Function::CompensationSweep => Signal {
            kind: Kind::Float,
            ..base
        }
        .about(
            "violated bound as f32 in SI units (the parameter's unit; A, rad/s, Pa or s for a \
             step; the amplitude limit in A or the bin expected for a table frame; the needed \
             mode for reason 5); for reasons 3, 6, 8 the bits are an integer",
        ),
        Function::SetMode | Function::ClearFaults | Function::Heartbeat | Function::Commission => {
            base.about(
                "the mode code, expected length, blocking fault code or readiness code the \
                 reason names",
            )
        }
    }
}

/// A reply's message.
pub(super) fn reply(kind: ReplyKind) -> Message {
    let u8s = |n: &str, byte| signal(n, byte, 8, Kind::Unsigned);
    let (base, name, comment, signals) = match kind {
        ReplyKind::Status => {
            let mut last = function_choices();
            last.push((i64::from(NO_COMMAND), "none".to_string()));
            (
                id::STATUS,
                "Status",
                "periodic status, and the answer to an accepted command",
                vec![
                    u8s("Mode", 0).choices(mode_choices()).about("mode code"),
                    u8s("Fault", 1)
                        .choices(fault_choices())
                        .about("latched fault code, 0 none"),
                    signal("Pressure", 2, 16, Kind::Signed)
                        .scaled(STATUS_PA_PER_LSB, "Pa")
                        .about("measured pressure, gauge (saturating)"),
                    signal("Speed", 4, 16, Kind::Signed)
                        .scaled(STATUS_RAD_S_PER_LSB, "rad/s")
                        .about("measured shaft speed (saturating)"),
                    u8s("LastCommand", 6)
                        .choices(last)
                        .about("function code of the last accepted command"),
                    u8s("Sequence", 7).about("status counter, wraps at 256"),
                ],
            )
        }
        ReplyKind::Reject => {
            let mut s = vec![
                u8s("Function", 0)
                    .mux(Mux::Switch)
                    .choices(function_choices())
                    .about("function code of the refused command"),
                u8s("Reason", 1)
                    .choices(reason_choices())
                    .about("why it was refused"),
            ];
            s.extend(Function::ALL.iter().map(|f| reject_bound(*f)));
            s.push(
                u8s("Parameter", 6)
                    .choices(parameter_choices())
                    .about("parameter id (or unknown code) the refusal concerns, 0 none"),
            );
            (
                id::REJECT,
                "Reject",
                "a refused command: function, reason, violated bound",
                s,
            )
        }
        ReplyKind::Parameter => (
            id::PARAMETER,
            "Parameter",
            "a live parameter's value in use (answer to SetParameter and GetParameter)",
            parameter_values(),
        ),
        ReplyKind::Diagnostics => (
            id::DIAGNOSTICS,
            "Diagnostics",
            "the drive's measurements of itself, once a second",
            vec![
                signal("StackPeak", 0, 32, Kind::Unsigned)
                    .unit("B")
                    .about("stack high-water mark since power-up"),
                signal("StackSize", 4, 32, Kind::Unsigned)
                    .unit("B")
                    .about("the stack's size: the RAM below the static data"),
            ],
        ),
    };
    Message {
        base,
        name,
        dlc: 8,
        sender: Sender::Drive,
        comment: ascii(comment),
        signals,
    }
}
