//! Scratch folders for the unit tests that write files.

use std::path::PathBuf;

/// A fresh, empty scratch folder `eha-<name>-<pid>` for a unit test.
pub(crate) fn scratch_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("eha-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}
