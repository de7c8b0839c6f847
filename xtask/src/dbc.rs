//! `cargo xtask dbc [--node N] [--out FILE]`: the DBC description of the drive's CAN
//! protocol, generated from `firmware::can_protocol` and the tables it names — identifiers
//! from `can_protocol::id`, data lengths from `Function::dlc`, wire scalings from the
//! protocol's `*_PER_LSB` constants, value tables from the firmware's enumerations
//! (modes, fault codes, functions, reject reasons, step-test loops, parameter ids by name),
//! parameter units and bounds from `firmware::parameters`.
//!
//! Every command and reply has a message; signals are little endian (Intel). Where a
//! field's meaning depends on another, the message is multiplexed: `SetParameter` and
//! `Parameter` by the parameter id (one value signal per parameter, in its unit and
//! bounds), `StepTest` by the loop (amplitude in A, rad/s or Pa), `Reject` by the refused
//! function (the bound in that command's wire unit, or an `f32` in SI units for the
//! configuration functions). The byte positions are written here; the cantools check
//! ([`crate::can_check`]) holds them to the firmware's own encoder and decoder, value for
//! value, both ways.
//!
//! The checked-in `eha.dbc` is for node 1 (the application's `board::CAN_NODE`); for
//! another node pass `--node`, or decode with `cantools decode -m 0x7F0`, which matches
//! identifiers without their node bits.

use anyhow::{bail, Result};
use firmware::can_protocol::{
    id, Function, RejectReason, NO_COMMAND, SETPOINT_PA_PER_LSB, SETPOINT_RAD_S_PER_LSB,
    STATUS_PA_PER_LSB, STATUS_RAD_S_PER_LSB,
};
use firmware::parameters::ParamId;
use firmware::step_test::StepLoop;
use firmware::{FaultCode, Mode};
use std::fmt::Write as _;

/// The node the checked-in file describes (the application's `board::CAN_NODE`).
pub const DEFAULT_NODE: u8 = 1;
/// The checked-in file, relative to the workspace root.
pub const FILE: &str = "eha.dbc";

/// Who sends a message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sender {
    /// The host (a PC, a PLC) commands.
    Host,
    /// The drive replies.
    Drive,
}

impl Sender {
    fn name(self) -> &'static str {
        match self {
            Sender::Host => "Host",
            Sender::Drive => "Drive",
        }
    }

    fn receiver(self) -> &'static str {
        match self {
            Sender::Host => "Drive",
            Sender::Drive => "Host",
        }
    }
}

/// A signal's place in the multiplexing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mux {
    /// Always present.
    Plain,
    /// The multiplexer.
    Switch,
    /// Present when the multiplexer has this value.
    Case(u8),
}

/// How a signal's bits are read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Unsigned integer.
    Unsigned,
    /// Two's-complement integer.
    Signed,
    /// IEEE-754 single precision (32 bits).
    Float,
}

/// One signal.
#[derive(Clone, Debug, PartialEq)]
pub struct Signal {
    /// Name (unique in its message).
    pub name: String,
    /// First byte.
    pub byte: u32,
    /// Length. [bits]
    pub bits: u32,
    /// How the bits are read.
    pub kind: Kind,
    /// Physical value per raw unit. [unit/LSB]
    pub factor: f64,
    /// Physical range, `None` for the raw field's whole range.
    pub range: Option<(f64, f64)>,
    /// SI unit (ASCII).
    pub unit: String,
    /// Multiplexing.
    pub mux: Mux,
    /// What it is.
    pub comment: String,
    /// Value table: raw value and its name.
    pub choices: Vec<(i64, String)>,
}

/// One frame kind.
#[derive(Clone, Debug, PartialEq)]
pub struct Message {
    /// Identifier base (the node is added).
    pub base: u16,
    /// Name.
    pub name: &'static str,
    /// Data length. [bytes]
    pub dlc: u8,
    /// Who sends it.
    pub sender: Sender,
    /// What it does.
    pub comment: String,
    /// Its signals.
    pub signals: Vec<Signal>,
}

fn signal(name: &str, byte: u32, bits: u32, kind: Kind) -> Signal {
    Signal {
        name: name.to_string(),
        byte,
        bits,
        kind,
        factor: 1.0,
        range: None,
        unit: String::new(),
        mux: Mux::Plain,
        comment: String::new(),
        choices: Vec::new(),
    }
}

impl Signal {
    fn scaled(mut self, factor: f32, unit: &str) -> Signal {
        // The constant's shortest decimal text, as the DBC file writes it.
        self.factor = shortest(factor);
        self.unit = ascii(unit);
        self
    }
    fn unit(mut self, unit: &str) -> Signal {
        self.unit = ascii(unit);
        self
    }
    fn range(mut self, lo: f64, hi: f64) -> Signal {
        self.range = Some((lo, hi));
        self
    }
    fn mux(mut self, m: Mux) -> Signal {
        self.mux = m;
        self
    }
    fn about(mut self, c: &str) -> Signal {
        self.comment = ascii(c);
        self
    }
    fn choices(mut self, c: Vec<(i64, String)>) -> Signal {
        self.choices = c;
        self
    }
}

/// An `f32` constant as the f64 its shortest decimal text denotes (`1e-3` → 0.001).
pub fn shortest(x: f32) -> f64 {
    format!("{x}").parse().unwrap_or(f64::from(x))
}

/// Text for a DBC file (read as cp1252 by most tools): the units' `·`, `³`, `Ω` spelled
/// in ASCII.
pub fn ascii(s: &str) -> String {
    s.replace('·', "*")
        .replace('³', "3")
        .replace('²', "2")
        .replace('Ω', "Ohm")
        .replace(['—', '–'], "-")
        .replace('‥', "..")
        .replace('"', "'")
}

/// "BelowMinimum" → "below minimum".
fn words(debug_name: &str) -> String {
    let mut out = String::new();
    for (k, c) in debug_name.chars().enumerate() {
        if c.is_uppercase() && k > 0 {
            out.push(' ');
        }
        out.extend(c.to_lowercase());
    }
    out
}

/// Mode codes and names.
pub fn mode_choices() -> Vec<(i64, String)> {
    Mode::ALL
        .iter()
        .map(|m| (i64::from(m.code()), m.name().to_string()))
        .collect()
}

/// Fault codes and what they mean (0: none).
pub fn fault_choices() -> Vec<(i64, String)> {
    let mut v = vec![(0, "none".to_string())];
    v.extend(
        FaultCode::ALL
            .iter()
            .map(|f| (i64::from(f.code()), ascii(f.description()))),
    );
    v
}

/// Function codes and the commands' names.
pub fn function_choices() -> Vec<(i64, String)> {
    Function::ALL
        .iter()
        .map(|f| (i64::from(f.code()), format!("{f:?}")))
        .collect()
}

fn reason_choices() -> Vec<(i64, String)> {
    RejectReason::ALL
        .iter()
        .map(|r| (i64::from(r.code()), words(&format!("{r:?}"))))
        .collect()
}

fn loop_choices() -> Vec<(i64, String)> {
    StepLoop::ALL
        .iter()
        .map(|l| (i64::from(l.code()), words(&format!("{l:?}"))))
        .collect()
}

fn parameter_choices() -> Vec<(i64, String)> {
    ParamId::ALL
        .iter()
        .map(|p| (i64::from(p.code()), p.name().to_string()))
        .collect()
}

/// The signal name of a parameter's value (`speed.kp` → `speed_kp`).
pub fn parameter_signal(p: ParamId) -> String {
    p.name().replace('.', "_")
}

/// One value signal per parameter, multiplexed by the id at byte 0, the value at byte 1.
fn parameter_values() -> Vec<Signal> {
    let mut v = vec![signal("ParameterId", 0, 8, Kind::Unsigned)
        .mux(Mux::Switch)
        .choices(parameter_choices())
        .about("parameter id (firmware::parameters)")];
    v.extend(ParamId::ALL.iter().map(|p| {
        signal(&parameter_signal(*p), 1, 32, Kind::Float)
            .unit(p.unit())
            .range(shortest(p.min()), shortest(p.max()))
            .mux(Mux::Case(p.code()))
            .about(&format!("{} [{}]", p.name(), p.unit()))
    }));
    v
}

/// The step amplitude's unit per loop.
fn step_unit(l: StepLoop) -> &'static str {
    match l {
        StepLoop::Current => "A",
        StepLoop::Speed => "rad/s",
        StepLoop::Pressure => "Pa",
    }
}

/// A command's message.
fn command(f: Function) -> Message {
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
        Function::StepTest => {
            let mut s = vec![u8s("Loop")
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
            (
                "StepTest",
                "step one loop's reference with telemetry at full rate",
                s,
            )
        }
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
            vec![
                signal("Bin", 0, 16, Kind::Unsigned).about("bin index; 65535 the header"),
                signal("Raw0", 2, 16, Kind::Signed)
                    .about("constant channel, LSB 2^-e0 A (header: exponents e0, e1)"),
                signal("Raw1", 4, 16, Kind::Signed)
                    .about("per-pressure channel, LSB 2^-e1 A/Pa (header: exponent e2)"),
                signal("Raw2", 6, 16, Kind::Signed)
                    .about("per-current channel, LSB 2^-e2 A/A (header: bin count)"),
            ],
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
fn reply(kind: ReplyKind) -> Message {
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

/// Every message of the protocol.
pub fn messages() -> Vec<Message> {
    let mut v: Vec<Message> = Function::ALL.iter().map(|f| command(*f)).collect();
    v.extend(ReplyKind::ALL.iter().map(|k| reply(*k)));
    v.sort_by_key(|m| m.base);
    v
}

/// A number as the DBC file writes it: 15 significant digits at most, shortest text
/// (`32767 × 0.1` is `3276.7`, not its binary neighbour `3276.7000000000003`).
fn num(x: f64) -> String {
    let rounded: f64 = format!("{x:.14e}").parse().unwrap_or(x);
    format!("{rounded}")
}

/// The raw field's range times the factor.
fn full_range(s: &Signal) -> (f64, f64) {
    let (lo, hi) = match s.kind {
        Kind::Unsigned => (0.0, (2f64).powi(s.bits as i32) - 1.0),
        Kind::Signed => (
            -(2f64).powi(s.bits as i32 - 1),
            (2f64).powi(s.bits as i32 - 1) - 1.0,
        ),
        Kind::Float => (0.0, 0.0),
    };
    (lo * s.factor, hi * s.factor)
}

/// The DBC text for drive `node`.
pub fn generate(node: u8) -> Result<String> {
    if node > firmware::can_protocol::NODE_MAX {
        bail!(
            "node {node}: the protocol has nodes 0..={}",
            firmware::can_protocol::NODE_MAX
        );
    }
    let msgs = messages();
    let id_of = |m: &Message| u32::from(m.base) + u32::from(node);
    let mut t = String::new();
    t.push_str(
        "VERSION \"\"\n\n\nNS_ :\n\tCM_\n\tVAL_\n\tSIG_VALTYPE_\n\nBS_:\n\nBU_: Host Drive\n\n",
    );
    for m in &msgs {
        let _ = writeln!(
            t,
            "\nBO_ {} {}: {} {}",
            id_of(m),
            m.name,
            m.dlc,
            m.sender.name()
        );
        for s in &m.signals {
            let mux = match s.mux {
                Mux::Plain => String::new(),
                Mux::Switch => " M".to_string(),
                Mux::Case(v) => format!(" m{v}"),
            };
            let sign = if s.kind == Kind::Unsigned { '+' } else { '-' };
            let (lo, hi) = s.range.unwrap_or_else(|| full_range(s));
            let _ = writeln!(
                t,
                " SG_ {}{mux} : {}|{}@1{sign} ({},0) [{}|{}] \"{}\" {}",
                s.name,
                s.byte * 8,
                s.bits,
                num(s.factor),
                num(lo),
                num(hi),
                s.unit,
                m.sender.receiver()
            );
        }
    }
    t.push('\n');
    let _ = writeln!(
        t,
        "\nCM_ \"EHA drive CAN protocol (classic CAN 2.0A, node {node}): generated by `cargo xtask \
         dbc` from firmware::can_protocol; do not edit.\";"
    );
    for m in &msgs {
        let _ = writeln!(t, "CM_ BO_ {} \"{}\";", id_of(m), m.comment);
        for s in m.signals.iter().filter(|s| !s.comment.is_empty()) {
            let _ = writeln!(t, "CM_ SG_ {} {} \"{}\";", id_of(m), s.name, s.comment);
        }
    }
    for m in &msgs {
        for s in m.signals.iter().filter(|s| !s.choices.is_empty()) {
            let _ = write!(t, "VAL_ {} {}", id_of(m), s.name);
            for (v, name) in s.choices.iter().rev() {
                let _ = write!(t, " {v} \"{name}\"");
            }
            t.push_str(" ;\n");
        }
    }
    for m in &msgs {
        for s in m.signals.iter().filter(|s| s.kind == Kind::Float) {
            let _ = writeln!(t, "SIG_VALTYPE_ {} {} : 1;", id_of(m), s.name);
        }
    }
    if !t.is_ascii() {
        bail!("the DBC text has a character outside ASCII; spell it in `ascii()`");
    }
    Ok(t)
}

/// `cargo xtask dbc [--node N] [--out FILE] [--check]`.
pub fn dbc(args: &[String]) -> Result<()> {
    let mut node = DEFAULT_NODE;
    let mut out = crate::root().join(FILE);
    let mut check = false;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--node" => {
                let v = it.next().map(String::as_str).unwrap_or("");
                node = v
                    .parse()
                    .map_err(|_| anyhow::anyhow!("--node: `{v}` is not a node number 0..=15"))?;
            }
            "--out" => match it.next() {
                Some(p) => out = p.into(),
                None => bail!("--out needs a file"),
            },
            "--check" => check = true,
            other => bail!("dbc: unknown argument `{other}` (--node N, --out FILE, --check)"),
        }
    }
    let text = generate(node)?;
    if check {
        return check_in_sync(&text, &out);
    }
    std::fs::write(&out, text)?;
    eprintln!("xtask: wrote {} (node {node})", out.display());
    Ok(())
}

/// Fails when the checked-in file differs from what the firmware's definitions give.
pub fn check_in_sync(text: &str, file: &std::path::Path) -> Result<()> {
    let on_disk = std::fs::read_to_string(file).unwrap_or_default();
    if on_disk != text {
        bail!(
            "{} is out of sync with firmware::can_protocol: run `cargo xtask dbc` and commit it",
            file.display()
        );
    }
    eprintln!(
        "xtask: {} is in sync with firmware::can_protocol",
        file.display()
    );
    Ok(())
}
