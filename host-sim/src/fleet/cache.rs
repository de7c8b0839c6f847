//! What makes a fleet run resumable: every log is known by the SHA-256 of its bytes, and
//! each diagnosis is kept in the output folder as `diagnoses/<sha256>.json`, a record the
//! next run reads instead of diagnosing the log again:
//!
//! ```text
//! {"sha256": "<log's SHA-256, hex>", "rig_sha256": "<rig file's SHA-256, or \"nominal\">",
//!  "eha_version": "<version of the eha that diagnosed it>",
//!  "outcome": "ok" | "bad_input",
//!  "diagnosis": {… eha diagnose's JSON …}          (outcome ok)
//!  "error": "<eha diagnose's message>"}             (outcome bad_input)
//! ```
//!
//! Only outcomes that the log's content decides are kept: a diagnosis, or a log the
//! diagnosis refuses as bad input (exit status 2). A diagnosis that was killed, timed out
//! or failed otherwise is not kept, so the next run tries it again. A record made on
//! another rig or by another version of eha does not count. Each record is an output
//! transaction of its own ([`crate::output::Outputs`]), committed the moment the outcome
//! is known, so a run killed at any moment leaves whole records or none; the Dask driver
//! (`tools/fleet_dask.py`) writes the same records.

use crate::output::{CliError, Outputs};
use serde_json::{json, Value};
use sha2::{Digest, Sha256};
use std::fs::File;
use std::io::{self, Read};
use std::path::{Path, PathBuf};

/// The folder of the records inside the output folder.
pub const FOLDER: &str = "diagnoses";

/// The rig identity of the nominal rig (no `--rig`).
pub const NOMINAL_RIG: &str = "nominal";

/// What decides whether a record still holds: the rig and the version of eha.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Context {
    /// SHA-256 of the rig file, or [`NOMINAL_RIG`].
    pub rig_sha256: String,
    /// The version of eha.
    pub eha_version: String,
}

/// A kept outcome.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// The diagnosis's JSON.
    Diagnosed(Value),
    /// The log refused as bad input, with the message.
    BadInput(String),
}

/// SHA-256 of a file's bytes, read in blocks (memory bounded whatever the file's size), as
/// lower-case hex.
pub fn sha256_file(path: &Path) -> io::Result<String> {
    let mut file = File::open(path)?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = match file.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        hasher.update(&buf[..n]);
    }
    Ok(hex(&hasher.finalize()))
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The record's path for the log of hash `sha256`.
pub fn record_path(out: &Path, sha256: &str) -> PathBuf {
    out.join(FOLDER).join(format!("{sha256}.json"))
}

/// The kept outcome for the log of hash `sha256`, if there is one that holds in `ctx`; a
/// missing, unreadable or malformed record is none.
pub fn load(out: &Path, sha256: &str, ctx: &Context) -> Option<Outcome> {
    let text = std::fs::read_to_string(record_path(out, sha256)).ok()?;
    let v: Value = serde_json::from_str(&text).ok()?;
    let holds = v["sha256"] == sha256
        && v["rig_sha256"] == ctx.rig_sha256.as_str()
        && v["eha_version"] == ctx.eha_version.as_str();
    if !holds {
        return None;
    }
    match v["outcome"].as_str()? {
        "ok" => Some(Outcome::Diagnosed(v.get("diagnosis")?.clone())),
        "bad_input" => Some(Outcome::BadInput(v["error"].as_str()?.to_string())),
        _ => None,
    }
}

/// Keeps `outcome` for the log of hash `sha256` in the output folder `out` (given by
/// `--out`), whole or not at all.
pub fn store(out: &Path, sha256: &str, ctx: &Context, outcome: &Outcome) -> Result<(), CliError> {
    let mut v = json!({
        "sha256": sha256,
        "rig_sha256": ctx.rig_sha256,
        "eha_version": ctx.eha_version,
    });
    match outcome {
        Outcome::Diagnosed(d) => {
            v["outcome"] = json!("ok");
            v["diagnosis"] = d.clone();
        }
        Outcome::BadInput(e) => {
            v["outcome"] = json!("bad_input");
            v["error"] = json!(e);
        }
    }
    let folder = out.join(FOLDER);
    std::fs::create_dir_all(&folder).map_err(|source| CliError::Write {
        file: folder,
        source,
    })?;
    let text = serde_json::to_string(&v).map_err(|e| CliError::Failed(e.to_string()))?;
    let mut outputs = Outputs::new();
    outputs.file("--out", &record_path(out, sha256), text.as_bytes())?;
    outputs.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hashes_are_sha256_of_the_bytes() {
        // FIPS 180-2's test vector "abc", and the empty message.
        let d = crate::output::scratch::scratch_dir("fleet-sha");
        std::fs::write(d.join("abc"), b"abc").unwrap();
        std::fs::write(d.join("empty"), b"").unwrap();
        assert_eq!(
            sha256_file(&d.join("abc")).unwrap(),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        assert_eq!(
            sha256_file(&d.join("empty")).unwrap(),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn records_hold_only_for_their_rig_and_version() {
        let d = crate::output::scratch::scratch_dir("fleet-cache");
        let ctx = Context {
            rig_sha256: NOMINAL_RIG.into(),
            eha_version: "1.0".into(),
        };
        let h = "ab".repeat(32);
        assert_eq!(load(&d, &h, &ctx), None);
        let ok = Outcome::Diagnosed(json!({"samples": 4000}));
        store(&d, &h, &ctx, &ok).unwrap();
        assert_eq!(load(&d, &h, &ctx), Some(ok));
        let other_rig = Context {
            rig_sha256: "cd".repeat(32),
            ..ctx.clone()
        };
        assert_eq!(load(&d, &h, &other_rig), None);
        let bad = Outcome::BadInput("line 5: not a number".into());
        store(&d, &h, &ctx, &bad).unwrap();
        assert_eq!(load(&d, &h, &ctx), Some(bad));
        std::fs::write(record_path(&d, &h), "{ truncated").unwrap();
        assert_eq!(load(&d, &h, &ctx), None);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
