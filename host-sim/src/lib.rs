//! The `eha` command's library: everything the binary does, reachable from the tests and
//! benchmarks too (the `eha` binary in `main.rs` only calls [`cli::main`]).
//!
//! - [`cli`]: the subcommands of `shared/contracts/eha-cli.md`, routed to the modules that
//!   own them; [`output`]: what they report through (errors and exit status, their outputs
//!   as one transaction); [`values`]: the command line's number parsers.
//! - [`bench_log`]: the bench-log CSV contract (`shared/contracts/bench-log.md`), read and
//!   written.
//! - [`rig_file`]: the rig-file format, TOML of [`plant_model::Rig`]; [`rig_command`]: `eha rig`.
//! - [`study`]: the paper's accumulator study (Section 4.3 design, Section 5.2 sweep).
//! - [`simulate`]: `eha simulate` and `eha demo`; [`run`]: one closed-loop run as a bench
//!   log.
//! - [`ingest`]: the firmware's defmt telemetry (decoded text) to a bench log.
//! - [`commission`], [`tune`]: commissioning on the simulated motor and loop tuning from a
//!   step log; [`can_commands`]: parameter changes as `cansend` lines and `candump` logs.
//! - [`compensate`]: the torque feed-forward learned from bench logs; [`feedforward`]: what
//!   it loads into a drive, and the table file that carries it.
//! - [`memory`]: where the allocator takes large blocks from (mapped, or the heap while the
//!   diagnosis fits), and the freed ones handed back between a command's stages.
//! - [`diagnose`]: what the model gets wrong on a bench log, why, and the gain; [`fleet`]:
//!   many logs diagnosed at once, one table, each drive's trends; [`timestamp`]: the RFC
//!   3339 times of logs and predictions.
//! - [`watch`]: the drive's telemetry live in the terminal, and the bench log as it comes.

pub mod bench_log;
pub mod can_commands;
pub mod cli;
pub mod commission;
pub mod compensate;
pub mod diagnose;
pub mod feedforward;
pub mod fleet;
pub mod ingest;
pub mod memory;
pub mod output;
pub mod plots;
pub mod pulsation;
pub mod rig_command;
pub mod rig_file;
pub mod run;
pub mod simulate;
pub mod study;
pub mod timestamp;
pub mod tune;
pub mod values;
pub mod watch;
