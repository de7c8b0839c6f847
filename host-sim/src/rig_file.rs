//! The rig file: the project's format for a rig, TOML of [`plant_model::Rig`] (its serde
//! derives), one table per parameter group (`[motor]`, `[pump]`, `[absorber]`, …) with the
//! field names and SI units of `plant_model::rig`. `eha rig` prints the nominal rig in this
//! format; `--rig FILE` loads one.
//!
//! Loading checks, in order, and names the file and the place in every error: TOML syntax
//! and types (line, column and key, from the TOML parser), keys the rig does not have (a
//! misspelt key would otherwise be ignored silently), then the physics ([`Rig::validate`],
//! naming the parameter). A file must give every parameter: start from `eha rig > my.toml`.
//!
//! `eha rig` ([`crate::rig_command`]) prints a rig in this format.

use crate::output::file_kind::{describe, input_problem};
use plant_model::{Rig, RigError};
use std::io::Read as _;
use std::path::{Path, PathBuf};

/// A rig file that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum RigFileError {
    /// The file cannot be read.
    #[error("rig file `{}`: {}", file.display(), describe(source))]
    Read {
        /// The file.
        file: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// Not TOML, or a value of the wrong type, or a parameter missing.
    #[error("rig file `{}`{}: {message}", file.display(), key.as_ref().map(|k| format!(", key `{k}`")).unwrap_or_default())]
    Syntax {
        /// The file.
        file: PathBuf,
        /// Dotted path of the key whose value is wrong, when the error sits on a
        /// `key = value` line.
        key: Option<String>,
        /// The TOML parser's message: line, column, the offending text and the key.
        message: String,
        /// 1-based line of the error, when the parser gives one.
        line: Option<usize>,
    },
    /// A key the rig does not have.
    #[error("rig file `{}`, line {line}: unknown key `{key}` (a misspelt parameter name?)", file.display())]
    UnknownKey {
        /// The file.
        file: PathBuf,
        /// Dotted path of the key, e.g. `absorber.precharge`.
        key: String,
        /// 1-based line where the key is written (its first mention; 0 if not found).
        line: usize,
    },
    /// Parsed, but physically invalid.
    #[error("rig file `{}`: {source}", file.display())]
    Invalid {
        /// The file.
        file: PathBuf,
        /// The parameter and the reason.
        source: RigError,
    },
}

/// The largest rig file read: the nominal rig is under 3 kB. [bytes]
pub const MAX_BYTES: u64 = 1 << 20;

/// Reads, parses and validates the rig file at `path` (a regular file or a pipe of at most
/// [`MAX_BYTES`] of UTF-8 text).
pub fn load(path: &Path) -> Result<Rig, RigFileError> {
    let read_err = |source| RigFileError::Read {
        file: path.to_path_buf(),
        source,
    };
    let refuse = |why: String| read_err(std::io::Error::new(std::io::ErrorKind::InvalidInput, why));
    if let Some(why) = input_problem(path) {
        return Err(refuse(why));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_BYTES + 1).read_to_end(&mut bytes))
        .map_err(read_err)?;
    if bytes.len() as u64 > MAX_BYTES {
        return Err(refuse(format!(
            "larger than {MAX_BYTES} bytes; a rig file is a few kilobytes of TOML"
        )));
    }
    let text = String::from_utf8(bytes).map_err(|e| {
        refuse(format!(
            "not UTF-8 text (byte {})",
            e.utf8_error().valid_up_to()
        ))
    })?;
    from_toml(&text, path)
}

/// Parses and validates a rig from TOML `text`; `path` names it in errors.
pub fn from_toml(text: &str, path: &Path) -> Result<Rig, RigFileError> {
    let syntax = |e: toml::de::Error| {
        let line = e
            .span()
            .map(|s| 1 + text[..s.start.min(text.len())].matches('\n').count());
        RigFileError::Syntax {
            file: path.to_path_buf(),
            key: line.and_then(|l| key_at_line(text, l)),
            line,
            message: e.to_string().trim_end().to_string(),
        }
    };
    let rig: Rig = toml::from_str(text).map_err(syntax)?;
    // Keys serde skipped: everything in the file that the rig does not write back.
    let given: toml::Table = toml::from_str(text).map_err(syntax)?;
    let known = toml::Table::try_from(&rig).map_err(|e| RigFileError::Syntax {
        file: path.to_path_buf(),
        key: None,
        line: None,
        message: e.to_string(),
    })?;
    if let Some(key) = first_unknown_key(&given, &known, "") {
        let line = line_of_key(text, &key);
        return Err(RigFileError::UnknownKey {
            file: path.to_path_buf(),
            key,
            line,
        });
    }
    rig.validate().map_err(|source| RigFileError::Invalid {
        file: path.to_path_buf(),
        source,
    })?;
    Ok(rig)
}

/// The rig in the rig-file format.
pub fn to_toml(rig: &Rig) -> String {
    // Serialising plain structs of numbers, bools and fixed arrays cannot fail.
    toml::to_string(rig).unwrap_or_else(|e| format!("# cannot serialise the rig: {e}\n"))
}

/// The first key path of `given` absent from `known`, descending into tables and arrays of
/// tables.
fn first_unknown_key(given: &toml::Table, known: &toml::Table, prefix: &str) -> Option<String> {
    for (k, v) in given {
        let path = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        let Some(kv) = known.get(k) else {
            return Some(path);
        };
        let found = match (v, kv) {
            (toml::Value::Table(g), toml::Value::Table(n)) => first_unknown_key(g, n, &path),
            (toml::Value::Array(g), toml::Value::Array(n)) => {
                g.iter()
                    .zip(n)
                    .enumerate()
                    .find_map(|(i, (gv, nv))| match (gv, nv) {
                        (toml::Value::Table(gt), toml::Value::Table(nt)) => {
                            first_unknown_key(gt, nt, &format!("{path}[{i}]"))
                        }
                        _ => None,
                    })
            }
            _ => None,
        };
        if found.is_some() {
            return found;
        }
    }
    None
}

/// The dotted key assigned on 1-based `line`: the last table header above it and the key
/// left of `=` (`None` when the line assigns nothing).
fn key_at_line(text: &str, line: usize) -> Option<String> {
    let mut table = String::new();
    for l in text.lines().take(line.saturating_sub(1)) {
        let l = l.trim();
        if l.starts_with('[') {
            table = l.trim_matches(|c| c == '[' || c == ']').trim().to_string();
        }
    }
    let (k, _) = text.lines().nth(line.checked_sub(1)?)?.split_once('=')?;
    let k = k.trim().trim_matches('"');
    if k.is_empty() || k.starts_with('#') {
        return None;
    }
    Some(if table.is_empty() {
        k.to_string()
    } else {
        format!("{table}.{k}")
    })
}

/// Best-effort line of a dotted key: the first line that assigns its last segment after the
/// table header of its first segment (0 when not found; the key is named either way).
fn line_of_key(text: &str, key: &str) -> usize {
    let leaf = key
        .rsplit('.')
        .next()
        .unwrap_or(key)
        .split('[')
        .next()
        .unwrap_or(key);
    let table = key.split(['.', '[']).next().unwrap_or("");
    let mut in_table = !key.contains('.');
    for (i, l) in text.lines().enumerate() {
        let l = l.trim();
        if l.starts_with('[') {
            let name = l.trim_matches(|c| c == '[' || c == ']').trim();
            in_table = name == table || name.starts_with(&format!("{table}."));
            if !key.contains('.') && name == leaf {
                return i + 1;
            }
            continue;
        }
        if in_table {
            if let Some((k, _)) = l.split_once('=') {
                if k.trim().trim_matches('"') == leaf {
                    return i + 1;
                }
            }
        }
    }
    0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p() -> &'static Path {
        Path::new("my-rig.toml")
    }

    #[test]
    fn nominal_round_trips_bit_for_bit() {
        let text = to_toml(&Rig::nominal());
        let back = from_toml(&text, p()).unwrap();
        assert_eq!(back, Rig::nominal());
    }

    #[test]
    fn a_non_number_is_named_with_its_line() {
        let text = to_toml(&Rig::nominal())
            .replace("precharge_pa = 3000000.0", "precharge_pa = \"three\"");
        assert_ne!(text, to_toml(&Rig::nominal()), "replacement must hit");
        let e = from_toml(&text, p()).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("my-rig.toml"), "{msg}");
        assert!(msg.contains("key `absorber.precharge_pa`"), "{msg}");
        let want = 1 + text[..text.find("\"three\"").unwrap()]
            .matches('\n')
            .count();
        assert!(
            matches!(e, RigFileError::Syntax { line: Some(l), .. } if l == want),
            "{msg}"
        );
    }

    #[test]
    fn a_negative_volume_is_named_by_validation() {
        let mut rig = Rig::nominal();
        rig.absorber.shell_volume_m3 = -4e-4;
        let e = from_toml(&to_toml(&rig), p()).unwrap_err();
        assert!(
            matches!(&e, RigFileError::Invalid { source, .. } if source.parameter == "absorber.shell_volume_m3"),
            "{e}"
        );
    }

    #[test]
    fn a_misspelt_key_is_rejected_with_its_line() {
        let text =
            to_toml(&Rig::nominal()).replace("[absorber]\n", "[absorber]\nprecharge_Pa = 5e6\n");
        let e = from_toml(&text, p()).unwrap_err();
        let want = 2 + text[..text.find("[absorber]").unwrap()]
            .matches('\n')
            .count();
        match e {
            RigFileError::UnknownKey { key, line, .. } => {
                assert_eq!(key, "absorber.precharge_Pa");
                assert_eq!(line, want);
            }
            e => panic!("{e}"),
        }
    }

    #[test]
    fn a_missing_parameter_is_named() {
        let text = to_toml(&Rig::nominal()).replace("bulk_modulus_pa = 650000000.0\n", "");
        let msg = from_toml(&text, p()).unwrap_err().to_string();
        assert!(msg.contains("bulk_modulus_pa"), "{msg}");
    }
}
