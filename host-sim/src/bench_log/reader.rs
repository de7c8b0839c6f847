//! The reader (`bench-log.md`, "File" and "Bad input"): the `# key: value` metadata
//! lines, the header, whose columns are found by name (unknown ones skipped unread), then
//! the rows, each value checked as it is read ([`super::rules`]) within the bounds of
//! [`super::limits`]; the first fault is reported with its file, line and column.

use super::columns::{keeps_row, BenchLog, Signal, MIN_ROWS, THINNING_PROBE_ROWS};
use super::error::{BenchLogError, Problem};
use super::limits::{
    self, excerpt, line_too_long, LineLimited, MAX_METADATA_BYTES, MAX_METADATA_LINES,
};
use super::rules::{beyond, metadata_fits, out_of_range, time_problem};
use std::fs::File;
use std::io::{self, BufRead, BufReader, Read};
use std::path::Path;

/// Reads and checks a bench log.
pub fn read(path: &Path) -> Result<BenchLog, BenchLogError> {
    read_thinned(path, 0.0).map(|(log, _)| log)
}

/// Reads and checks a bench log, every row; of a log sampled faster than `min_interval_s`
/// (its first rows' median interval below it) keeps only rows at least that after the last
/// row kept (the first row always): such a log is kept at about that interval, its rows
/// unchanged, without holding the rest in memory. Returns the log and the number of rows
/// the file holds.
pub fn read_thinned(path: &Path, min_interval_s: f64) -> Result<(BenchLog, usize), BenchLogError> {
    let io_err = |source| BenchLogError::Read {
        file: path.to_path_buf(),
        source,
    };
    if let Some(why) = crate::output::file_kind::input_problem(path) {
        return Err(io_err(io::Error::new(io::ErrorKind::InvalidInput, why)));
    }
    let file = File::open(path).map_err(io_err)?;
    parse_thinned(BufReader::new(file), path, min_interval_s)
}

// A log too short to be probed is refused for its rows, so every log read was probed.
const _: () = assert!(THINNING_PROBE_ROWS <= MIN_ROWS);

/// Thins `log` (every row read so far) as [`BenchLog::thinned`] does; whether it was.
fn thin_whole(log: &mut BenchLog, min_interval_s: f64) -> bool {
    match log.thinned(min_interval_s) {
        Some(thinned) => {
            *log = thinned;
            true
        }
        None => false,
    }
}

/// Parses a bench log from `input`; `path` names it in errors.
pub fn parse<R: Read>(input: R, path: &Path) -> Result<BenchLog, BenchLogError> {
    parse_thinned(input, path, 0.0).map(|(log, _)| log)
}

/// [`parse`], keeping the rows [`read_thinned`] keeps; returns the log and the rows read.
fn parse_thinned<R: Read>(
    input: R,
    path: &Path,
    min_interval_s: f64,
) -> Result<(BenchLog, usize), BenchLogError> {
    let err =
        |line: usize, column: &str, problem: Problem| content_error(path, line, column, problem);
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
    let known = known_columns(&names, path, header_line)?;
    for &(_, s) in &known {
        log.column_mut(s);
    }
    let most_rows = limits::max_rows(known.len());

    let mut last_line = header_line;
    // Rows read, the previous row's time (the rules compare neighbours in the file) and
    // the row's values before it is kept or dropped.
    let mut rows = 0usize;
    let mut previous_t: Option<f64> = None;
    let mut values = vec![0.0; known.len()];
    // Whether rows are thinned: undecided until the first rows have been read.
    let mut thin: Option<bool> = (min_interval_s <= 0.0).then_some(false);
    while reader
        .read_record(&mut record)
        .map_err(|e| csv_err(e, last_line + 1))?
    {
        let line = line_of(&record, last_line + 1);
        last_line = line;
        if rows == most_rows {
            let problem = Problem::TooManyRows { most: most_rows };
            return Err(err(line, Signal::Time.name(), problem));
        }
        let row = Row {
            record: &record,
            line,
            path,
        };
        row.read_into(&names, &known, &mut values, &mut previous_t)?;
        rows += 1;
        let t = previous_t.unwrap_or(0.0);
        if thin != Some(true) || keeps_row(log.t_s.last().copied(), t, min_interval_s) {
            for (&v, &(_, s)) in values.iter().zip(&known) {
                log.column_mut(s).push(v);
            }
        }
        // The first rows kept whole tell whether the log is thinned at all; if so, they are
        // thinned as the rows after them are.
        if thin.is_none() && rows == THINNING_PROBE_ROWS {
            thin = Some(thin_whole(&mut log, min_interval_s));
        }
    }
    if rows < MIN_ROWS {
        return Err(err(
            last_line,
            Signal::Time.name(),
            Problem::TooFewRows { rows },
        ));
    }
    // The columns grew by doubling: hand back what they did not fill, so a log costs its
    // values and nothing more while the diagnosis holds it.
    for &(_, s) in &known {
        log.column_mut(s).shrink_to_fit();
    }
    Ok((log, rows))
}

/// The error of `path`'s content at `line` and `column`.
fn content_error(path: &Path, line: usize, column: &str, problem: Problem) -> BenchLogError {
    BenchLogError::Content {
        file: path.to_path_buf(),
        line,
        column: excerpt(column),
        problem,
    }
}

/// The header `names` (at `header_line` of `path`) checked: no name twice, every required
/// column present. Returns (field index, signal) of the columns the contract knows; others
/// are not read.
fn known_columns(
    names: &[String],
    path: &Path,
    header_line: usize,
) -> Result<Vec<(usize, Signal)>, BenchLogError> {
    let err = |column: &str, problem| content_error(path, header_line, column, problem);
    for (i, n) in names.iter().enumerate() {
        if let Some(j) = names[..i].iter().position(|m| m == n) {
            let problem = Problem::DuplicateColumn {
                first: j + 1,
                second: i + 1,
            };
            return Err(err(n, problem));
        }
    }
    for s in Signal::ALL.into_iter().filter(|s| s.is_required()) {
        if !names.iter().any(|n| n == s.name()) {
            return Err(err(s.name(), Problem::MissingColumn));
        }
    }
    Ok(names
        .iter()
        .enumerate()
        .filter_map(|(i, n)| Signal::from_name(n).map(|s| (i, s)))
        .collect())
}

/// One data row of the CSV, at `line` of `path`.
struct Row<'a> {
    record: &'a csv::StringRecord,
    line: usize,
    path: &'a Path,
}

impl Row<'_> {
    /// Reads the `known` columns of the row into `values`, each checked: the row has as
    /// many fields as the header `names`, every value is a finite number within its
    /// signal's range, and the time increases from `previous_t` (updated).
    fn read_into(
        &self,
        names: &[String],
        known: &[(usize, Signal)],
        values: &mut [f64],
        previous_t: &mut Option<f64>,
    ) -> Result<(), BenchLogError> {
        let err = |column: &str, problem| content_error(self.path, self.line, column, problem);
        let record = self.record;
        if record.len() != names.len() {
            let column = names
                .get(record.len().min(names.len().saturating_sub(1)))
                .filter(|_| record.len() < names.len())
                .cloned()
                .unwrap_or_else(|| format!("field {}", names.len() + 1));
            let problem = Problem::WrongFieldCount {
                expected: names.len(),
                found: record.len(),
            };
            return Err(err(&column, problem));
        }
        for (slot, &(i, s)) in values.iter_mut().zip(known) {
            let text = record.get(i).unwrap_or("");
            let v = match text.parse::<f64>() {
                Ok(v) if v.is_finite() => v,
                _ if text.is_empty() => return Err(err(s.name(), Problem::EmptyField)),
                _ => {
                    let problem = Problem::NotANumber {
                        text: excerpt(text),
                    };
                    return Err(err(s.name(), problem));
                }
            };
            if out_of_range(s, v) {
                return Err(err(s.name(), beyond(s, v)));
            }
            if s == Signal::Time {
                if let Some(problem) = previous_t.and_then(|p| time_problem(p, v)) {
                    return Err(err(s.name(), problem));
                }
                *previous_t = Some(v);
            }
            *slot = v;
        }
        Ok(())
    }
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
    if let Some(why) = crate::output::file_kind::input_problem(path) {
        return Err(io_err(io::Error::new(io::ErrorKind::InvalidInput, why)));
    }
    let file = File::open(path).map_err(io_err)?;
    let mut input = BufReader::new(LineLimited::new(file));
    let mut metadata = Vec::new();
    parse_metadata(&mut input, path, &mut metadata)?;
    Ok(metadata)
}
