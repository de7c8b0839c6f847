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

pub mod limits;
mod number;
pub mod replayable;

use limits::{
    excerpt, line_too_long, physical_range, LineLimited, MAX_LINE_BYTES, MAX_METADATA_BYTES,
    MAX_METADATA_LINES, MAX_ROWS, MAX_VALUES, MIN_SAMPLE_INTERVAL_S,
};

use std::fs::File;
use std::io::{self, BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};

/// The fewest data rows a bench log may have.
pub const MIN_ROWS: usize = 100;

/// Metadata key naming the actuator a log comes from (`# drive: ID`).
pub const DRIVE_KEY: &str = "drive";

/// Metadata key of the time a log started (`# recorded_at: 2026-11-30T14:05:00Z`, RFC 3339).
pub const RECORDED_AT_KEY: &str = "recorded_at";

/// A column of the contract.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Signal {
    /// `t_s`: time since the start of the log, strictly increasing. [s]
    Time,
    /// `p_ref_pa`: pressure setpoint seen by the controller. [Pa]
    PressureRef,
    /// `p_pa`: measured pressure on the pump's high-pressure port. [Pa]
    Pressure,
    /// `speed_rad_s`: measured shaft speed. [rad/s]
    Speed,
    /// `iq_a`: measured q-axis current. [A]
    Iq,
    /// `id_a`: measured d-axis current. [A]
    Id,
    /// `theta_m_rad`: shaft mechanical angle. [rad]
    ThetaM,
    /// `x_m`: piston position from mid-stroke. [m]
    PistonPosition,
    /// `p_low_pa`: pressure on the pump's low-pressure port. [Pa]
    PressureLow,
    /// `speed_ref_rad_s`: speed reference. [rad/s]
    SpeedRef,
    /// `iq_ref_a`: q-current reference. [A]
    IqRef,
    /// `ud_v`: commanded d-axis voltage. [V]
    Ud,
    /// `uq_v`: commanded q-axis voltage. [V]
    Uq,
    /// `udc_v`: measured DC-link voltage. [V]
    Udc,
    /// `oil_temp_c`: oil temperature. [°C]
    OilTemp,
}

impl Signal {
    /// Every column, required ones first, in the order the writer puts them.
    pub const ALL: [Signal; 15] = [
        Signal::Time,
        Signal::PressureRef,
        Signal::Pressure,
        Signal::Speed,
        Signal::Iq,
        Signal::Id,
        Signal::ThetaM,
        Signal::PistonPosition,
        Signal::PressureLow,
        Signal::SpeedRef,
        Signal::IqRef,
        Signal::Ud,
        Signal::Uq,
        Signal::Udc,
        Signal::OilTemp,
    ];

    /// The column name in the file.
    pub const fn name(self) -> &'static str {
        match self {
            Signal::Time => "t_s",
            Signal::PressureRef => "p_ref_pa",
            Signal::Pressure => "p_pa",
            Signal::Speed => "speed_rad_s",
            Signal::Iq => "iq_a",
            Signal::Id => "id_a",
            Signal::ThetaM => "theta_m_rad",
            Signal::PistonPosition => "x_m",
            Signal::PressureLow => "p_low_pa",
            Signal::SpeedRef => "speed_ref_rad_s",
            Signal::IqRef => "iq_ref_a",
            Signal::Ud => "ud_v",
            Signal::Uq => "uq_v",
            Signal::Udc => "udc_v",
            Signal::OilTemp => "oil_temp_c",
        }
    }

    /// Whether every bench log must have this column.
    pub const fn is_required(self) -> bool {
        matches!(
            self,
            Signal::Time
                | Signal::PressureRef
                | Signal::Pressure
                | Signal::Speed
                | Signal::Iq
                | Signal::Id
        )
    }

    /// The signal of a column name, if the contract knows it.
    pub fn from_name(name: &str) -> Option<Signal> {
        Signal::ALL.into_iter().find(|s| s.name() == name)
    }
}

/// One bench log: metadata and one vector per column, all of the same length.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BenchLog {
    /// The `# key: value` lines, in file order (unknown keys included).
    pub metadata: Vec<(String, String)>,
    /// Time since the start of the log, strictly increasing. [s]
    pub t_s: Vec<f64>,
    /// Pressure setpoint seen by the controller. [Pa]
    pub p_ref_pa: Vec<f64>,
    /// Measured pressure on the pump's high-pressure port (gauge). [Pa]
    pub p_pa: Vec<f64>,
    /// Measured motor (= pump) shaft speed. [rad/s]
    pub speed_rad_s: Vec<f64>,
    /// Measured q-axis current (amplitude-invariant Park transform). [A]
    pub iq_a: Vec<f64>,
    /// Measured d-axis current. [A]
    pub id_a: Vec<f64>,
    /// Shaft mechanical angle, wrapped or unwrapped. [rad]
    pub theta_m_rad: Option<Vec<f64>>,
    /// Piston position from mid-stroke; absent means blocked. [m]
    pub x_m: Option<Vec<f64>>,
    /// Pressure on the pump's low-pressure port (gauge). [Pa]
    pub p_low_pa: Option<Vec<f64>>,
    /// Speed reference. [rad/s]
    pub speed_ref_rad_s: Option<Vec<f64>>,
    /// q-current reference. [A]
    pub iq_ref_a: Option<Vec<f64>>,
    /// Commanded d-axis voltage. [V]
    pub ud_v: Option<Vec<f64>>,
    /// Commanded q-axis voltage. [V]
    pub uq_v: Option<Vec<f64>>,
    /// Measured DC-link voltage. [V]
    pub udc_v: Option<Vec<f64>>,
    /// Oil temperature. [°C]
    pub oil_temp_c: Option<Vec<f64>>,
}

impl BenchLog {
    /// Number of samples (rows).
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// The log from row `from` on (clamped to the last row), its time restarted at zero.
    pub fn tail(&self, from: usize) -> BenchLog {
        let k = from.min(self.len().saturating_sub(1));
        let cut = |v: &Vec<f64>| v.get(k..).map_or_else(Vec::new, <[f64]>::to_vec);
        let cut_opt = |v: &Option<Vec<f64>>| v.as_ref().map(cut);
        let t0 = self.t_s.get(k).copied().unwrap_or(0.0);
        BenchLog {
            metadata: self.metadata.clone(),
            t_s: cut(&self.t_s).into_iter().map(|t| t - t0).collect(),
            p_ref_pa: cut(&self.p_ref_pa),
            p_pa: cut(&self.p_pa),
            speed_rad_s: cut(&self.speed_rad_s),
            iq_a: cut(&self.iq_a),
            id_a: cut(&self.id_a),
            theta_m_rad: cut_opt(&self.theta_m_rad),
            x_m: cut_opt(&self.x_m),
            p_low_pa: cut_opt(&self.p_low_pa),
            speed_ref_rad_s: cut_opt(&self.speed_ref_rad_s),
            iq_ref_a: cut_opt(&self.iq_ref_a),
            ud_v: cut_opt(&self.ud_v),
            uq_v: cut_opt(&self.uq_v),
            udc_v: cut_opt(&self.udc_v),
            oil_temp_c: cut_opt(&self.oil_temp_c),
        }
    }

    /// The value of the first metadata line with `key`.
    pub fn meta(&self, key: &str) -> Option<&str> {
        self.metadata
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// The actuator the log comes from (`# drive: ID`), if the log names it.
    pub fn drive(&self) -> Option<&str> {
        self.meta(DRIVE_KEY)
    }

    /// When the log started (`# recorded_at: …`, RFC 3339, as written), if the log says.
    pub fn recorded_at(&self) -> Option<&str> {
        self.meta(RECORDED_AT_KEY)
    }

    /// The column of `signal`, `None` for an absent optional column.
    pub fn column(&self, signal: Signal) -> Option<&[f64]> {
        let c = match signal {
            Signal::Time => &self.t_s,
            Signal::PressureRef => &self.p_ref_pa,
            Signal::Pressure => &self.p_pa,
            Signal::Speed => &self.speed_rad_s,
            Signal::Iq => &self.iq_a,
            Signal::Id => &self.id_a,
            Signal::ThetaM => return self.theta_m_rad.as_deref(),
            Signal::PistonPosition => return self.x_m.as_deref(),
            Signal::PressureLow => return self.p_low_pa.as_deref(),
            Signal::SpeedRef => return self.speed_ref_rad_s.as_deref(),
            Signal::IqRef => return self.iq_ref_a.as_deref(),
            Signal::Ud => return self.ud_v.as_deref(),
            Signal::Uq => return self.uq_v.as_deref(),
            Signal::Udc => return self.udc_v.as_deref(),
            Signal::OilTemp => return self.oil_temp_c.as_deref(),
        };
        Some(c)
    }

    /// The column of `signal` for filling, created empty if it was an absent optional one.
    pub fn column_mut(&mut self, signal: Signal) -> &mut Vec<f64> {
        match signal {
            Signal::Time => &mut self.t_s,
            Signal::PressureRef => &mut self.p_ref_pa,
            Signal::Pressure => &mut self.p_pa,
            Signal::Speed => &mut self.speed_rad_s,
            Signal::Iq => &mut self.iq_a,
            Signal::Id => &mut self.id_a,
            Signal::ThetaM => self.theta_m_rad.get_or_insert_with(Vec::new),
            Signal::PistonPosition => self.x_m.get_or_insert_with(Vec::new),
            Signal::PressureLow => self.p_low_pa.get_or_insert_with(Vec::new),
            Signal::SpeedRef => self.speed_ref_rad_s.get_or_insert_with(Vec::new),
            Signal::IqRef => self.iq_ref_a.get_or_insert_with(Vec::new),
            Signal::Ud => self.ud_v.get_or_insert_with(Vec::new),
            Signal::Uq => self.uq_v.get_or_insert_with(Vec::new),
            Signal::Udc => self.udc_v.get_or_insert_with(Vec::new),
            Signal::OilTemp => self.oil_temp_c.get_or_insert_with(Vec::new),
        }
    }

    /// The columns present, in writing order.
    pub fn columns(&self) -> impl Iterator<Item = (Signal, &[f64])> {
        Signal::ALL
            .into_iter()
            .filter_map(|s| self.column(s).map(|c| (s, c)))
    }

    /// Checks the contract's rules on this log as [`write`] would lay it out; errors name
    /// the line the offending value would have in the file.
    pub fn check(&self, file: &Path) -> Result<(), BenchLogError> {
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
    #[error("bench log `{}`: {}", file.display(), crate::output::paths::describe(source))]
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
    /// Readable, but not replayable on the rig (see [`replayable`]).
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

/// Reads and checks a bench log.
pub fn read(path: &Path) -> Result<BenchLog, BenchLogError> {
    let io_err = |source| BenchLogError::Read {
        file: path.to_path_buf(),
        source,
    };
    if let Some(why) = crate::output::paths::input_problem(path) {
        return Err(io_err(io::Error::new(io::ErrorKind::InvalidInput, why)));
    }
    let file = File::open(path).map_err(io_err)?;
    parse(BufReader::new(file), path)
}

/// Parses a bench log from `input`; `path` names it in errors.
pub fn parse<R: Read>(input: R, path: &Path) -> Result<BenchLog, BenchLogError> {
    let err = |line: usize, column: &str, problem: Problem| BenchLogError::Content {
        file: path.to_path_buf(),
        line,
        column: excerpt(column),
        problem,
    };
    let io_err = |source| BenchLogError::Read {
        file: path.to_path_buf(),
        source,
    };
    let mut input = BufReader::new(LineLimited::new(input));
    let mut log = BenchLog::default();
    // Metadata and blank lines before the header; the CSV reader takes over at the first
    // other line, so its line numbers are offset by the lines consumed here.
    let consumed = parse_metadata(&mut input, path, &mut log.metadata)?;

    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(input);
    let mut record = csv::StringRecord::new();
    let line_of = |r: &csv::StringRecord, fallback: usize| {
        r.position()
            .map_or(fallback, |p| consumed + p.line() as usize)
    };
    let csv_err = |e: csv::Error, fallback: usize| {
        let line = e
            .position()
            .map_or(fallback, |p| consumed + p.line() as usize);
        match e.into_kind() {
            csv::ErrorKind::Io(source) => match line_too_long(&source) {
                Some(l) => err(l, "", Problem::LineTooLong),
                None => io_err(source),
            },
            csv::ErrorKind::Utf8 { .. } => err(line, "", Problem::NotUtf8),
            _ => err(line, "", Problem::Malformed("not CSV".into())),
        }
    };

    if !reader
        .read_record(&mut record)
        .map_err(|e| csv_err(e, consumed + 1))?
    {
        return Err(err(consumed + 1, "", Problem::NoHeader));
    }
    let header_line = line_of(&record, consumed + 1);
    let names: Vec<String> = record.iter().map(str::to_string).collect();
    for (i, n) in names.iter().enumerate() {
        if let Some(j) = names[..i].iter().position(|m| m == n) {
            return Err(err(
                header_line,
                n,
                Problem::DuplicateColumn {
                    first: j + 1,
                    second: i + 1,
                },
            ));
        }
    }
    for s in Signal::ALL.into_iter().filter(|s| s.is_required()) {
        if !names.iter().any(|n| n == s.name()) {
            return Err(err(header_line, s.name(), Problem::MissingColumn));
        }
    }
    // (field index, signal) of the columns the contract knows; others are not read.
    let known: Vec<(usize, Signal)> = names
        .iter()
        .enumerate()
        .filter_map(|(i, n)| Signal::from_name(n).map(|s| (i, s)))
        .collect();
    for &(_, s) in &known {
        log.column_mut(s);
    }
    let most_rows = limits::max_rows(known.len());

    let mut last_line = header_line;
    while reader
        .read_record(&mut record)
        .map_err(|e| csv_err(e, last_line + 1))?
    {
        let line = line_of(&record, last_line + 1);
        last_line = line;
        if log.len() == most_rows {
            let problem = Problem::TooManyRows { most: most_rows };
            return Err(err(line, Signal::Time.name(), problem));
        }
        if record.len() != names.len() {
            let column = names
                .get(record.len().min(names.len().saturating_sub(1)))
                .filter(|_| record.len() < names.len())
                .cloned()
                .unwrap_or_else(|| format!("field {}", names.len() + 1));
            return Err(err(
                line,
                &column,
                Problem::WrongFieldCount {
                    expected: names.len(),
                    found: record.len(),
                },
            ));
        }
        for &(i, s) in &known {
            let text = record.get(i).unwrap_or("");
            let v = match text.parse::<f64>() {
                Ok(v) if v.is_finite() => v,
                _ if text.is_empty() => return Err(err(line, s.name(), Problem::EmptyField)),
                _ => {
                    return Err(err(
                        line,
                        s.name(),
                        Problem::NotANumber {
                            text: excerpt(text),
                        },
                    ))
                }
            };
            if out_of_range(s, v) {
                return Err(err(line, s.name(), beyond(s, v)));
            }
            if s == Signal::Time {
                if let Some(problem) = log.t_s.last().and_then(|p| time_problem(*p, v)) {
                    return Err(err(line, s.name(), problem));
                }
            }
            log.column_mut(s).push(v);
        }
    }
    if log.len() < MIN_ROWS {
        return Err(err(
            last_line,
            Signal::Time.name(),
            Problem::TooFewRows { rows: log.len() },
        ));
    }
    Ok(log)
}

/// Reads the `# key: value` lines (and blank lines) before the header of `input` into
/// `metadata`, leaving `input` at the header; returns the lines consumed.
fn parse_metadata<R: BufRead>(
    input: &mut R,
    path: &Path,
    metadata: &mut Vec<(String, String)>,
) -> Result<usize, BenchLogError> {
    let err = |line: usize, column: &str, problem: Problem| BenchLogError::Content {
        file: path.to_path_buf(),
        line,
        column: excerpt(column),
        problem,
    };
    let io_err = |source| BenchLogError::Read {
        file: path.to_path_buf(),
        source,
    };
    let mut consumed = 0usize;
    let mut metadata_bytes = 0usize;
    let mut line = String::new();
    loop {
        let buf = input.fill_buf().map_err(io_err)?;
        let starts_meta = buf.first() == Some(&b'#')
            || (consumed == 0 && buf.starts_with("\u{feff}#".as_bytes()));
        let blank = buf.first() == Some(&b'\n') || buf.starts_with(b"\r\n");
        if !(starts_meta || blank) {
            return Ok(consumed);
        }
        line.clear();
        input.read_line(&mut line).map_err(|e| {
            if let Some(l) = line_too_long(&e) {
                err(l, "", Problem::LineTooLong)
            } else if e.kind() == io::ErrorKind::InvalidData {
                err(consumed + 1, "", Problem::NotUtf8)
            } else {
                io_err(e)
            }
        })?;
        consumed += 1;
        if starts_meta {
            let text = line.trim_start_matches('\u{feff}').trim_start_matches('#');
            let (k, v) = text.split_once(':').unwrap_or((text, ""));
            let (k, v) = (k.trim(), v.trim());
            if k.is_empty() && v.is_empty() {
                continue; // a bare `#`: nothing to keep, like a blank line
            }
            // What the writer could not write back (an empty key, a carriage return inside
            // the value) is refused here too, so every log read can be written.
            if !metadata_fits(k, v) {
                return Err(err(consumed, k, Problem::BadMetadata));
            }
            metadata_bytes += k.len() + v.len();
            if metadata.len() == MAX_METADATA_LINES || metadata_bytes > MAX_METADATA_BYTES {
                return Err(err(consumed, k, Problem::TooMuchMetadata));
            }
            metadata.push((k.to_string(), v.to_string()));
        }
    }
}

/// Reads only the metadata lines of the bench log at `path` (what `eha fleet` needs to
/// sort a log before diagnosing it), with the reader's rules for them; the rows are not
/// read or checked.
pub fn read_metadata(path: &Path) -> Result<Vec<(String, String)>, BenchLogError> {
    let io_err = |source| BenchLogError::Read {
        file: path.to_path_buf(),
        source,
    };
    if let Some(why) = crate::output::paths::input_problem(path) {
        return Err(io_err(io::Error::new(io::ErrorKind::InvalidInput, why)));
    }
    let file = File::open(path).map_err(io_err)?;
    let mut input = BufReader::new(LineLimited::new(file));
    let mut metadata = Vec::new();
    parse_metadata(&mut input, path, &mut metadata)?;
    Ok(metadata)
}

/// Whether a metadata line `# k: v` can be written and read back as this key and value: a
/// non-empty key without `:`, line breaks or surrounding blanks, a value on one line.
fn metadata_fits(k: &str, v: &str) -> bool {
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
fn out_of_range(signal: Signal, v: f64) -> bool {
    let (low, high, _) = physical_range(signal);
    !(low..=high).contains(&v)
}

/// The problem of a value outside its column's physical range.
fn beyond(signal: Signal, value: f64) -> Problem {
    let (low, high, unit) = physical_range(signal);
    Problem::OutOfRange {
        value,
        low,
        high,
        unit,
    }
}

/// Writes `log` to `path` as a command's one output ([`crate::output::Outputs`]), after
/// [`BenchLog::check`]: metadata lines, the header of the columns present, one row per
/// sample in shortest round-trip notation.
pub fn write(path: &Path, log: &BenchLog) -> Result<(), BenchLogError> {
    let mut out = crate::output::Outputs::new();
    stage(&mut out, "", path, log)
        .and_then(|()| out.commit())
        .map_err(|e| match e {
            crate::output::CliError::BenchLog(e) => e,
            crate::output::CliError::Write { file, source } => {
                BenchLogError::Write { file, source }
            }
            e => BenchLogError::Write {
                file: path.to_path_buf(),
                source: io::Error::other(e.to_string()),
            },
        })
}

/// Stages `log` (checked first) as the output file `path` given by `flag`.
pub fn stage(
    out: &mut crate::output::Outputs,
    flag: &str,
    path: &Path,
    log: &BenchLog,
) -> Result<(), crate::output::CliError> {
    log.check(path)?;
    out.file_with(flag, path, |w| write_to(w, log))
}

/// Writes `log` (checked first) as the file `name` of a staged output folder.
pub fn write_into(
    d: &crate::output::StagedFolder,
    name: &str,
    log: &BenchLog,
) -> Result<(), crate::output::CliError> {
    log.check(&d.shown(name))?;
    d.file_with(name, |w| write_to(w, log))
}

/// `log` as the bytes [`write`] puts in a file, after the same checks.
pub fn to_bytes(log: &BenchLog) -> Result<Vec<u8>, BenchLogError> {
    log.check(Path::new(IN_MEMORY))?;
    let mut out = Vec::new();
    write_to(&mut out, log).map_err(|source| BenchLogError::Write {
        file: PathBuf::from(IN_MEMORY),
        source,
    })?;
    Ok(out)
}

/// What errors about a log held in memory name as its file.
const IN_MEMORY: &str = "<in memory>";

/// Writes `log` (assumed checked) to `w`: the metadata lines, the header, the rows. Names
/// and numbers never need CSV quoting, so the rows are spelled directly, a block of them
/// at a time.
fn write_to(w: &mut dyn Write, log: &BenchLog) -> io::Result<()> {
    for (k, v) in &log.metadata {
        writeln!(w, "# {k}: {v}")?;
    }
    let columns: Vec<(Signal, &[f64])> = log.columns().collect();
    let names: Vec<&str> = columns.iter().map(|(s, _)| s.name()).collect();
    writeln!(w, "{}", names.join(","))?;
    let mut block: Vec<u8> = Vec::with_capacity(1 << 16);
    for row in 0..log.len() {
        for (k, (_, c)) in columns.iter().enumerate() {
            if k > 0 {
                block.push(b',');
            }
            number::push_bytes(&mut block, c.get(row).copied().unwrap_or(f64::NAN));
        }
        block.push(b'\n');
        if block.len() >= 1 << 15 {
            w.write_all(&block)?;
            block.clear();
        }
    }
    w.write_all(&block)?;
    w.flush()
}

/// Shortest round-trip text of `v`: the fewest digits that parse back to the same f64;
/// positional for ordinary magnitudes, exponent notation for very small or large ones
/// (where positional would spell out dozens of zeros) — Rust's float formatting, spelled
/// faster ([`number`]).
pub fn format_value(out: &mut String, v: f64) {
    number::push(out, v);
}

#[cfg(test)]
mod tests;
