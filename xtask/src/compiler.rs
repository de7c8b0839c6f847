//! The compiler the linted host build runs for the workspace's own crates: `clippy-driver`
//! (rustc with Clippy's lints), reached through this task's own executable, which compiles
//! the unit tests of the optimised libraries at a lower optimisation level.
//!
//! The dev profile optimises `host-sim`, `plant-model`, `closed-loop` and `firmware`
//! (Cargo.toml): their integration tests run long closed-loop simulations and the
//! diagnosis's fits. Their unit-test crates are each the whole library compiled again with
//! its tests, and under `cargo test` every unit takes the same profile, so a plain build
//! compiles them at opt-level 3 as well, though their tests are small checks that run in
//! seconds either way. Cargo has no setting per target, so the wrapper Cargo runs for the
//! workspace's crates (`RUSTC_WORKSPACE_WRAPPER`) appends a lower `-C opt-level` to those
//! compilations ([`UNIT_TEST_OPT_LEVELS`]; rustc takes a codegen option's last value) and
//! hands every call to `clippy-driver` unchanged otherwise. Optimisation does not change a
//! floating-point result here (no fast-math), so the tests check the same numbers.
//!
//! Cargo calls the wrapper as `WRAPPER RUSTC ARGS…`; this executable knows the call by
//! [`DRIVER_VAR`] in its environment, set only by [`crate::workspace::linted_cargo`], and
//! a first argument naming rustc. Cargo fingerprints the wrapper by its path, not by what
//! it does: a change of [`UNIT_TEST_OPT_LEVELS`] reaches a crate already built at its next
//! change (only the build's time depends on it).

use std::ffi::{OsStr, OsString};
use std::path::Path;
use std::process::Command;

/// Environment variable holding the `clippy-driver` the wrapper hands its calls to.
pub const DRIVER_VAR: &str = "EHA_XTASK_CLIPPY_DRIVER";

/// Environment variable naming the wrapper (`cargo xtask`'s executable) for the processes
/// `cargo xtask` starts that run linted builds themselves.
pub const WRAPPER_VAR: &str = "EHA_XTASK_WRAPPER";

/// Crates (rustc's names) whose unit-test build takes a lower optimisation level, and that
/// level: 0 where the compile saves far more than the slower tests cost, 1 for the
/// firmware's, whose tests would spend unoptimised about what the compile saves.
pub const UNIT_TEST_OPT_LEVELS: [(&str, &str); 4] = [
    ("host_sim", "0"),
    ("plant_model", "0"),
    ("closed_loop", "0"),
    ("firmware", "1"),
];

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
    if let Some(level) = unit_test_opt_level(&args) {
        cmd.arg(format!("-Copt-level={level}"));
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

/// The optimisation level of the compiler call `args` when it builds the unit tests
/// (`--test`) of one of [`UNIT_TEST_OPT_LEVELS`].
fn unit_test_opt_level(args: &[OsString]) -> Option<&'static str> {
    if !args.iter().any(|a| a == "--test") {
        return None;
    }
    let crate_name = args
        .windows(2)
        .find(|w| w[0] == "--crate-name")
        .map(|w| w[1].as_os_str())?;
    UNIT_TEST_OPT_LEVELS
        .iter()
        .find(|(name, _)| crate_name == OsStr::new(name))
        .map(|(_, level)| *level)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn call(line: &str) -> Vec<OsString> {
        line.split(' ').map(OsString::from).collect()
    }

    #[test]
    fn only_the_listed_unit_tests_take_a_lower_level() {
        let level = |line: &str| unit_test_opt_level(&call(line));
        let unit =
            "rustc --crate-name host_sim --edition=2021 host-sim/src/lib.rs --test -C opt-level=3";
        assert_eq!(level(unit), Some("0"));
        assert_eq!(
            level("rustc --crate-name plant_model --test p/src/lib.rs"),
            Some("0")
        );
        assert_eq!(
            level("rustc --crate-name closed_loop --test c/src/lib.rs"),
            Some("0")
        );
        assert_eq!(
            level("rustc --crate-name firmware --test f/src/lib.rs"),
            Some("1")
        );
        // The library itself, as the integration tests link it.
        let lib = "rustc --crate-name host_sim --crate-type lib host-sim/src/lib.rs -C opt-level=3";
        assert_eq!(level(lib), None);
        // An integration test of host-sim, another crate's unit tests.
        assert_eq!(
            level("rustc --crate-name bad_input tests/bad_input.rs --test"),
            None
        );
        assert_eq!(
            level("rustc --crate-name tests tests/src/lib.rs --test"),
            None
        );
        // A crate whose name only contains a listed one.
        assert_eq!(level("rustc --crate-name host_sim_extra --test x.rs"), None);
    }
}
