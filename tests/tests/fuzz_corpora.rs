//! Replays, on stable, every input kept for the fuzz targets (`fuzz/seeds/<target>/`, the
//! minimised corpora `fuzz/corpus/<target>/` when present, and each finding in
//! `fuzz/regressions/<target>/`) through the same target bodies libFuzzer runs
//! ([`tests::fuzz`]): none may panic. Also makes sure every target has seeds and every
//! folder names a target.

use std::fs;
use std::path::{Path, PathBuf};
use tests::fuzz::TARGETS;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz")
}

/// The files directly in `dir` (none if it does not exist), sorted.
fn files(dir: &Path) -> Vec<PathBuf> {
    let Ok(rd) = fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut v: Vec<PathBuf> = rd
        .map(|e| e.expect("a directory entry").path())
        .filter(|p| p.is_file())
        .collect();
    v.sort();
    v
}

#[test]
fn every_kept_input_replays_without_panic() {
    let mut failures = Vec::new();
    let mut replayed = 0;
    for (name, body) in TARGETS {
        let seeds = files(&root().join("seeds").join(name));
        assert!(!seeds.is_empty(), "target {name} has no seeds");
        for set in ["seeds", "corpus", "regressions"] {
            for file in files(&root().join(set).join(name)) {
                let data = fs::read(&file).expect("a readable input");
                replayed += 1;
                if std::panic::catch_unwind(|| body(&data)).is_err() {
                    failures.push(file.display().to_string());
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {replayed} inputs panic: {failures:#?}",
        failures.len()
    );
}

#[test]
fn every_corpus_folder_names_a_target() {
    for set in ["seeds", "corpus", "regressions"] {
        let Ok(rd) = fs::read_dir(root().join(set)) else {
            continue;
        };
        for e in rd {
            let name = e
                .expect("an entry")
                .file_name()
                .to_string_lossy()
                .into_owned();
            assert!(
                TARGETS.iter().any(|(t, _)| *t == name),
                "fuzz/{set}/{name} is no target"
            );
        }
    }
}
