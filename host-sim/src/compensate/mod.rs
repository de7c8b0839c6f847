//! `eha compensate LOG.csv… --out TABLE [--method model|histogram] [--json PATH]`: the
//! angle-indexed torque feed-forward learned from bench logs, written as the table record
//! the drive loads ([`firmware::compensation::record`]), the CAN frames that load it
//! printed, and its effect predicted on the paper's holding with the firmware's control
//! core against the model fitted to the logs.
//!
//! - [`args`]: its command line; [`command`]: the command, from the logs to the outputs.
//! - [`learn`]: the diagnosis's significant angle-locked effects, combined over logs.
//! - [`method`]: the feed-forward by the method asked, model or histogram.
//! - [`model`]: the channels from a rig's equations, the rig extended by those effects.
//! - [`histogram`]: the anchors' method, the q current binned by angle, for comparison.
//! - [`table`]: channels as harmonics → the drive's table (pre-emphasis, quantisation).
//! - [`predict`]: holding runs without and with a table, their pulsation; `outcome`: one
//!   run's feed-forward learned and predicted.
//! - [`can`]: the loading frames in `cansend` notation.
//! - [`study`]: the closed-loop study of `docs/compensation.md`.
//! - `summary`: the printed summary and the JSON of a run.
//!
//! What is learned, the table file and its speed modulation ([`flow`]), is
//! [`crate::feedforward`]'s.
//!
//! More than one log may be given (the contract's one `LOG.csv` is the common case): the
//! bench sweep at low pressure carries the load-independent lines, a hold at working
//! pressure the load-scaled ones.

pub mod args;
pub mod can;
pub mod command;
pub mod histogram;
pub mod learn;
pub mod method;
pub mod model;
mod outcome;
pub mod predict;
pub mod study;
mod summary;
pub mod table;

pub use crate::feedforward::{flow, read_table, Feedforward};
pub use args::CompensateArgs;
pub use command::{run_compensate, MAX_LEARNED_ROWS};
pub use learn::{find, Found};
pub use method::{feedforward_of, fitted_plant, table_of, Method};
