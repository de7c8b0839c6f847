//! What every subcommand reports through: the error type [`CliError`] with its exit status
//! ([`error`]), standard output ([`stdout`]), what a path names in words ([`file_kind`]),
//! the paths it is given, checked before it runs ([`paths`], [`folder`]), its outputs as one
//! transaction ([`transaction`]: every file, folder and standard output of a command
//! written together at the end, or none), clean-up when a run is interrupted
//! ([`interrupt`]), and progress on a terminal ([`progress`]).
//!
//! Exit status: 0 on success, 2 for bad input or arguments (a bad rig file, a bad bench
//! log, a value out of range), 1 for anything else; the message goes to standard error.
//!
//! # Writing a command's outputs
//!
//! A command declares the paths it reads and writes, with the files an output folder of
//! its own may hold; `eha` checks them all before the command starts ([`paths::check`]):
//!
//! ```ignore
//! /// The files `eha fleet` writes into its folder.
//! pub const FILES: &[&str] = &["fleet.csv", "fleet.json", "trends.csv", "trend_*.svg", "trend_*.png"];
//!
//! impl FleetArgs {
//!     pub fn paths(&self) -> Declared<'_> {
//!         Declared::default()
//!             .input("--manifest", self.manifest.as_ref())
//!             .dir("--out", Some(&self.out), FILES)
//!             .file("--json", self.json.as_ref())
//!     }
//! }
//! ```
//!
//! When its work is done it stages every output, then commits them together:
//!
//! ```ignore
//! let mut out = Outputs::new();
//! out.folder("--out", &args.out, FILES, |d| {
//!     d.file("fleet.csv", table.as_bytes())?;            // or d.file_with(name, |w| …)
//!     figure.write_into(d, "trend_drive7.svg")?;          // plots render, the folder writes
//!     Ok(())
//! })?;
//! if let Some(path) = &args.json {
//!     out.json("--json", path, &value)?;                  // `-`: standard output
//! }
//! out.print(&summary);                                    // standard output, after the files
//! out.commit()
//! ```
//!
//! Nothing appears until [`Outputs::commit`]; an error (or `?`) before it drops the
//! transaction and removes what was staged. A command that keeps results across runs
//! commits each in a transaction of its own; an interruption then keeps the committed
//! ones and says so.

pub mod error;
pub mod file_kind;
pub mod folder;
pub mod hooks;
pub mod interrupt;
pub mod paths;
pub mod progress;
#[cfg(test)]
pub(crate) mod scratch;
pub mod stdout;
pub mod transaction;

pub use error::CliError;
pub use stdout::{is_stdout, print_stdout};
pub use transaction::{Outputs, StagedFolder};
