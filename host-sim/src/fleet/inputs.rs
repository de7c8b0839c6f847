//! The logs of a fleet run and what is known of each before it is diagnosed: found in the
//! files and folders given (folders searched recursively for `*.csv`, hidden entries and
//! the output folder skipped) and in a manifest CSV (`path`, `drive`, `recorded_at`
//! columns; paths relative to the manifest's folder), each with its drive and start time
//! from the manifest or else from the log's `# drive:` and `# recorded_at:` lines.
//!
//! The logs are put in one deterministic order — drive, start time, path — and
//! `--shard K/N` takes the K-th of N contiguous parts of it, so the shards' tables,
//! concatenated in order, are the whole table.

use crate::bench_log::{self, DRIVE_KEY, RECORDED_AT_KEY};
use crate::output::file_kind::describe;
use crate::output::CliError;
use crate::timestamp::parse_days;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One log of the run.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    /// The log's path as given or found (relative paths stay relative).
    pub path: PathBuf,
    /// The drive it is of, if known.
    pub drive: Option<String>,
    /// When it started, as written (RFC 3339), if known.
    pub recorded_at: Option<String>,
    /// `recorded_at` in days since the Unix epoch. [day]
    pub t_days: Option<f64>,
    /// Why the log cannot be diagnosed before it is even read (its metadata unreadable or
    /// its time no RFC 3339 timestamp).
    pub problem: Option<String>,
}

/// What the manifest says of one log.
#[derive(Clone, Debug, Default, PartialEq)]
struct Listed {
    drive: Option<String>,
    recorded_at: Option<String>,
}

/// `--shard K/N`: the K-th (0-based) of N parts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// Which part, 0-based.
    pub index: usize,
    /// How many parts.
    pub count: usize,
}

/// Parses `K/N` with 0 ≤ K < N.
pub fn parse_shard(s: &str) -> Result<Shard, String> {
    let (k, n) = s
        .split_once('/')
        .ok_or_else(|| format!("`{s}` is not K/N (for example 0/4)"))?;
    let index: usize = k
        .trim()
        .parse()
        .map_err(|_| format!("`{s}`: K must be a whole number from 0"))?;
    let count: usize = n
        .trim()
        .parse()
        .map_err(|_| format!("`{s}`: N must be a whole number from 1"))?;
    if count == 0 || index >= count {
        return Err(format!(
            "`{s}`: K counts from 0 and must be below N (0/{n} to {}/{n})",
            count.max(1) - 1
        ));
    }
    Ok(Shard { index, count })
}

impl Shard {
    /// The shard's part of `n` ordered items: items [K·n/N, (K+1)·n/N).
    pub fn range(self, n: usize) -> std::ops::Range<usize> {
        (self.index * n / self.count)..((self.index + 1) * n / self.count)
    }
}

/// Every log of the run in the table's order: the files and folders of `paths` and the
/// manifest's logs (once each), drive and time filled in; `out` (the output folder) is
/// never searched. Bad arguments (a path that does not exist, a manifest that cannot be
/// read or breaks its format) are errors; a log that cannot be read is an entry with its
/// problem.
pub fn gather(
    paths: &[PathBuf],
    manifest: Option<&Path>,
    out: &Path,
) -> Result<Vec<Entry>, CliError> {
    let listed = match manifest {
        Some(m) => read_manifest(m)?,
        None => Vec::new(),
    };
    let mut found: Vec<PathBuf> = Vec::new();
    let out_canonical = std::fs::canonicalize(out).ok();
    for p in paths {
        let meta = std::fs::metadata(p)
            .map_err(|e| CliError::BadInput(format!("`{}`: {}", p.display(), describe(&e))))?;
        if meta.is_dir() {
            search(p, out_canonical.as_deref(), &mut found)?;
        } else {
            found.push(p.clone());
        }
    }
    // One entry per file: the manifest's spelling and data win over a search's.
    let mut by_file: BTreeMap<PathBuf, (PathBuf, Listed)> = BTreeMap::new();
    for (path, l) in listed {
        by_file.entry(identity(&path)).or_insert((path, l));
    }
    for path in found {
        by_file
            .entry(identity(&path))
            .or_insert((path, Listed::default()));
    }
    let mut entries: Vec<Entry> = by_file
        .into_values()
        .map(|(path, l)| entry(path, l))
        .collect();
    entries.sort_by(order);
    Ok(entries)
}

/// The table's order: drive, then time, then path (entries without a drive or time first).
fn order(a: &Entry, b: &Entry) -> std::cmp::Ordering {
    a.drive
        .cmp(&b.drive)
        .then(
            a.t_days
                .unwrap_or(f64::NEG_INFINITY)
                .total_cmp(&b.t_days.unwrap_or(f64::NEG_INFINITY)),
        )
        .then_with(|| a.path.cmp(&b.path))
}

/// What makes two spellings one file: its canonical path where it exists.
fn identity(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
}

/// The entry of `path`: the manifest's drive and time, else the log's metadata lines.
fn entry(path: PathBuf, listed: Listed) -> Entry {
    let mut e = Entry {
        path,
        drive: listed.drive,
        recorded_at: listed.recorded_at,
        t_days: None,
        problem: None,
    };
    // Only regular files are logs: opening a FIFO would wait for a writer for ever, a
    // device would never end.
    match std::fs::metadata(&e.path) {
        Ok(m) if m.is_file() => {}
        Ok(_) => {
            e.problem = Some(format!(
                "bench log `{}`: not a regular file",
                e.path.display()
            ));
            return e;
        }
        Err(err) => {
            e.problem = Some(format!(
                "bench log `{}`: {}",
                e.path.display(),
                describe(&err)
            ));
            return e;
        }
    }
    if e.drive.is_none() || e.recorded_at.is_none() {
        match bench_log::read_metadata(&e.path) {
            Ok(meta) => {
                let value = |key: &str| {
                    meta.iter()
                        .find(|(k, _)| k == key)
                        .map(|(_, v)| v.clone())
                        .filter(|v| !v.is_empty())
                };
                e.drive = e.drive.or_else(|| value(DRIVE_KEY));
                e.recorded_at = e.recorded_at.or_else(|| value(RECORDED_AT_KEY));
            }
            Err(err) => e.problem = Some(err.to_string()),
        }
    }
    if let Some(at) = &e.recorded_at {
        match parse_days(at) {
            Ok(d) => e.t_days = Some(d),
            Err(why) => {
                e.problem.get_or_insert(format!(
                    "bench log `{}`: recorded_at: {why}",
                    e.path.display()
                ));
            }
        }
    }
    e
}

/// Every `*.csv` file below `dir` (hidden files and folders, and `out`, skipped), in
/// name order; symbolic links are not followed (a link loop cannot trap the search).
fn search(dir: &Path, out: Option<&Path>, found: &mut Vec<PathBuf>) -> Result<(), CliError> {
    let walk = walkdir::WalkDir::new(dir)
        .sort_by_file_name()
        .into_iter()
        .filter_entry(|e| {
            let hidden = e.depth() > 0 && e.file_name().to_string_lossy().starts_with('.');
            let is_out = e.file_type().is_dir()
                && out.is_some_and(|o| std::fs::canonicalize(e.path()).ok().as_deref() == Some(o));
            !hidden && !is_out
        });
    for item in walk {
        match item {
            Ok(e) => {
                let csv = e
                    .path()
                    .extension()
                    .is_some_and(|x| x.eq_ignore_ascii_case("csv"));
                if csv && !e.file_type().is_dir() {
                    found.push(e.into_path());
                }
            }
            Err(err) => {
                // A folder that cannot be listed is a log (or many) that cannot be read:
                // an argument the run cannot honour.
                let at = err.path().unwrap_or(dir).display().to_string();
                let why = err.io_error().map_or_else(|| err.to_string(), describe);
                return Err(CliError::BadInput(format!(
                    "cannot search `{at}` for logs: {why}"
                )));
            }
        }
    }
    Ok(())
}

/// The manifest's logs: a CSV with a header naming at least `path` (and optionally
/// `drive`, `recorded_at`; other columns ignored). Relative paths are relative to the
/// manifest's folder. Any flaw is bad input naming the line.
fn read_manifest(path: &Path) -> Result<Vec<(PathBuf, Listed)>, CliError> {
    let bad = |line: u64, why: String| {
        CliError::BadInput(format!("manifest `{}`, line {line}: {why}", path.display()))
    };
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_path(path)
        .map_err(|e| CliError::BadInput(format!("manifest `{}`: {e}", path.display())))?;
    let headers = reader.headers().map_err(|e| bad(1, e.to_string()))?.clone();
    let column = |name: &str| headers.iter().position(|h| h == name);
    let path_col = column("path").ok_or_else(|| {
        bad(
            1,
            "no `path` column in the header (columns: path, drive, recorded_at)".into(),
        )
    })?;
    let (drive_col, time_col) = (column("drive"), column("recorded_at"));
    let base = path.parent().unwrap_or(Path::new(""));
    let mut out = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            bad(line, e.to_string())
        })?;
        let line = record.position().map_or(0, |p| p.line());
        let field = |c: Option<usize>| {
            c.and_then(|c| record.get(c))
                .filter(|v| !v.is_empty())
                .map(str::to_string)
        };
        let Some(p) = field(Some(path_col)) else {
            return Err(bad(line, "the `path` field is empty".into()));
        };
        let recorded_at = field(time_col);
        if let Some(at) = &recorded_at {
            parse_days(at).map_err(|why| bad(line, format!("recorded_at: {why}")))?;
        }
        let drive = field(drive_col);
        if drive.as_deref().is_some_and(|d| d.contains(['\n', '\r'])) {
            return Err(bad(line, "a drive's name must be on one line".into()));
        }
        let p = PathBuf::from(p);
        let p = if p.is_relative() { base.join(p) } else { p };
        out.push((p, Listed { drive, recorded_at }));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_are_contiguous_parts_that_cover_everything_once() {
        assert_eq!(parse_shard("1/3").unwrap(), Shard { index: 1, count: 3 });
        for bad in ["3/3", "1", "a/2", "0/0", "-1/2"] {
            assert!(parse_shard(bad).is_err(), "{bad}");
        }
        for n in [0, 1, 7, 10] {
            for count in 1..5 {
                let mut all = Vec::new();
                for index in 0..count {
                    all.extend(Shard { index, count }.range(n));
                }
                assert_eq!(all, (0..n).collect::<Vec<_>>(), "n {n} in {count}");
            }
        }
    }

    #[test]
    fn the_manifest_wins_and_folders_are_searched_without_the_output() {
        let d = crate::output::scratch::scratch_dir("fleet-inputs");
        let logs = d.join("logs");
        std::fs::create_dir_all(logs.join("b")).unwrap();
        std::fs::create_dir_all(logs.join(".hidden")).unwrap();
        let head = |drive: &str, at: &str| format!("# drive: {drive}\n# recorded_at: {at}\nt_s\n");
        std::fs::write(logs.join("b/2.csv"), head("D2", "2026-02-01T00:00:00Z")).unwrap();
        std::fs::write(logs.join("1.csv"), head("D2", "2026-01-01T00:00:00Z")).unwrap();
        std::fs::write(logs.join("0.CSV"), head("D1", "2026-03-01T00:00:00Z")).unwrap();
        std::fs::write(logs.join("notes.txt"), "x").unwrap();
        std::fs::write(logs.join(".hidden/x.csv"), "x").unwrap();
        let out = logs.join("out");
        std::fs::create_dir_all(&out).unwrap();
        std::fs::write(out.join("fleet.csv"), "x").unwrap();
        let manifest = d.join("m.csv");
        std::fs::write(
            &manifest,
            "path,drive,recorded_at,comment\nlogs/1.csv,D0,,moved\n",
        )
        .unwrap();
        let e = gather(std::slice::from_ref(&logs), Some(&manifest), &out).unwrap();
        let names: Vec<String> = e
            .iter()
            .map(|e| format!("{} {:?}", e.path.display(), e.drive))
            .collect();
        // 1.csv under the manifest's spelling and drive, its time from the log; then by
        // drive and time.
        assert_eq!(
            names,
            [
                format!("{} Some(\"D0\")", d.join("logs/1.csv").display()),
                format!("{} Some(\"D1\")", logs.join("0.CSV").display()),
                format!("{} Some(\"D2\")", logs.join("b/2.csv").display()),
            ]
        );
        assert_eq!(e[0].recorded_at.as_deref(), Some("2026-01-01T00:00:00Z"));
        assert!(e.iter().all(|e| e.problem.is_none()));
        // A bad time in a log is that log's problem; in the manifest, a bad argument.
        std::fs::write(logs.join("1.csv"), head("D2", "yesterday")).unwrap();
        let e = gather(std::slice::from_ref(&logs), None, &out).unwrap();
        let bad = e.iter().find(|e| e.path.ends_with("1.csv")).unwrap();
        assert!(bad.problem.as_deref().unwrap().contains("RFC 3339"));
        std::fs::write(&manifest, "path,recorded_at\nlogs/1.csv,soon\n").unwrap();
        let err = gather(&[], Some(&manifest), &out).unwrap_err();
        assert!(err.to_string().contains("line 2"), "{err}");
        assert_eq!(err.exit_status(), 2);
        std::fs::write(&manifest, "file\nlogs/1.csv\n").unwrap();
        assert!(gather(&[], Some(&manifest), &out).is_err());
        assert!(gather(&[d.join("absent")], None, &out).is_err());
        std::fs::remove_dir_all(&d).unwrap();
    }
}
