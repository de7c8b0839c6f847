//! What `cargo xtask` and its checks' executable (`xtask/checks`) share: the workspace and
//! its linted `cargo` ([`workspace`]), the compiler wrapper that linted build runs
//! ([`compiler`]), the tools the checks need installed when missing ([`setup`]), and the
//! builds of the Cortex-M4F images ([`images`]), and the processes run beside the steps
//! ([`beside`]).
//!
//! It depends on `anyhow` alone, so `cargo xtask` builds in seconds on a fresh clone; the
//! checks with their heavier dependencies (the firmware's codec, the ELF and defmt readers,
//! the Rust parser) are a workspace member, compiled by the linted build with the features
//! the rest of the workspace resolves, so no dependency is compiled twice.

pub mod beside;
pub mod compiler;
pub mod images;
pub mod setup;
pub mod workspace;
