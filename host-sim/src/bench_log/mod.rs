//! The bench log, version 1 (`shared/contracts/bench-log.md`): the one CSV format of every
//! time series the project reads or writes — simulated runs, ingested firmware telemetry and
//! logs measured on a test rig — read and written here only.
//!
//! A file is optional `# key: value` metadata lines, one header row naming the columns (in
//! any order; columns are found by name), then one row per sample in SI units. The reader
//! rejects what the contract lists — a missing required column, a duplicated column name, a
//! value that is not a finite number, time that does not strictly increase, fewer than
//! [`MIN_ROWS`] data rows, a row with the wrong number of fields — with a [`BenchLogError`]
//! naming the file, the line and the column. Columns the contract does not know are skipped
//! unread (a rig's logger may add a text column); unknown metadata keys are kept. The keys
//! `drive` and `recorded_at` name the actuator and the start time ([`BenchLog::drive`],
//! [`BenchLog::recorded_at`]); [`read_metadata`] reads the metadata lines alone.
//!
//! Beyond the contract, for bounded memory and arithmetic: a line longer than
//! [`limits::MAX_LINE_BYTES`], more rows than [`limits::max_rows`] allows (at most
//! [`limits::MAX_ROWS`], and [`limits::MAX_VALUES`] values), more metadata than
//! [`limits::MAX_METADATA_LINES`] lines or [`limits::MAX_METADATA_BYTES`] bytes, a value
//! outside its column's physical range ([`limits::physical_range`]), or two rows closer in
//! time than any sampler logs ([`limits::MIN_SAMPLE_INTERVAL_S`]) is refused the same way.
//!
//! The writer checks the same rules first (so every file it writes reads back) and writes
//! the values in shortest round-trip notation, as an output of the command's transaction
//! ([`crate::output::Outputs`]): a failed write leaves no partial file.
//!
//! - [`columns`]: the columns, the metadata keys and a log in memory ([`BenchLog`]);
//! - [`reader`] and [`writer`]; [`rules`]: the rules on values both apply; [`error`]: what
//!   is wrong, and where;
//! - [`limits`]: the bounds beyond the contract; [`replayable`]: whether a log can be
//!   replayed on the rig.

pub mod columns;
pub mod error;
pub mod limits;
mod number;
pub mod reader;
pub mod replayable;
pub mod rules;
pub mod writer;

pub use columns::{BenchLog, Signal, DRIVE_KEY, MIN_ROWS, RECORDED_AT_KEY};
pub use error::{BenchLogError, Problem};
pub use reader::{parse, read, read_metadata, read_thinned};
pub use rules::time_problem;
pub use writer::{format_value, stage, to_bytes, write, write_into};

#[cfg(test)]
mod tests;
