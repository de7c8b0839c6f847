//! `eha ingest`: the firmware's defmt telemetry, as the host decoder prints it (`probe-rs
//! run`, `defmt-print`, or `cargo xtask`'s PIL decoder), turned into a bench log.
//!
//! Each line holding the tag `EHA1 ` is a telemetry frame and is parsed by the firmware's
//! own [`firmware::telemetry::parse_line`] — one definition of the line format for the
//! target that writes it and the host that reads it. Whatever the decoder put before the
//! tag (timestamp, level) is ignored; lines without the tag (other logs, the decoder's
//! location lines, blank lines) are skipped and counted.
//!
//! Strict about telemetry: a tagged line that does not parse, a value that is not finite
//! and a time that does not increase (a controller reset mid-log) are each reported with
//! file, line and field, and any of them fails the whole ingest with exit status 2 and no
//! output file. A bench log from a partly garbled capture would look trustworthy to `eha
//! diagnose` and `eha tune`; re-capturing (or cutting the log at the reset) is the fix.

use crate::bench_log::limits::{
    line_too_long, max_rows, physical_range, LineLimited, MAX_LINE_BYTES, MIN_SAMPLE_INTERVAL_S,
};
use crate::bench_log::{self, time_problem, BenchLog, Problem, Signal, MIN_ROWS};
use crate::output::paths::Declared;
use crate::output::{CliError, Outputs};
use clap::Args;
use firmware::telemetry::{parse_line, ParseError, TelemetryFrame, COLUMNS};
use std::fmt;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

/// `eha ingest`.
#[derive(Debug, Args)]
pub struct IngestArgs {
    /// The decoder's output (`probe-rs run` or `defmt-print`).
    #[arg(value_name = "DEFMT_LOG")]
    pub defmt_log: PathBuf,
    /// Bench log to write.
    #[arg(long, value_name = "LOG.csv")]
    pub out: PathBuf,
}

impl IngestArgs {
    /// The files it reads and writes.
    pub fn paths(&self) -> Declared<'_> {
        Declared::default()
            .input("DEFMT_LOG", Some(&self.defmt_log))
            .file("--out", Some(&self.out))
    }
}

/// How many malformed lines the error message lists (all are counted).
const LISTED: usize = 10;

/// How many malformed lines are kept (the rest only counted: a capture of garbage must not
/// fill the memory).
pub const KEPT: usize = 100;

/// What is wrong with one telemetry line.
#[derive(Clone, Debug, PartialEq)]
pub enum LineProblem {
    /// The line has the tag but does not parse.
    Parse(ParseError),
    /// A field parsed to NaN or an infinity (the bench log holds finite numbers only).
    NotFinite(&'static str),
    /// A field outside its column's physical range (the bench log's
    /// [`physical_range`]).
    OutOfRange(&'static str, f64),
    /// The frame's time does not exceed the previous frame's.
    TimeNotIncreasing {
        /// The previous frame's time. [s]
        previous: f64,
        /// This frame's time. [s]
        value: f64,
    },
    /// The frame follows the previous one closer in time than any sampler logs
    /// ([`MIN_SAMPLE_INTERVAL_S`]).
    IntervalTooShort {
        /// The previous frame's time. [s]
        previous: f64,
        /// This frame's time. [s]
        value: f64,
    },
}

impl fmt::Display for LineProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LineProblem::Parse(e) => write!(f, "{e}"),
            LineProblem::NotFinite(k) => write!(f, "field `{k}` is not a finite number"),
            LineProblem::OutOfRange(k, v) => {
                let (low, high, unit) = Signal::from_name(k).map_or((0.0, 0.0, ""), physical_range);
                write!(
                    f,
                    "field `{k}` = {v:e} {unit} lies outside the physical range {low:e} to \
                     {high:e} {unit}"
                )
            }
            LineProblem::TimeNotIncreasing { previous, value } => write!(
                f,
                "field `t_s`: time {value} s does not exceed the previous frame's {previous} s \
                 (controller reset?)"
            ),
            LineProblem::IntervalTooShort { previous, value } => write!(
                f,
                "field `t_s`: time {value} s follows the previous frame's {previous} s by \
                 {:.3e} s; no sampler logs frames less than {MIN_SAMPLE_INTERVAL_S:e} s apart",
                value - previous
            ),
        }
    }
}

/// A malformed telemetry line.
#[derive(Clone, Debug, PartialEq)]
pub struct Malformed {
    /// 1-based line number in the input.
    pub line: usize,
    /// What is wrong.
    pub problem: LineProblem,
}

/// The result of reading a decoder's output.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Ingested {
    /// The telemetry as a bench log (metadata: source and counts).
    pub log: BenchLog,
    /// Lines without the telemetry tag, skipped.
    pub skipped: usize,
    /// Telemetry lines that do not parse or break the bench-log rules: the first [`KEPT`].
    pub malformed: Vec<Malformed>,
    /// How many telemetry lines were malformed in all.
    pub malformed_count: usize,
    /// Frames that carried a latched fault.
    pub faulted_frames: usize,
}

impl Ingested {
    /// Telemetry frames taken into the log.
    pub fn frames(&self) -> usize {
        self.log.len()
    }

    /// Counts a malformed line, keeping the first [`KEPT`].
    fn note(&mut self, line: usize, problem: LineProblem) {
        self.malformed_count += 1;
        if self.malformed.len() < KEPT {
            self.malformed.push(Malformed { line, problem });
        }
    }
}

/// Why ingest failed.
#[derive(Debug, thiserror::Error)]
pub enum IngestError {
    /// The input cannot be read.
    #[error("defmt log `{}`: {source}", file.display())]
    Read {
        /// The file.
        file: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// Malformed telemetry lines (all counted, the first few listed).
    #[error("{}", malformed_message(file, malformed, *count))]
    Malformed {
        /// The file.
        file: PathBuf,
        /// The first malformed lines.
        malformed: Vec<Malformed>,
        /// How many there are.
        count: usize,
    },
    /// A line longer than any decoder prints (a binary file?).
    #[error(
        "defmt log `{}`, line {line}: longer than {} bytes; not a decoder's text output",
        file.display(),
        MAX_LINE_BYTES
    )]
    LineTooLong {
        /// The file.
        file: PathBuf,
        /// 1-based line.
        line: usize,
    },
    /// More telemetry frames than a bench log may hold.
    #[error(
        "defmt log `{}`: more than {} telemetry lines; a bench log of the telemetry's \
         columns holds at most that many rows (split the capture)",
        file.display(),
        max_rows(COLUMNS.len())
    )]
    TooManyFrames {
        /// The file.
        file: PathBuf,
    },
    /// Too few frames for a bench log.
    #[error(
        "defmt log `{}`: only {frames} telemetry lines (`EHA1 …`) among {lines} lines; a bench \
         log needs at least {MIN_ROWS}",
        file.display()
    )]
    TooFewFrames {
        /// The file.
        file: PathBuf,
        /// Frames found.
        frames: usize,
        /// Lines read.
        lines: usize,
    },
}

fn malformed_message(file: &Path, malformed: &[Malformed], count: usize) -> String {
    let mut s = format!(
        "defmt log `{}`: {} malformed telemetry line{}",
        file.display(),
        count,
        if count == 1 { "" } else { "s" }
    );
    for m in malformed.iter().take(LISTED) {
        s.push_str(&format!("\n  {}:{}: {}", file.display(), m.line, m.problem));
    }
    if count > LISTED {
        s.push_str(&format!("\n  … and {} more", count - LISTED));
    }
    s
}

/// The first non-finite field of a frame, by its column name.
fn non_finite_field(f: &TelemetryFrame) -> Option<&'static str> {
    if !f.t_s.is_finite() {
        return Some(COLUMNS[0]);
    }
    let v = frame_values(f);
    COLUMNS
        .iter()
        .zip(v)
        .skip(1)
        .find(|(_, x)| !x.is_finite())
        .map(|(k, _)| *k)
}

/// The first field of a frame outside its column's physical range, with its value.
fn out_of_range_field(f: &TelemetryFrame) -> Option<(&'static str, f64)> {
    COLUMNS.iter().zip(frame_values(f)).find_map(|(k, v)| {
        let (low, high, _) = physical_range(Signal::from_name(k)?);
        (!(low..=high).contains(&v)).then_some((*k, v))
    })
}

/// A frame's values in [`COLUMNS`] order (the bench-log column names). [SI]
pub fn frame_values(f: &TelemetryFrame) -> [f64; 12] {
    [
        f.t_s,
        f.p_ref_pa as f64,
        f.p_pa as f64,
        f.speed_rad_s as f64,
        f.iq_a as f64,
        f.id_a as f64,
        f.theta_m_rad as f64,
        f.speed_ref_rad_s as f64,
        f.iq_ref_a as f64,
        f.ud_v as f64,
        f.uq_v as f64,
        f.udc_v as f64,
    ]
}

/// What one line of a decoder's output holds.
#[derive(Clone, Debug, PartialEq)]
pub enum Line {
    /// A telemetry frame fit for a bench log.
    Frame(TelemetryFrame),
    /// No telemetry tag: another log line, a location line, a blank line.
    Other,
    /// A telemetry line that does not parse or breaks the bench-log rules.
    Malformed(LineProblem),
}

/// Classifies a decoder's output line by line: the firmware's [`parse_line`], then the
/// bench log's rules (finite values, physical ranges, time increasing from frame to frame).
/// `eha ingest` and `eha watch` read telemetry through it.
#[derive(Clone, Debug, Default)]
pub struct LineReader {
    /// The last accepted frame's time. [s]
    last_t: Option<f64>,
}

impl LineReader {
    /// What `text` (one line, its line break removed or not) holds; an accepted frame's
    /// time becomes the one the next must exceed.
    pub fn classify(&mut self, text: &str) -> Line {
        let text = text.trim_end_matches(['\n', '\r']);
        let frame = match parse_line(text) {
            Ok(f) => f,
            Err(ParseError::NoTag) => return Line::Other,
            Err(e) => return Line::Malformed(LineProblem::Parse(e)),
        };
        if let Some(k) = non_finite_field(&frame) {
            return Line::Malformed(LineProblem::NotFinite(k));
        }
        if let Some((k, v)) = out_of_range_field(&frame) {
            return Line::Malformed(LineProblem::OutOfRange(k, v));
        }
        let value = frame.t_s;
        match self.last_t.and_then(|p| Some((p, time_problem(p, value)?))) {
            Some((previous, Problem::TimeNotIncreasing { .. })) => {
                return Line::Malformed(LineProblem::TimeNotIncreasing { previous, value })
            }
            Some((previous, _)) => {
                return Line::Malformed(LineProblem::IntervalTooShort { previous, value })
            }
            None => {}
        }
        self.last_t = Some(frame.t_s);
        Line::Frame(frame)
    }
}

/// Reads a decoder's output from `input` (`file` names it in messages). Returns the log
/// and the counts whatever they are; [`check`] decides whether the result is usable.
pub fn read<R: BufRead>(mut input: R, file: &Path) -> Result<(Ingested, usize), IngestError> {
    let mut out = Ingested::default();
    let mut buf = Vec::new();
    let mut line_no = 0usize;
    let mut reader = LineReader::default();
    loop {
        buf.clear();
        let n =
            input
                .read_until(b'\n', &mut buf)
                .map_err(|source| match line_too_long(&source) {
                    Some(line) => IngestError::LineTooLong {
                        file: file.to_path_buf(),
                        line,
                    },
                    None => IngestError::Read {
                        file: file.to_path_buf(),
                        source,
                    },
                })?;
        if n == 0 {
            break;
        }
        line_no += 1;
        // A decoder's output may carry bytes that are not UTF-8 on lines that are not
        // telemetry; telemetry itself is ASCII, so a lossy view loses nothing of it.
        let frame = match reader.classify(&String::from_utf8_lossy(&buf)) {
            Line::Frame(f) => f,
            Line::Other => {
                out.skipped += 1;
                continue;
            }
            Line::Malformed(problem) => {
                out.note(line_no, problem);
                continue;
            }
        };
        if out.frames() == max_rows(COLUMNS.len()) {
            return Err(IngestError::TooManyFrames {
                file: file.to_path_buf(),
            });
        }
        if frame.fault.is_some() {
            out.faulted_frames += 1;
        }
        // The line's keys are bench-log column names (a test checks every one is known).
        for (s, v) in COLUMNS
            .iter()
            .filter_map(|c| Signal::from_name(c))
            .zip(frame_values(&frame))
        {
            out.log.column_mut(s).push(v);
        }
    }
    Ok((out, line_no))
}

/// Fails on any malformed line and on too few frames for a bench log.
pub fn check(ingested: &Ingested, lines: usize, file: &Path) -> Result<(), IngestError> {
    if ingested.malformed_count > 0 {
        return Err(IngestError::Malformed {
            file: file.to_path_buf(),
            malformed: ingested.malformed.clone(),
            count: ingested.malformed_count,
        });
    }
    if ingested.frames() < MIN_ROWS {
        return Err(IngestError::TooFewFrames {
            file: file.to_path_buf(),
            frames: ingested.frames(),
            lines,
        });
    }
    Ok(())
}

/// `eha ingest DEFMT_LOG --out LOG.csv`.
pub fn run_ingest(args: &IngestArgs) -> Result<(), CliError> {
    let file = &args.defmt_log;
    let input = File::open(file).map_err(|source| {
        CliError::BadInput(
            IngestError::Read {
                file: file.clone(),
                source,
            }
            .to_string(),
        )
    })?;
    let (mut ingested, lines) = read(BufReader::new(LineLimited::new(input)), file)
        .map_err(|e| CliError::BadInput(e.to_string()))?;
    check(&ingested, lines, file).map_err(|e| CliError::BadInput(e.to_string()))?;
    let name = file
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    ingested.log.metadata = vec![
        ("source".into(), "firmware telemetry".into()),
        ("ingested_from".into(), name),
        ("telemetry_lines".into(), ingested.frames().to_string()),
        ("skipped_lines".into(), ingested.skipped.to_string()),
        ("faulted_frames".into(), ingested.faulted_frames.to_string()),
    ];
    let mut out = Outputs::new();
    bench_log::stage(&mut out, "--out", &args.out, &ingested.log)?;
    out.commit()?;
    eprintln!(
        "ingest: {} telemetry lines of {lines} written to {} ({} other lines skipped, 0 \
         malformed{})",
        ingested.frames(),
        args.out.display(),
        ingested.skipped,
        if ingested.faulted_frames > 0 {
            format!("; {} frames carry a latched fault", ingested.faulted_frames)
        } else {
            String::new()
        }
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmware::{FaultCode, Mode};

    fn frame(i: usize) -> TelemetryFrame {
        TelemetryFrame {
            t_s: i as f64 * 5e-4,
            p_ref_pa: 5e6,
            p_pa: 4.99e6 + i as f32,
            speed_rad_s: 6.25,
            iq_a: 0.5,
            id_a: -0.03125,
            theta_m_rad: 1.5,
            speed_ref_rad_s: 6.0,
            iq_ref_a: 0.625,
            ud_v: -1.5,
            uq_v: 2.25,
            udc_v: 280.0,
            mode: Mode::Pressure,
            fault: None,
            command_status: 0,
        }
    }

    fn line(f: &TelemetryFrame) -> String {
        let mut s = String::new();
        f.write_line(&mut s).unwrap();
        s
    }

    fn ingest(text: &str) -> Ingested {
        read(text.as_bytes(), Path::new("x.log")).unwrap().0
    }

    #[test]
    fn decoder_prefixes_and_location_lines_are_handled() {
        // defmt-print's default layout: "<timestamp> <LEVEL> <message>" then the location.
        let mut text = String::new();
        for i in 0..3 {
            text.push_str(&format!("0.00{i} INFO  {}\r\n", line(&frame(i))));
            text.push_str("└─ firmware::telemetry @ firmware/src/telemetry.rs:140\n");
        }
        let r = ingest(&text);
        assert_eq!((r.frames(), r.skipped, r.malformed.len()), (3, 3, 0));
        // Every column as written (values chosen exact in f32).
        assert_eq!(r.log.t_s, [0.0, 5e-4, 1e-3]);
        assert_eq!(r.log.p_pa, [4.99e6, 4.99e6 + 1.0, 4.99e6 + 2.0]);
        assert_eq!(r.log.id_a, [-0.03125; 3]);
        assert_eq!(r.log.udc_v.as_deref(), Some(&[280.0; 3][..]));
        assert_eq!(r.log.iq_ref_a.as_deref(), Some(&[0.625; 3][..]));
    }

    #[test]
    fn every_telemetry_column_is_a_bench_log_column() {
        for c in COLUMNS {
            assert!(Signal::from_name(c).is_some(), "{c}");
        }
    }

    #[test]
    fn interleaved_logs_are_skipped_and_counted() {
        let text = format!(
            "INFO  boot\n{}\nWARN  overrun\n\n\u{fffd}\u{1}binary\nDEBUG EHA1\n{}\n",
            line(&frame(0)),
            line(&frame(1))
        );
        let r = ingest(&text);
        // "DEBUG EHA1" has no `EHA1 ` tag (nothing after it): another log line.
        assert_eq!((r.frames(), r.skipped, r.malformed.len()), (2, 5, 0));
    }

    #[test]
    fn malformed_telemetry_is_reported_with_its_line_and_field() {
        let good = line(&frame(0));
        let mut nan = frame(2);
        nan.iq_a = f32::NAN;
        let text = [
            good.clone(),
            good.replace(" p_pa=", " p_pa=x"),  // line 2: bad value
            line(&nan),                         // line 3: NaN
            good.replace(" mode=3", " mode=9"), // line 4: unknown mode
            good.split(" iq_a=").next().unwrap().into(), // line 5: truncated
            line(&frame(1)),                    // line 6: good
            line(&frame(1)),                    // line 7: time repeats
        ]
        .join("\n");
        let r = ingest(&text);
        assert_eq!(r.frames(), 2);
        let found: Vec<(usize, LineProblem)> = r
            .malformed
            .iter()
            .map(|m| (m.line, m.problem.clone()))
            .collect();
        assert_eq!(
            found,
            [
                (2, LineProblem::Parse(ParseError::BadValue("p_pa"))),
                (3, LineProblem::NotFinite("iq_a")),
                (4, LineProblem::Parse(ParseError::BadMode)),
                (5, LineProblem::Parse(ParseError::Missing("iq_a"))),
                (
                    7,
                    LineProblem::TimeNotIncreasing {
                        previous: 5e-4,
                        value: 5e-4
                    }
                ),
            ]
        );
        let e = check(&r, 7, Path::new("x.log")).unwrap_err().to_string();
        assert!(e.contains("5 malformed telemetry lines"), "{e}");
        assert!(e.contains("x.log:2: field `p_pa` is not a number"), "{e}");
        assert!(e.contains("x.log:7: field `t_s`"), "{e}");
    }

    #[test]
    fn too_few_frames_and_faults_are_counted() {
        let mut f = frame(0);
        f.fault = Some(FaultCode::OverSpeed);
        let r = ingest(&format!("{}\n", line(&f)));
        assert_eq!(r.faulted_frames, 1);
        let e = check(&r, 1, Path::new("x.log")).unwrap_err().to_string();
        assert!(e.contains("only 1 telemetry lines"), "{e}");
    }
}
