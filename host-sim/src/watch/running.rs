//! A running watch ([`Watch`]): the stream's lines taken as they come ([`super::source`]),
//! classified and counted by the session ([`super::session`]), the telemetry frames
//! written to the live log ([`super::live_log`]) until the stream ends, the controller
//! resets or the log is full, and the one line saying what became of it all.

use super::live_log::LiveLog;
use super::session::{Outcome, Session};
use super::source::{self, Event, Source};
use crate::output::{interrupt, CliError};
use std::path::PathBuf;
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

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
