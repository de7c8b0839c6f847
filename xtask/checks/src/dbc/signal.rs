//! The DBC file's model of a message and its signals: who sends it, its multiplexing, how
//! a signal's bits are read (Intel byte order, unsigned, two's complement or `f32`), its
//! scaling, range, unit and value table; and the text helpers every message uses (an
//! `f32` protocol constant's shortest decimal value, units spelled in ASCII).

/// Who sends a message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sender {
    /// The host (a PC, a PLC) commands.
    Host,
    /// The drive replies.
    Drive,
}

impl Sender {
    pub(super) fn name(self) -> &'static str {
        match self {
            Sender::Host => "Host",
            Sender::Drive => "Drive",
        }
    }

    pub(super) fn receiver(self) -> &'static str {
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

pub(super) fn signal(name: &str, byte: u32, bits: u32, kind: Kind) -> Signal {
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
    pub(super) fn scaled(mut self, factor: f32, unit: &str) -> Signal {
        // The constant's shortest decimal text, as the DBC file writes it.
        self.factor = shortest(factor);
        self.unit = ascii(unit);
        self
    }
    pub(super) fn unit(mut self, unit: &str) -> Signal {
        self.unit = ascii(unit);
        self
    }
    pub(super) fn range(mut self, lo: f64, hi: f64) -> Signal {
        self.range = Some((lo, hi));
        self
    }
    pub(super) fn mux(mut self, m: Mux) -> Signal {
        self.mux = m;
        self
    }
    pub(super) fn about(mut self, c: &str) -> Signal {
        self.comment = ascii(c);
        self
    }
    pub(super) fn choices(mut self, c: Vec<(i64, String)>) -> Signal {
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
