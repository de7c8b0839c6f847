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
//! hands every call to `clippy-driver` unchanged otherwise. Their integration tests,
//! benchmarks and examples are compiled unoptimised the same way
//! ([`helper_target_opt_level`]). Optimisation does not change a floating-point result
//! here (no fast-math), so the tests check the same numbers.
//!
//! Cargo calls the wrapper as `WRAPPER RUSTC ARGS…`; this executable knows the call by
//! [`DRIVER_VAR`] in its environment, set only by [`crate::workspace::linted_cargo`], and
//! a first argument naming rustc. Cargo fingerprints the wrapper by its path, not by what
//! it does: a change of [`UNIT_TEST_OPT_LEVELS`] reaches a crate already built at its next
//! change (only the build's time depends on it).

use std::ffi::{OsStr, OsString};
use std::path::{Path, PathBuf};
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
    let package = std::env::var_os("CARGO_MANIFEST_DIR").map(PathBuf::from);
    let level = unit_test_opt_level(&args).or_else(|| {
        let cwd = std::env::current_dir().ok()?;
        helper_target_opt_level(&args, &cwd, package.as_deref()?)
    });
    if let Some(level) = level {
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

/// The folders of a package whose crates are its integration tests, benchmarks and
/// examples (Cargo's conventional places).
const HELPER_TARGET_DIRS: [&str; 3] = ["tests", "benches", "examples"];

/// The optimisation level of the compiler call `args` (run in `cwd`, for the package in
/// `package`) when its crate root lies in one of [`HELPER_TARGET_DIRS`]: "0". The dev
/// profile's level is the package's, for every target; the optimised packages' tests,
/// benchmarks and examples call the library (optimised) for their heavy work, or run `eha`,
/// and the linted build only compiles the benchmarks and examples, so optimising them again
/// costs compile time the runs do not give back. A plain `cargo test`, `cargo run
/// --example` or `cargo bench` keeps the profile's level.
fn helper_target_opt_level(args: &[OsString], cwd: &Path, package: &Path) -> Option<&'static str> {
    let root = args
        .iter()
        .filter(|a| !a.to_string_lossy().starts_with('-'))
        .map(Path::new)
        .find(|a| a.extension() == Some(OsStr::new("rs")))?;
    let root = cwd.join(root);
    let first = root.strip_prefix(package).ok()?.components().next()?;
    HELPER_TARGET_DIRS
        .iter()
        .any(|d| first.as_os_str() == OsStr::new(d))
        .then_some("0")
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

    #[test]
    fn a_packages_tests_benchmarks_and_examples_take_level_0() {
        let ws = Path::new("/w");
        let pkg = Path::new("/w/host-sim");
        let level = |line: &str| helper_target_opt_level(&call(line), ws, pkg);
        assert_eq!(
            level("rustc --crate-name cli --edition=2021 host-sim/tests/cli.rs --test"),
            Some("0")
        );
        assert_eq!(
            level(
                "rustc --crate-name closed_loop host-sim/benches/closed_loop.rs --crate-type bin"
            ),
            Some("0")
        );
        assert_eq!(
            level("rustc --crate-name residual_budget /w/host-sim/examples/residual_budget.rs"),
            Some("0")
        );
        // The library, its unit tests and the executable keep the profile's level.
        assert_eq!(
            level("rustc --crate-name host_sim host-sim/src/lib.rs"),
            None
        );
        assert_eq!(
            level("rustc --crate-name host_sim host-sim/src/lib.rs --test"),
            None
        );
        assert_eq!(level("rustc --crate-name eha host-sim/src/main.rs"), None);
        // Another package's tests, a file named like the folders elsewhere, no crate root.
        assert_eq!(
            level("rustc --crate-name faults plant-model/tests/faults.rs --test"),
            None
        );
        assert_eq!(level("rustc --crate-name x host-sim/src/tests.rs"), None);
        assert_eq!(level("rustc -vV"), None);
    }
}
