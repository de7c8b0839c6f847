//! What is wrong with a bench log, named as the contract asks (`bench-log.md`, "Bad
//! input": the file, the line and the column): the [`Problem`] at a place, and the
//! [`BenchLogError`] of a file that cannot be read, written or replayed, which tells bad
//! input (exit status 2) from a failure to write.

use super::columns::MIN_ROWS;
use super::limits::{
    MAX_LINE_BYTES, MAX_METADATA_BYTES, MAX_METADATA_LINES, MAX_ROWS, MAX_VALUES,
    MIN_SAMPLE_INTERVAL_S,
};
use std::io;
use std::path::PathBuf;

/// What is wrong at a place in a bench log.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Problem {
    /// No header row (the file is empty or holds only metadata).
    #[error("no header row")]
    NoHeader,
    /// A required column is absent from the header.
    #[error("required column is missing from the header")]
    MissingColumn,
    /// A column name appears twice in the header.
    #[error("column name appears twice in the header (fields {first} and {second})")]
    DuplicateColumn {
        /// 1-based field number of the first occurrence.
        first: usize,
        /// 1-based field number of the second occurrence.
        second: usize,
    },
    /// A field of a known column is not a finite number.
    #[error("`{text}` is not a finite number")]
    NotANumber {
        /// The field as written (an excerpt of a long one).
        text: String,
    },
    /// A field of a known column is empty.
    #[error("the field is empty; a number is required")]
    EmptyField,
    /// A value outside its column's physical range.
    #[error("{value:e} {unit} lies outside the physical range {low:e} to {high:e} {unit}")]
    OutOfRange {
        /// The value.
        value: f64,
        /// The range's low end.
        low: f64,
        /// The range's high end.
        high: f64,
        /// Its unit.
        unit: &'static str,
    },
    /// More rows than a bench log may have.
    #[error(
        "more than {most} data rows; a bench log holds at most {MAX_ROWS} rows and \
         {MAX_VALUES} values of the contract's columns: split the log"
    )]
    TooManyRows {
        /// The most rows a log of these columns may have.
        most: usize,
    },
    /// A line longer than a bench log's longest.
    #[error("line longer than {MAX_LINE_BYTES} bytes (not a bench log, or a binary file?)")]
    LineTooLong,
    /// A line that is not UTF-8 text.
    #[error("not UTF-8 text (a binary file?)")]
    NotUtf8,
    /// Time does not strictly increase.
    #[error("time {value} s does not exceed the previous row's {previous} s")]
    TimeNotIncreasing {
        /// The previous row's time. [s]
        previous: f64,
        /// This row's time. [s]
        value: f64,
    },
    /// Two rows closer in time than any sampler logs.
    #[error(
        "time {value} s follows the previous row's {previous} s by {:.3e} s; no sampler logs \
         rows less than {MIN_SAMPLE_INTERVAL_S:e} s apart (is t_s in seconds, printed with \
         enough digits?)",
        value - previous
    )]
    IntervalTooShort {
        /// The previous row's time. [s]
        previous: f64,
        /// This row's time. [s]
        value: f64,
    },
    /// More metadata than a bench log's header holds.
    #[error(
        "more than {MAX_METADATA_LINES} metadata lines or {MAX_METADATA_BYTES} bytes of \
         metadata; a bench log's `# key: value` lines are a short header"
    )]
    TooMuchMetadata,
    /// The log is too short.
    #[error("only {rows} data rows; a bench log needs at least {MIN_ROWS}")]
    TooFewRows {
        /// Data rows found.
        rows: usize,
    },
    /// A row has more or fewer fields than the header.
    #[error("row has {found} fields, the header has {expected}")]
    WrongFieldCount {
        /// Fields in the header.
        expected: usize,
        /// Fields in this row.
        found: usize,
    },
    /// The line is not valid CSV.
    #[error("malformed line: {0}")]
    Malformed(String),
    /// Writing: a column's length differs from the time column's.
    #[error("column has {found} values, the time column {expected}")]
    ColumnLength {
        /// Length of `t_s`.
        expected: usize,
        /// Length of this column.
        found: usize,
    },
    /// Writing: a metadata key is empty or holds `:` or a line break, or a value a line
    /// break.
    #[error("metadata must be `# key: value` on one line, with a non-empty key without `:`")]
    BadMetadata,
}

/// A bench log that cannot be read or written.
#[derive(Debug, thiserror::Error)]
pub enum BenchLogError {
    /// The file cannot be opened or read.
    #[error("bench log `{}`: {}", file.display(), crate::output::file_kind::describe(source))]
    Read {
        /// The file.
        file: PathBuf,
        /// Why.
        source: io::Error,
    },
    /// The file cannot be written.
    #[error("cannot write bench log `{}`: {source}", file.display())]
    Write {
        /// The file.
        file: PathBuf,
        /// Why.
        source: io::Error,
    },
    /// The content breaks the contract.
    #[error("bench log `{}`, line {line}{}: {problem}", file.display(), column_part(column))]
    Content {
        /// The file.
        file: PathBuf,
        /// 1-based line number in the file.
        line: usize,
        /// The column's name (or `field N` for a field beyond the header).
        column: String,
        /// What is wrong.
        problem: Problem,
    },
    /// Readable, but not replayable on the rig (see [`super::replayable`]).
    #[error("bench log `{}`, data row {}, t = {t_s} s, column `{column}`: {why}", file.display(), row + 1)]
    Replay {
        /// The file.
        file: PathBuf,
        /// 0-based data row.
        row: usize,
        /// Its time. [s]
        t_s: f64,
        /// The column.
        column: String,
        /// Why.
        why: String,
    },
}

/// `, column `name`` unless the error sits on no column.
fn column_part(column: &str) -> String {
    if column.is_empty() {
        String::new()
    } else {
        format!(", column `{column}`")
    }
}

impl BenchLogError {
    /// True when the fault is in the input (a bad or missing file), false for a failure to
    /// write output.
    pub fn is_bad_input(&self) -> bool {
        !matches!(self, BenchLogError::Write { .. })
    }
}
