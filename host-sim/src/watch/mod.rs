//! `eha watch [STREAM] [--out LOG.csv] [--signals LIST]`: the drive's defmt telemetry as
//! the host decoder prints it (`probe-rs run`, `defmt-print`), live.
//!
//! - [`source`]: the stream — standard input or a pipe to its end, a regular file followed
//!   as it grows — split into lines on a thread of its own;
//! - [`session`]: the lines classified by `eha ingest`'s reader (the firmware's own
//!   parser), counted, and the window of frames with the mode, the fault and the pulsation;
//! - [`live_log`]: the bench log written as the frames come, finished atomically;
//! - [`running`]: a running watch, the stream pumped into the session and the log;
//! - [`screen`]: the terminal view (ratatui): rolling traces, mode and fault by the
//!   firmware's names, the pulsation over the last second, the counts.
//!
//! On a terminal the view runs until `q`, Esc or Ctrl-C; when the stream ends the log is
//! finished at once and the view stays until quit. Without a terminal on standard output
//! (a script, a pipe) there is no view: it reads to the end of the stream (or to Ctrl-C
//! when following a file) and prints the counts. Either way an interruption finishes the
//! log rather than discarding it; a second one abandons it.

pub mod live_log;
pub mod running;
pub mod screen;
pub mod session;
pub mod source;

use crate::output::paths::Declared;
use crate::output::{interrupt, CliError};
use crate::values::positive_f64;
use clap::Args;
use firmware::telemetry::COLUMNS;
use plant_model::Rig;
use session::Session;
use source::Source;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Duration;

pub use running::{Stream, Watch};

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
