//! The `eha` command's library: everything the binary does, reachable from the tests and
//! benchmarks too (the `eha` binary in `main.rs` only calls [`cli::main`]).
//!
//! - [`cli`]: argument parsing (the subcommands of `shared/contracts/eha-cli.md`), error
//!   reporting with exit status 2 for bad input and 1 for anything else.
//! - [`bench_log`]: the bench-log CSV contract (`shared/contracts/bench-log.md`), read and
//!   written.
//! - [`rig_file`]: the rig-file format, TOML of [`plant_model::Rig`].
//! - [`study`]: the paper's accumulator study (Section 4.3).
//! - [`simulate`]: the closed-loop runs behind `demo`, `simulate` and `sweep-precharge`.
//! - [`ingest`]: the firmware's defmt telemetry (decoded text) to a bench log.
//! - [`commission`], [`tune`]: commissioning on the simulated motor and loop tuning from a
//!   step log (issue 8).
//! - [`diagnose`]: what the model gets wrong on a bench log, why, and the gain (issue 5).
//! - [`atomic_file`]: output files appear whole or not at all.

pub mod atomic_file;
pub mod bench_log;
pub mod cli;
pub mod commission;
pub mod diagnose;
pub mod ingest;
pub mod plots;
pub mod pulsation;
pub mod rig_file;
pub mod run;
pub mod simulate;
pub mod study;
pub mod tune;
