//! What keeps reading a bench log bounded in memory and its messages readable, whatever the
//! file holds: a longest line ([`MAX_LINE_BYTES`], enforced below the CSV reader so a file
//! without line breaks is refused after that many bytes, not after filling the memory), a
//! most rows and values ([`max_rows`]), a most metadata lines and bytes ([`MAX_METADATA_LINES`],
//! [`MAX_METADATA_BYTES`]), the physical range of each column ([`physical_range`]), the
//! shortest interval between two rows a sampler makes ([`MIN_SAMPLE_INTERVAL_S`]), and
//! excerpts of offending fields instead of the fields whole ([`excerpt`]).

use super::columns::Signal;
use std::io::{self, Read};

/// The longest line a bench log may have: a row of every column in full precision is under
/// 400 bytes; a logger's extra text columns get the rest. [bytes]
pub const MAX_LINE_BYTES: usize = 64 * 1024;

/// The most data rows a bench log may have: ten minutes at 10 kHz is 6 million, the
/// contract's largest typical log; every row costs 8 bytes of memory per column read.
pub const MAX_ROWS: usize = 10_000_000;

/// The most values a bench log may hold, rows times the contract's columns present: ten
/// minutes at 10 kHz of all fifteen columns. Read, they take 720 MB, so that reading any
/// log, or simulating one, stays under 1 GiB of memory.
pub const MAX_VALUES: usize = 90_000_000;

/// The most data rows of a log with `columns` of the contract's columns: [`MAX_ROWS`], or
/// fewer so that it holds at most [`MAX_VALUES`] values.
pub const fn max_rows(columns: usize) -> usize {
    let by_values = MAX_VALUES / if columns == 0 { 1 } else { columns };
    if by_values < MAX_ROWS {
        by_values
    } else {
        MAX_ROWS
    }
}

/// The most `# key: value` lines a bench log may carry: a logger's header of its
/// configuration is tens to hundreds of lines; beyond this the lines are data, not a header.
pub const MAX_METADATA_LINES: usize = 10_000;

/// The most bytes the metadata's keys and values may hold together (each line up to
/// [`MAX_LINE_BYTES`], but not ten thousand of those). [bytes]
pub const MAX_METADATA_BYTES: usize = 1 << 20;

/// The shortest interval between two rows: no sampler of an actuator's signals logs faster
/// than 1 MHz (the drive's telemetry comes at most at its 20 kHz PWM rate, a laboratory
/// data logger at a few hundred kHz). Shorter steps are a time column in other units than
/// seconds, or times printed with too few digits for the rate. [s]
pub const MIN_SAMPLE_INTERVAL_S: f64 = 1e-6;

/// Characters of an offending field quoted in a message.
const EXCERPT_CHARS: usize = 40;

/// The range of values a column can physically hold, with its unit; beyond it a value is
/// no measurement of an actuator of this kind (and would overflow the arithmetic that
/// replays it).
pub const fn physical_range(signal: Signal) -> (f64, f64, &'static str) {
    match signal {
        Signal::Time => (-1e9, 1e9, "s"),
        // Gauge: absolute vacuum is −101 325 Pa; a transducer's offset may read below it,
        // but not twice as far.
        Signal::PressureRef | Signal::Pressure | Signal::PressureLow => (-2e5, 1e9, "Pa"),
        Signal::Speed | Signal::SpeedRef => (-1e5, 1e5, "rad/s"),
        Signal::Iq | Signal::Id | Signal::IqRef => (-1e5, 1e5, "A"),
        Signal::ThetaM => (-1e12, 1e12, "rad"),
        Signal::PistonPosition => (-1e3, 1e3, "m"),
        Signal::Ud | Signal::Uq | Signal::Udc => (-1e6, 1e6, "V"),
        Signal::OilTemp => (-273.15, 1e4, "°C"),
    }
}

/// `text` as quoted in a message: at most [`EXCERPT_CHARS`] characters, control
/// characters escaped, the length said when cut.
pub fn excerpt(text: &str) -> String {
    let mut out: String = text
        .chars()
        .take(EXCERPT_CHARS)
        .flat_map(char::escape_debug)
        .collect();
    let n = text.chars().count();
    if n > EXCERPT_CHARS {
        out.push_str(&format!("… ({} bytes)", text.len()));
    }
    out
}

/// A line longer than [`MAX_LINE_BYTES`]: carried inside an `io::Error` from the reader.
#[derive(Debug)]
pub struct LineTooLong {
    /// 1-based line number.
    pub line: usize,
}

impl std::fmt::Display for LineTooLong {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "line {} is longer than {MAX_LINE_BYTES} bytes",
            self.line
        )
    }
}

impl std::error::Error for LineTooLong {}

/// The line of a [`LineTooLong`] error, if `e` is one.
pub fn line_too_long(e: &io::Error) -> Option<usize> {
    e.get_ref()
        .and_then(|inner| inner.downcast_ref::<LineTooLong>())
        .map(|l| l.line)
}

/// A reader that fails with [`LineTooLong`] once a line exceeds [`MAX_LINE_BYTES`].
pub struct LineLimited<R> {
    inner: R,
    /// Bytes since the last line break.
    run: usize,
    /// Line breaks passed.
    breaks: usize,
    limit: usize,
}

impl<R: Read> LineLimited<R> {
    /// Wraps `inner` with the bench log's line limit.
    pub fn new(inner: R) -> Self {
        Self::with_limit(inner, MAX_LINE_BYTES)
    }

    /// Wraps `inner` with a limit of `limit` bytes per line.
    pub fn with_limit(inner: R, limit: usize) -> Self {
        LineLimited {
            inner,
            run: 0,
            breaks: 0,
            limit,
        }
    }
}

impl<R: Read> Read for LineLimited<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        for &b in &buf[..n] {
            if b == b'\n' {
                self.breaks += 1;
                self.run = 0;
            } else {
                self.run += 1;
                if self.run > self.limit {
                    return Err(io::Error::new(
                        io::ErrorKind::InvalidData,
                        LineTooLong {
                            line: self.breaks + 1,
                        },
                    ));
                }
            }
        }
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_line_is_refused_with_its_number_before_it_is_read_whole() {
        let text = format!("a\nbb\n{}\n", "x".repeat(100));
        let mut r = LineLimited::with_limit(text.as_bytes(), 10);
        let mut out = Vec::new();
        let e = r.read_to_end(&mut out).unwrap_err();
        assert_eq!(line_too_long(&e), Some(3));
        let mut ok = LineLimited::with_limit("short\nlines\n".as_bytes(), 10);
        assert!(ok.read_to_end(&mut out).is_ok());
    }

    #[test]
    fn excerpts_are_short_and_printable() {
        assert_eq!(excerpt("abc"), "abc");
        assert_eq!(excerpt("a\u{0}b"), "a\\0b");
        let long = "9".repeat(2_000_000);
        let e = excerpt(&long);
        assert!(e.len() < 80, "{e}");
        assert!(e.contains("2000000 bytes"), "{e}");
    }
}
