//! The compiler the linted host build runs for the workspace's own crates: `clippy-driver`
//! (rustc with Clippy's lints), reached through this task's own executable, which leaves the
//! unit tests of the simulation's libraries unoptimised.
//!
//! The dev profile optimises `host-sim`, `plant-model` and `closed-loop` (Cargo.toml): their
//! integration tests run long closed-loop simulations and the diagnosis's fits. Their
//! unit-test crates are each the whole library compiled again with its tests, and under
//! `cargo test` every unit takes the same profile, so a plain build compiles them at
//! opt-level 3 as well, though their tests are small checks that run in seconds either way.
//! Cargo has no setting per target, so the wrapper Cargo runs for the workspace's crates
//! (`RUSTC_WORKSPACE_WRAPPER`) appends `-C opt-level=0` to those compilations (rustc takes a
//! codegen option's last value) and hands every call to `clippy-driver` unchanged otherwise.
//! Optimisation does not change a floating-point result here (no fast-math), so the tests
//! check the same numbers.
//!
//! Cargo calls the wrapper as `WRAPPER RUSTC ARGS…`; this executable knows the call by
//! [`DRIVER_VAR`] in its environment, set only by [`crate::workspace::linted_cargo`], and
//! a first argument naming rustc. Cargo fingerprints the wrapper by its path, not by what
//! it does: a change of [`UNOPTIMISED_UNIT_TESTS`] reaches a crate already built at its
//! next change (only the build's time depends on it).

use std::ffi::{OsStr, OsString};
use std::path::Path;
use std::process::Command;

/// Environment variable holding the `clippy-driver` the wrapper hands its calls to.
pub const DRIVER_VAR: &str = "EHA_XTASK_CLIPPY_DRIVER";

/// Crates (rustc's names) whose unit-test build is left unoptimised.
pub const UNOPTIMISED_UNIT_TESTS: [&str; 3] = ["host_sim", "plant_model", "closed_loop"];

/// When this process is Cargo's compiler wrapper, runs the compiler and exits with its
/// status; otherwise returns.
pub fn wrap_if_called() {
    let Some(driver) = std::env::var_os(DRIVER_VAR) else {
        return;
    };
    let args: Vec<OsString> = std::env::args_os().skip(1).collect();
    let names_rustc = args
        .first()
        .and_then(|a| Path::new(a).file_stem())
        .is_some_and(|s| s == "rustc");
    if !names_rustc {
        return;
    }
    let mut cmd = Command::new(&driver);
    cmd.args(&args);
    if unoptimised(&args) {
        cmd.arg("-Copt-level=0");
    }
    let code = match cmd.status() {
        Ok(status) => status.code().unwrap_or(1),
        Err(e) => {
            eprintln!(
                "xtask: could not start {} as the compiler: {e}",
                Path::new(&driver).display()
            );
            1
        }
    };
    std::process::exit(code);
}

/// Whether the compiler call `args` builds the unit tests (`--test`) of one of
/// [`UNOPTIMISED_UNIT_TESTS`].
fn unoptimised(args: &[OsString]) -> bool {
    let crate_name = args
        .windows(2)
        .find(|w| w[0] == "--crate-name")
        .map(|w| w[1].as_os_str());
    args.iter().any(|a| a == "--test")
        && crate_name.is_some_and(|n| UNOPTIMISED_UNIT_TESTS.iter().any(|u| n == OsStr::new(u)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn call(line: &str) -> Vec<OsString> {
        line.split(' ').map(OsString::from).collect()
    }

    #[test]
    fn only_the_listed_unit_tests_are_left_unoptimised() {
        let unit =
            "rustc --crate-name host_sim --edition=2021 host-sim/src/lib.rs --test -C opt-level=3";
        assert!(unoptimised(&call(unit)));
        let plant = "rustc --crate-name plant_model --test plant-model/src/lib.rs";
        assert!(unoptimised(&call(plant)));
        let seam = "rustc --crate-name closed_loop --test closed-loop/src/lib.rs";
        assert!(unoptimised(&call(seam)));
        // The library itself, as the integration tests link it.
        let lib = "rustc --crate-name host_sim --crate-type lib host-sim/src/lib.rs -C opt-level=3";
        assert!(!unoptimised(&call(lib)));
        // An integration test of host-sim, another crate's unit tests.
        let integration = "rustc --crate-name bad_input host-sim/tests/bad_input.rs --test";
        assert!(!unoptimised(&call(integration)));
        let firmware = "rustc --crate-name firmware firmware/src/lib.rs --test";
        assert!(!unoptimised(&call(firmware)));
        // A crate whose name only contains a listed one.
        let longer = "rustc --crate-name host_sim_extra --test x.rs";
        assert!(!unoptimised(&call(longer)));
    }
}
