//! The bench log `eha watch --out` writes as the frames arrive (`contracts/bench-log.md`,
//! the same columns and number text as `eha ingest`): rows go to a hidden file beside the
//! log as they come, and [`LiveLog::finish`] puts the metadata (counts known only at the
//! end) and the header before them in the log itself, as the command's one output
//! ([`Outputs`]). Until then the log's path holds what it held before (or nothing); a
//! session stopped by Ctrl-C or a stream that ends is finished the same way, so every
//! frame taken is in the log.

use crate::bench_log::limits::max_rows;
use crate::bench_log::{format_value, MIN_ROWS};
use crate::ingest::frame_values;
use crate::output::{interrupt, CliError, Outputs};
use firmware::telemetry::{TelemetryFrame, COLUMNS};
use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How often the rows written so far are pushed to the file system.
const FLUSH_EVERY: Duration = Duration::from_secs(1);

/// Why a live log was not written.
#[derive(Debug, thiserror::Error)]
pub enum LiveLogError {
    /// Writing failed.
    #[error("bench log `{}`: {source}", file.display())]
    Write {
        /// The log.
        file: PathBuf,
        /// Why.
        source: io::Error,
    },
    /// Too few frames for a bench log.
    #[error(
        "bench log `{}` not written: only {rows} telemetry frames arrived; a bench log needs \
         at least {MIN_ROWS}",
        file.display()
    )]
    TooFewRows {
        /// The log.
        file: PathBuf,
        /// Frames taken.
        rows: usize,
    },
}

/// A bench log being written.
pub struct LiveLog {
    path: PathBuf,
    rows_path: PathBuf,
    rows: BufWriter<File>,
    count: usize,
    last_flush: Instant,
    _cleanup: interrupt::Guard,
}

impl LiveLog {
    /// Starts a log at `path` (its rows in a hidden file beside it).
    pub fn create(path: &Path) -> Result<LiveLog, LiveLogError> {
        let failed = |source| LiveLogError::Write {
            file: path.to_path_buf(),
            source,
        };
        let name = path.file_name().ok_or_else(|| {
            failed(io::Error::new(
                io::ErrorKind::InvalidInput,
                "does not name a file",
            ))
        })?;
        let mut rows_name = std::ffi::OsString::from(".");
        rows_name.push(name);
        rows_name.push(format!(".rows-{}", std::process::id()));
        let rows_path = path.with_file_name(rows_name);
        let _cleanup = interrupt::remove_on_interrupt(&rows_path);
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&rows_path)
            .map_err(failed)?;
        Ok(LiveLog {
            path: path.to_path_buf(),
            rows_path,
            rows: BufWriter::new(file),
            count: 0,
            last_flush: Instant::now(),
            _cleanup,
        })
    }

    /// Rows written.
    pub fn rows(&self) -> usize {
        self.count
    }

    /// The log's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// True once the log holds as many rows as a bench log of the telemetry's columns may
    /// ([`max_rows`]).
    pub fn is_full(&self) -> bool {
        self.count >= max_rows(COLUMNS.len())
    }

    /// Appends a frame (ignored once the log [`is_full`](Self::is_full)).
    pub fn push(&mut self, f: &TelemetryFrame) -> Result<(), LiveLogError> {
        if self.is_full() {
            return Ok(());
        }
        let mut line = String::with_capacity(256);
        for (k, v) in frame_values(f).into_iter().enumerate() {
            if k > 0 {
                line.push(',');
            }
            format_value(&mut line, v);
        }
        line.push('\n');
        self.rows
            .write_all(line.as_bytes())
            .map_err(|source| self.failed(source))?;
        self.count += 1;
        if self.last_flush.elapsed() >= FLUSH_EVERY {
            self.rows.flush().map_err(|source| self.failed(source))?;
            self.last_flush = Instant::now();
        }
        Ok(())
    }

    fn failed(&self, source: io::Error) -> LiveLogError {
        LiveLogError::Write {
            file: self.path.clone(),
            source,
        }
    }

    /// Writes the log: `metadata` lines, the header, the rows; atomically. Fails, leaving
    /// the log's path as it was, with fewer than [`MIN_ROWS`] rows.
    pub fn finish(mut self, metadata: &[(String, String)]) -> Result<usize, LiveLogError> {
        let result = self.write_out(metadata);
        let _ = fs::remove_file(&self.rows_path);
        result
    }

    fn write_out(&mut self, metadata: &[(String, String)]) -> Result<usize, LiveLogError> {
        self.rows.flush().map_err(|source| self.failed(source))?;
        if self.count < MIN_ROWS {
            return Err(LiveLogError::TooFewRows {
                file: self.path.clone(),
                rows: self.count,
            });
        }
        let rows_path = self.rows_path.clone();
        let mut out = Outputs::new();
        out.file_with("--out", &self.path, |w| {
            for (k, v) in metadata {
                writeln!(w, "# {k}: {v}")?;
            }
            writeln!(w, "{}", COLUMNS.join(","))?;
            io::copy(&mut File::open(&rows_path)?, w)?;
            Ok(())
        })
        .and_then(|()| out.commit())
        .map_err(|e| match e {
            CliError::Write { source, .. } => self.failed(source),
            e => self.failed(io::Error::other(e.to_string())),
        })?;
        Ok(self.count)
    }
}

impl Drop for LiveLog {
    fn drop(&mut self) {
        // A log dropped unfinished (an error on the way) leaves no hidden rows behind.
        let _ = fs::remove_file(&self.rows_path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmware::Mode;

    fn frame(i: usize) -> TelemetryFrame {
        TelemetryFrame {
            t_s: i as f64 * 1e-3,
            p_ref_pa: 5e6,
            p_pa: 5e6 + i as f32,
            speed_rad_s: 6.25,
            iq_a: -0.5,
            id_a: 0.0,
            theta_m_rad: 1.5,
            speed_ref_rad_s: 6.0,
            iq_ref_a: 0.5,
            ud_v: 1.0,
            uq_v: 2.0,
            udc_v: 280.0,
            mode: Mode::Pressure,
            fault: None,
            command_status: 0,
        }
    }

    #[test]
    fn the_finished_log_reads_back_and_too_few_rows_leave_nothing() {
        let d = crate::output::scratch::scratch_dir("live-log");
        let path = d.join("run.csv");
        let mut log = LiveLog::create(&path).unwrap();
        for i in 0..150 {
            log.push(&frame(i)).unwrap();
        }
        // Nothing at the log's path before it is finished.
        assert!(!path.exists());
        let meta = vec![("source".to_string(), "firmware telemetry".to_string())];
        assert_eq!(log.finish(&meta).unwrap(), 150);
        let read = crate::bench_log::read(&path).unwrap();
        assert_eq!(read.len(), 150);
        assert_eq!(read.meta("source"), Some("firmware telemetry"));
        assert_eq!(read.p_pa[149], 5e6 + 149.0);
        assert_eq!(read.iq_a[3], -0.5);
        assert_eq!(read.udc_v.as_deref().unwrap()[0], 280.0);

        let short = d.join("short.csv");
        let mut log = LiveLog::create(&short).unwrap();
        log.push(&frame(0)).unwrap();
        let e = log.finish(&meta).unwrap_err().to_string();
        assert!(e.contains("only 1 telemetry frames"), "{e}");
        assert!(!short.exists());
        // Only the finished log is left: no hidden rows or temporary files.
        let names: Vec<_> = fs::read_dir(&d)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, ["run.csv"]);
        fs::remove_dir_all(&d).unwrap();
    }
}
