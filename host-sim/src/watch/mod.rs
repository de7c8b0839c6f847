//! `eha watch [STREAM] [--out LOG.csv] [--signals LIST]`: the drive's defmt telemetry as
//! the host decoder prints it (`probe-rs run`, `defmt-print`), live.
//!
//! - [`source`]: the stream — standard input or a pipe to its end, a regular file followed
//!   as it grows — split into lines on a thread of its own;
//! - [`session`]: the lines classified by `eha ingest`'s reader (the firmware's own
//!   parser), counted, and the window of frames with the mode, the fault and the pulsation;
//! - [`live_log`]: the bench log written as the frames come, finished atomically;
//! - [`screen`]: the terminal view (ratatui): rolling traces, mode and fault by the
//!   firmware's names, the pulsation over the last second, the counts.
//!
//! On a terminal the view runs until `q`, Esc or Ctrl-C; when the stream ends the log is
//! finished at once and the view stays until quit. Without a terminal on standard output
//! (a script, a pipe) there is no view: it reads to the end of the stream (or to Ctrl-C
//! when following a file) and prints the counts. Either way an interruption finishes the
//! log rather than discarding it; a second one abandons it.

pub mod live_log;
pub mod screen;
pub mod session;
pub mod source;

use crate::output::paths::Declared;
use crate::output::{interrupt, CliError};
use crate::values::positive_f64;
use clap::Args;
use firmware::telemetry::COLUMNS;
use live_log::LiveLog;
use plant_model::Rig;
use session::{Outcome, Session};
use source::{Event, Source};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

/// The traces shown without `--signals`: pressure and its setpoint, speed and its
/// reference, the q current.
pub const DEFAULT_SIGNALS: &str = "p_pa+p_ref_pa,speed_rad_s+speed_ref_rad_s,iq_a";
/// Most panels on the screen.
pub const MAX_PANELS: usize = 6;

/// `eha watch`.
#[derive(Debug, Args)]
pub struct WatchArgs {
    /// The decoder's output: a file being written (followed) or a pipe; standard input
    /// when absent or `-`.
    #[arg(value_name = "STREAM")]
    pub stream: Option<PathBuf>,
    /// Write the bench log as the frames arrive (finished on exit, Ctrl-C or the end of
    /// the stream).
    #[arg(long, value_name = "LOG.csv")]
    pub out: Option<PathBuf>,
    /// Traces: panels separated by commas, signals in one panel joined by `+`
    /// (telemetry column names).
    #[arg(long, value_name = "LIST", default_value = DEFAULT_SIGNALS)]
    pub signals: String,
    /// Span of the rolling traces. [s]
    #[arg(long, value_name = "S", default_value_t = 5.0, value_parser = positive_f64)]
    pub window: f64,
}

impl WatchArgs {
    /// The files it reads and writes.
    pub fn paths(&self) -> Declared<'_> {
        let stream = self.stream.as_ref().filter(|p| p.as_os_str() != "-");
        Declared::default()
            .input("STREAM", stream)
            .file("--out", self.out.as_ref())
    }
}

/// The panels of a `--signals` list: each a list of telemetry column names (`t_s` aside).
pub fn panels(list: &str) -> Result<Vec<Vec<&'static str>>, CliError> {
    let known: Vec<&'static str> = COLUMNS[1..].to_vec();
    let mut out = Vec::new();
    for panel in list.split(',').map(str::trim) {
        let mut names = Vec::new();
        for name in panel.split('+').map(str::trim) {
            let Some(k) = known.iter().find(|k| **k == name) else {
                return Err(CliError::BadInput(format!(
                    "--signals: `{name}` is not a telemetry signal; known: {}",
                    known.join(", ")
                )));
            };
            names.push(*k);
        }
        out.push(names);
    }
    if out.len() > MAX_PANELS {
        return Err(CliError::BadInput(format!(
            "--signals: {} panels; at most {MAX_PANELS} fit the screen",
            out.len()
        )));
    }
    Ok(out)
}

/// Where the session stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stream {
    /// Lines may still come.
    Open,
    /// The stream ended (or failed); the log is finished.
    Ended,
}

/// A running watch: the stream's lines, the session, the log.
pub struct Watch {
    /// What the session knows.
    pub session: Session,
    /// Where the lines come from.
    pub source: Source,
    /// The log being written, until it is finished.
    log: Option<LiveLog>,
    /// What became of the log: its rows, or why it was not written.
    pub log_result: Option<Result<(PathBuf, usize), String>>,
    /// Frames that arrived after the log was closed (a reset, a full log).
    pub unlogged: usize,
    /// Why the stream stopped, when it failed.
    pub failure: Option<String>,
    rx: Receiver<Event>,
    /// Where the stream stands.
    pub stream: Stream,
}

impl Watch {
    /// Starts reading `source`, writing `out` if given.
    pub fn start(
        source: Source,
        out: Option<&PathBuf>,
        session: Session,
    ) -> Result<Watch, CliError> {
        let log = out
            .map(|p| LiveLog::create(p))
            .transpose()
            .map_err(|e| CliError::Failed(e.to_string()))?;
        let rx = source::spawn(source.clone())
            .map_err(|e| CliError::BadInput(format!("STREAM `{}`: {e}", source.name())))?;
        Ok(Watch {
            session,
            source,
            log,
            log_result: None,
            unlogged: 0,
            failure: None,
            rx,
            stream: Stream::Open,
        })
    }

    /// The log being written, if still open.
    pub fn open_log(&self) -> Option<&LiveLog> {
        self.log.as_ref()
    }

    /// Takes the lines that arrive within `wait` (at most a screenful of work), then
    /// returns.
    pub fn pump(&mut self, wait: Duration) -> Result<(), CliError> {
        if self.stream == Stream::Ended {
            std::thread::sleep(wait);
            return Ok(());
        }
        let until = Instant::now() + wait;
        loop {
            let left = until.saturating_duration_since(Instant::now());
            match self.rx.recv_timeout(left) {
                Ok(Event::Line(text)) => self.line(&text)?,
                Ok(Event::TooLong) => self.session.too_long(),
                Ok(Event::End) => return self.end(None),
                Ok(Event::Failed(why)) => return self.end(Some(why)),
                Err(RecvTimeoutError::Timeout) => return Ok(()),
                Err(RecvTimeoutError::Disconnected) => return self.end(None),
            }
            if Instant::now() >= until || interrupt::stop_requested() {
                return Ok(());
            }
        }
    }

    fn line(&mut self, text: &str) -> Result<(), CliError> {
        match self.session.line(text) {
            Outcome::Frame(f) => match &mut self.log {
                Some(log) if !log.is_full() => {
                    log.push(&f).map_err(|e| CliError::Failed(e.to_string()))?;
                    if log.is_full() {
                        self.finish_log();
                    }
                }
                _ => self.unlogged += 1,
            },
            // The log's time must increase: it ends at the reset.
            Outcome::Reset => self.finish_log(),
            Outcome::Nothing => {}
        }
        Ok(())
    }

    fn end(&mut self, failure: Option<String>) -> Result<(), CliError> {
        self.failure = failure;
        self.stream = Stream::Ended;
        self.finish_log();
        Ok(())
    }

    /// Finishes the log now (the end of the session, a reset, a full log).
    pub fn finish_log(&mut self) {
        let Some(log) = self.log.take() else {
            return;
        };
        let path = log.path().to_path_buf();
        let s = &self.session;
        let meta = vec![
            ("source".to_string(), "firmware telemetry".to_string()),
            ("watched_from".to_string(), self.source.name()),
            ("telemetry_lines".to_string(), log.rows().to_string()),
            ("skipped_lines".to_string(), s.skipped.to_string()),
            ("malformed_lines".to_string(), s.malformed.to_string()),
            ("faulted_frames".to_string(), s.faulted_frames.to_string()),
        ];
        self.log_result = Some(
            log.finish(&meta)
                .map(|rows| (path, rows))
                .map_err(|e| e.to_string()),
        );
    }

    /// One line saying what became of the session: counts and the log.
    pub fn summary(&self) -> String {
        let s = &self.session;
        let mut text = format!(
            "watch: {} telemetry frames of {} lines from {} ({} other lines skipped, {} \
             malformed",
            s.frames,
            s.lines,
            self.source.name(),
            s.skipped,
            s.malformed
        );
        if let Some((line, what)) = &s.first_malformed {
            text.push_str(&format!("; first at line {line}: {what}"));
        }
        text.push(')');
        if s.faulted_frames > 0 {
            text.push_str(&format!(
                "; {} frames carry a latched fault",
                s.faulted_frames
            ));
        }
        if s.resets > 0 {
            text.push_str(&format!("; {} controller resets", s.resets));
        }
        match &self.log_result {
            Some(Ok((path, rows))) => {
                text.push_str(&format!("; {rows} rows written to {}", path.display()));
                if self.unlogged > 0 {
                    text.push_str(&format!(" ({} later frames not logged)", self.unlogged));
                }
            }
            Some(Err(why)) => text.push_str(&format!("; {why}")),
            None => {}
        }
        if let Some(why) = &self.failure {
            text.push_str(&format!("; the stream failed: {why}"));
        }
        text
    }
}

/// `eha watch`.
pub fn run_watch(rig: &Rig, args: &WatchArgs) -> Result<(), CliError> {
    let panels = panels(&args.signals)?;
    let source = Source::for_path(args.stream.as_ref());
    let session = Session::new(args.window, crate::pulsation::sources(rig));
    let _stop = interrupt::stop_on_interrupt();
    let mut watch = Watch::start(source, args.out.as_ref(), session)?;
    if std::io::stdout().is_terminal() {
        screen::run(&mut watch, &panels)?;
    } else {
        while watch.stream == Stream::Open && !interrupt::stop_requested() {
            watch.pump(Duration::from_millis(100))?;
        }
    }
    watch.finish_log();
    eprintln!("{}", watch.summary());
    match &watch.log_result {
        Some(Err(why)) => Err(CliError::BadInput(why.clone())),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signal_lists_are_panels_of_known_columns() {
        let p = panels(DEFAULT_SIGNALS).unwrap();
        assert_eq!(
            p,
            [
                vec!["p_pa", "p_ref_pa"],
                vec!["speed_rad_s", "speed_ref_rad_s"],
                vec!["iq_a"]
            ]
        );
        let e = panels("p_pa,iq").unwrap_err().to_string();
        assert!(e.contains("`iq`") && e.contains("iq_a"), "{e}");
        assert!(panels("t_s").is_err());
        assert!(panels("p_pa,p_pa,p_pa,p_pa,p_pa,p_pa,p_pa").is_err());
    }
}
