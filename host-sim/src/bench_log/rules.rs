//! The contract's rules on values (`bench-log.md`, "Bad input", with the bounds of
//! [`super::limits`]), shared by the reader, row by row, and the writer, on the whole log
//! ([`BenchLog::check`]): finite values within their column's physical range, time strictly
//! increasing by more than a sampler's shortest interval, enough rows and not too many,
//! metadata lines that read back as written.

use super::columns::{BenchLog, Signal, MIN_ROWS};
use super::error::{BenchLogError, Problem};
use super::limits::{
    self, physical_range, MAX_METADATA_BYTES, MAX_METADATA_LINES, MIN_SAMPLE_INTERVAL_S,
};
use std::path::Path;

impl BenchLog {
    /// Checks the contract's rules on this log as [`super::writer::write`] would lay it out; errors name
    /// the line the offending value would have in the file.
    pub fn check(&self, file: &Path) -> Result<(), BenchLogError> {
        self.check_holding(file, &[])
    }

    /// [`BenchLog::check`] for a reader that never reads the columns of `unread` and may
    /// have let them go once they were checked as read (the diagnosis the pressure
    /// setpoint): one of them left empty passes; every other column is checked as always.
    pub fn check_holding(&self, file: &Path, unread: &[Signal]) -> Result<(), BenchLogError> {
        let content = |line: usize, column: &str, problem: Problem| BenchLogError::Content {
            file: file.to_path_buf(),
            line,
            column: column.to_string(),
            problem,
        };
        let mut bytes = 0usize;
        for (i, (k, v)) in self.metadata.iter().enumerate() {
            if !metadata_fits(k, v) {
                return Err(content(i + 1, k, Problem::BadMetadata));
            }
            bytes += k.len() + v.len();
            if i >= MAX_METADATA_LINES || bytes > MAX_METADATA_BYTES {
                return Err(content(i + 1, k, Problem::TooMuchMetadata));
            }
        }
        let header_line = self.metadata.len() + 1;
        let rows = self.len();
        for (s, c) in self.columns() {
            if c.is_empty() && unread.contains(&s) {
                continue;
            }
            if c.len() != rows {
                return Err(content(
                    header_line,
                    s.name(),
                    Problem::ColumnLength {
                        expected: rows,
                        found: c.len(),
                    },
                ));
            }
            if let Some(i) = c.iter().position(|v| !v.is_finite()) {
                return Err(content(
                    header_line + 1 + i,
                    s.name(),
                    Problem::NotANumber {
                        text: c[i].to_string(),
                    },
                ));
            }
            if let Some(i) = c.iter().position(|v| out_of_range(s, *v)) {
                return Err(content(header_line + 1 + i, s.name(), beyond(s, c[i])));
            }
        }
        let most = limits::max_rows(self.columns().count());
        if rows > most {
            return Err(content(
                header_line + 1 + most,
                Signal::Time.name(),
                Problem::TooManyRows { most },
            ));
        }
        let mut steps = self.t_s.windows(2).enumerate();
        if let Some((i, problem)) = steps.find_map(|(i, w)| Some((i, time_problem(w[0], w[1])?))) {
            return Err(content(header_line + 2 + i, Signal::Time.name(), problem));
        }
        if rows < MIN_ROWS {
            return Err(content(
                header_line + rows,
                Signal::Time.name(),
                Problem::TooFewRows { rows },
            ));
        }
        Ok(())
    }
}

/// Whether a metadata line `# k: v` can be written and read back as this key and value: a
/// non-empty key without `:`, line breaks or surrounding blanks, a value on one line.
pub(super) fn metadata_fits(k: &str, v: &str) -> bool {
    !k.trim().is_empty()
        && !k.contains([':', '\n', '\r'])
        && k.trim() == k
        && !v.contains(['\n', '\r'])
}

/// What is wrong with a row at `value` [s] after one at `previous` [s]: time going back or
/// standing, or a step shorter than any sampler makes.
pub fn time_problem(previous: f64, value: f64) -> Option<Problem> {
    if value <= previous {
        Some(Problem::TimeNotIncreasing { previous, value })
    } else if value - previous < MIN_SAMPLE_INTERVAL_S {
        Some(Problem::IntervalTooShort { previous, value })
    } else {
        None
    }
}

/// Whether `v` lies outside the physical range of `signal`'s column.
pub(super) fn out_of_range(signal: Signal, v: f64) -> bool {
    let (low, high, _) = physical_range(signal);
    !(low..=high).contains(&v)
}

/// The problem of a value outside its column's physical range.
pub(super) fn beyond(signal: Signal, value: f64) -> Problem {
    let (low, high, unit) = physical_range(signal);
    Problem::OutOfRange {
        value,
        low,
        high,
        unit,
    }
}
