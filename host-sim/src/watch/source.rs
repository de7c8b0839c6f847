//! Where `eha watch` reads the decoder's text from, on a thread of its own so the screen
//! and the signals are served while a read blocks: standard input or a pipe until it ends,
//! or a regular file followed as it grows (like `tail -f`; a file cut shorter is read again
//! from its start). Lines are split here, bounded to the bench log's
//! [`MAX_LINE_BYTES`] (a longer one is reported, not kept), and a last line without its
//! line break is delivered when the stream ends, so nothing the decoder printed is lost.

use crate::bench_log::limits::MAX_LINE_BYTES;
use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom};
use std::path::PathBuf;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::time::Duration;

/// What the reader thread reports, in stream order.
#[derive(Clone, Debug, PartialEq)]
pub enum Event {
    /// One line, without its line break (a final one may have had none).
    Line(String),
    /// A line longer than [`MAX_LINE_BYTES`], dropped.
    TooLong,
    /// The stream ended (standard input or a pipe closed).
    End,
    /// The stream could not be read further.
    Failed(String),
}

/// The stream to read.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// Standard input, until it ends.
    Stdin,
    /// A pipe or FIFO, until it ends.
    Pipe(PathBuf),
    /// A regular file, followed as it grows.
    Follow(PathBuf),
}

impl Source {
    /// The source for an optional path: standard input without one (or for `-`), a
    /// regular file followed, anything else read to its end.
    pub fn for_path(path: Option<&PathBuf>) -> Source {
        match path {
            None => Source::Stdin,
            Some(p) if p.as_os_str() == "-" => Source::Stdin,
            Some(p) if std::fs::metadata(p).is_ok_and(|m| m.is_file()) => Source::Follow(p.clone()),
            Some(p) => Source::Pipe(p.clone()),
        }
    }

    /// How the screen and the log name it.
    pub fn name(&self) -> String {
        match self {
            Source::Stdin => "standard input".into(),
            Source::Pipe(p) | Source::Follow(p) => p.display().to_string(),
        }
    }
}

/// Lines the channel holds before the reader waits for the screen to take them (bounds
/// the memory when the decoder outpaces the screen).
const QUEUE_LINES: usize = 65_536;
/// How often a followed file is looked at again once its end is reached.
const FOLLOW_POLL: Duration = Duration::from_millis(50);

/// Starts the reader thread of `source`; its events arrive on the returned channel. The
/// thread ends with the stream, or when the receiver is dropped.
pub fn spawn(source: Source) -> io::Result<Receiver<Event>> {
    let (tx, rx) = sync_channel(QUEUE_LINES);
    let input = match &source {
        Source::Stdin => Input::Stream(Box::new(io::stdin())),
        Source::Pipe(p) => Input::Stream(Box::new(File::open(p)?)),
        Source::Follow(p) => Input::Followed(File::open(p)?),
    };
    std::thread::Builder::new()
        .name("watch-reader".into())
        .spawn(move || pump(input, &tx))?;
    Ok(rx)
}

/// A stream read to its end, or a file followed.
enum Input {
    Stream(Box<dyn Read + Send>),
    Followed(File),
}

impl Input {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        match self {
            Input::Stream(r) => r.read(buf),
            Input::Followed(f) => f.read(buf),
        }
    }
}

/// Reads `input` into `tx` until it ends (never, when following) or `tx` is closed.
fn pump(mut input: Input, tx: &SyncSender<Event>) {
    let mut splitter = Splitter::default();
    let mut buf = vec![0u8; 64 * 1024];
    let mut position = 0u64;
    loop {
        let n = match input.read(&mut buf) {
            Ok(n) => n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => {
                let _ = tx.send(Event::Failed(e.to_string()));
                return;
            }
        };
        if n == 0 {
            if let Input::Followed(file) = &mut input {
                std::thread::sleep(FOLLOW_POLL);
                // A file now shorter than what was read has been written anew: start over.
                if file.metadata().is_ok_and(|m| m.len() < position)
                    && file.seek(SeekFrom::Start(0)).is_ok()
                {
                    position = 0;
                    splitter = Splitter::default();
                }
                continue;
            }
            if let Some(e) = splitter.finish() {
                if tx.send(e).is_err() {
                    return;
                }
            }
            let _ = tx.send(Event::End);
            return;
        }
        position += n as u64;
        for e in splitter.push(&buf[..n]) {
            if tx.send(e).is_err() {
                return;
            }
        }
    }
}

/// Splits bytes into lines of at most [`MAX_LINE_BYTES`].
#[derive(Debug, Default)]
pub struct Splitter {
    /// The line so far.
    line: Vec<u8>,
    /// Inside a line already reported too long: its bytes are dropped up to its break.
    dropping: bool,
}

impl Splitter {
    /// The lines completed by `bytes`.
    pub fn push(&mut self, bytes: &[u8]) -> Vec<Event> {
        let mut out = Vec::new();
        let mut rest = bytes;
        while !rest.is_empty() {
            let (part, done) = match rest.iter().position(|b| *b == b'\n') {
                Some(i) => (&rest[..i], Some(i + 1)),
                None => (rest, None),
            };
            if !self.dropping {
                if self.line.len() + part.len() > MAX_LINE_BYTES {
                    self.dropping = true;
                    self.line.clear();
                    out.push(Event::TooLong);
                } else {
                    self.line.extend_from_slice(part);
                }
            }
            match done {
                Some(i) => {
                    if !std::mem::take(&mut self.dropping) {
                        out.push(Event::Line(self.take_line()));
                    }
                    rest = &rest[i..];
                }
                None => rest = &[],
            }
        }
        out
    }

    /// The last line, when the stream ended without its line break.
    pub fn finish(&mut self) -> Option<Event> {
        if self.dropping || self.line.is_empty() {
            self.dropping = false;
            return None;
        }
        Some(Event::Line(self.take_line()))
    }

    fn take_line(&mut self) -> String {
        // Telemetry is ASCII; a lossy view of other log lines loses nothing of it.
        let s = String::from_utf8_lossy(&self.line)
            .trim_end_matches('\r')
            .to_string();
        self.line.clear();
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(events: &[Event]) -> Vec<&str> {
        events
            .iter()
            .map(|e| match e {
                Event::Line(l) => l.as_str(),
                Event::TooLong => "<too long>",
                _ => "<other>",
            })
            .collect()
    }

    #[test]
    fn lines_split_across_reads_are_joined_and_a_last_partial_one_is_kept() {
        let mut s = Splitter::default();
        let mut all = s.push(b"INFO  boot\r\nEHA1 t_s=0");
        assert_eq!(lines(&all), ["INFO  boot"]);
        all.extend(s.push(b".001 p\n\nEHA1 t_s=0.002"));
        all.extend(s.finish());
        assert_eq!(
            lines(&all),
            ["INFO  boot", "EHA1 t_s=0.001 p", "", "EHA1 t_s=0.002"]
        );
        assert_eq!(s.finish(), None);
    }

    #[test]
    fn an_over_long_line_is_reported_once_and_the_next_one_is_whole() {
        let mut s = Splitter::default();
        let long = vec![b'x'; MAX_LINE_BYTES / 2 + 1];
        let mut all = s.push(&long);
        all.extend(s.push(&long));
        all.extend(s.push(&long));
        all.extend(s.push(b"tail\nnext\n"));
        assert_eq!(lines(&all), ["<too long>", "next"]);
        // A line of exactly the limit is kept.
        let exact = vec![b'y'; MAX_LINE_BYTES];
        let mut e = s.push(&exact);
        e.extend(s.push(b"\n"));
        assert!(matches!(&e[..], [Event::Line(l)] if l.len() == MAX_LINE_BYTES));
    }
}
