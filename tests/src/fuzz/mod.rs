//! The fuzz targets' bodies: every reader of outside data, fed arbitrary bytes, must return
//! (an error or a value) without panicking, within bounded time and memory, and what it
//! accepts must survive its own writer. `fuzz/` runs them under libFuzzer (cargo-fuzz, on
//! nightly); `tests/tests/fuzz_corpora.rs` replays the kept corpora and every finding
//! through the same functions on stable, so CI runs them as ordinary tests.
//!
//! A property that does not hold panics (an `assert!`): that is how libFuzzer sees it.

pub mod can;
pub mod host;
pub mod store;

/// A fuzz target: its name (the folder of its corpus) and its body.
pub type Target = (&'static str, fn(&[u8]));

/// Every target, by the name `cargo fuzz run` and the corpora use.
pub const TARGETS: [Target; 7] = [
    ("bench_log", host::bench_log),
    ("telemetry", host::telemetry),
    ("ingest", host::ingest),
    ("rig_file", host::rig_file),
    ("can_frame", can::can_frame),
    ("can_server", can::can_server),
    ("param_store", store::param_store),
];
