//! `cargo xtask rooms`: the files over 650 lines and the import circles between files of
//! the workspace's crates (`firmware`, `plant-model`, `host-sim`, `closed-loop`, `tests`, `pil`,
//! `xtask` and its checks); the integration tests, benchmarks, examples and fuzz targets are
//! held to the same length.
//! An edge runs from file A to file B when A uses an item B defines (through `use`,
//! a `crate::`/`super::`/`self::` path, or a re-export followed to the defining file); a
//! circle is a strongly connected component of more than one file. Test-only code is left
//! out. Exits non-zero when either list is non-empty. `--root DIR` checks another checkout.
//!
//! Files are found by [`discovery`], parsed into module trees by [`modules`], their paths
//! resolved to edges by [`resolve`], the circles found by [`graph`] and gathered in
//! [`findings`], the text written by [`report`].

mod discovery;
mod findings;
mod graph;
mod modules;
mod report;
mod resolve;
#[cfg(test)]
mod tests;

use anyhow::{bail, Result};

/// The crates' source folders, relative to the workspace root.
pub const SOURCES: [&str; 8] = [
    "firmware/src",
    "plant-model/src",
    "host-sim/src",
    "closed-loop/src",
    "tests/src",
    "pil/src",
    "xtask/src",
    "xtask/checks/src",
];

/// Folders whose files are each a crate of their own or a module of one (integration tests,
/// benchmarks, examples, fuzz targets), relative to the workspace root: read for their
/// length only. A folder a checkout lacks is skipped.
pub const ALSO_MEASURED: [&str; 13] = [
    "firmware/tests",
    "plant-model/tests",
    "plant-model/benches",
    "plant-model/examples",
    "host-sim/tests",
    "host-sim/benches",
    "host-sim/examples",
    "closed-loop/tests",
    "tests/tests",
    "tests/examples",
    "xtask/tests",
    "xtask/checks/tests",
    "fuzz/fuzz_targets",
];

/// A file longer than this is reported (the guide aims at 600).
pub const LINE_LIMIT: usize = 650;

/// `cargo xtask rooms [--root DIR]`: this workspace, or the checkout at `DIR`.
pub fn rooms(args: &[String]) -> Result<()> {
    let root = match args {
        [] => xtask::workspace::root(),
        [flag, dir] if flag == "--root" => std::path::PathBuf::from(dir),
        _ => bail!("rooms: usage: cargo xtask rooms [--root DIR]"),
    };
    let srcs: Vec<_> = SOURCES.iter().map(|s| root.join(s)).collect();
    let measured: Vec<_> = ALSO_MEASURED
        .iter()
        .map(|s| root.join(s))
        .filter(|p| p.is_dir())
        .collect();
    let found = findings::check(&srcs, &measured, LINE_LIMIT)?;
    print!("{}", report::text(&found, &root, LINE_LIMIT));
    if !found.clean() {
        bail!(
            "rooms: {} file(s) over {LINE_LIMIT} lines and {} import circle(s) (listed above)",
            found.long_files.len(),
            found.circles.len()
        );
    }
    Ok(())
}
