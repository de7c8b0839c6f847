//! The paths a subcommand is given, checked before it starts any work: inputs exist and are
//! files the command can read to their end; outputs are regular files (or folders) it may
//! create or replace, in a folder it can write, none of them an input or another output,
//! and no output file inside an output folder (which is replaced whole); an existing output
//! folder holds only files the command writes there ([`super::folder`]). A failed check is
//! bad input (exit status 2) and leaves nothing behind.
//!
//! Special files are never replaced: an output naming a FIFO, a device node or a socket is
//! refused (`-` is standard output), a symbolic link is followed to the regular file it
//! names (the link stays), a dangling link is refused. Inputs may be regular files or
//! pipes (`<(command)`, `/dev/stdin` on a pipe); a device (`/dev/zero`), a socket or a
//! folder is refused, since reading it would never end or means nothing.

use super::error::CliError;
pub use super::file_kind::{describe, input_problem};
use super::file_kind::{kind, same_file};
use super::stdout::is_stdout;
use std::fs::{self, OpenOptions};
use std::io;
use std::path::{Component, Path, PathBuf};

pub(super) fn bad(flag: &str, path: &Path, why: impl std::fmt::Display) -> CliError {
    let name = if flag.is_empty() {
        format!("`{}`", path.display())
    } else {
        format!("{flag} `{}`", path.display())
    };
    CliError::BadInput(format!("{name}: {why}"))
}

/// The paths a subcommand reads and writes, each with the flag (or argument name) that
/// gave it, checked together by [`check`] before anything runs.
#[derive(Debug, Default)]
pub struct Declared<'a> {
    /// Files read.
    pub inputs: Vec<(&'static str, &'a Path)>,
    /// Files written (`-`: standard output).
    pub files: Vec<(&'static str, &'a Path)>,
    /// Folders written (created if missing, replaced whole), each with the names of the
    /// files it may hold before ([`super::folder`]).
    pub dirs: Vec<(&'static str, &'a Path, &'static [&'static str])>,
}

impl<'a> Declared<'a> {
    /// Adds an input, if given.
    pub fn input(mut self, flag: &'static str, path: Option<&'a PathBuf>) -> Self {
        self.inputs.extend(path.map(|p| (flag, p.as_path())));
        self
    }

    /// Adds an output file, if given.
    pub fn file(mut self, flag: &'static str, path: Option<&'a PathBuf>) -> Self {
        self.files.extend(path.map(|p| (flag, p.as_path())));
        self
    }

    /// Adds an output folder, if given, into which the command writes files `owned` names
    /// (`*` standing for any text).
    pub fn dir(
        mut self,
        flag: &'static str,
        path: Option<&'a PathBuf>,
        owned: &'static [&'static str],
    ) -> Self {
        self.dirs.extend(path.map(|p| (flag, p.as_path(), owned)));
        self
    }
}

/// Checks every declared path: inputs readable, outputs writable and none an input, no two
/// outputs the same, no output file inside an output folder.
pub fn check(d: &Declared) -> Result<(), CliError> {
    for (flag, p) in &d.inputs {
        input_file(flag, p)?;
    }
    let inputs: Vec<&Path> = d.inputs.iter().map(|(_, p)| *p).collect();
    for (flag, p) in &d.files {
        output_file(flag, p, &inputs)?;
    }
    for (flag, p, owned) in &d.dirs {
        output_dir(flag, p, &inputs, owned)?;
    }
    let folders: Vec<(&str, &Path)> = d.dirs.iter().map(|(f, p, _)| (*f, *p)).collect();
    let outputs: Vec<(&str, &Path)> = d.files.iter().chain(&folders).copied().collect();
    distinct(&outputs)?;
    for (ff, file) in d.files.iter().filter(|(_, p)| !is_stdout(p)) {
        for (fd, dir) in &folders {
            if lies_in(file, dir) {
                return Err(CliError::BadInput(format!(
                    "{ff} `{}` lies in the {fd} folder `{}`, which eha replaces whole: name a \
                     file outside it",
                    file.display(),
                    dir.display()
                )));
            }
        }
    }
    Ok(())
}

/// Whether the file `file` (existing or not) lies in the folder `dir` or below it.
fn lies_in(file: &Path, dir: &Path) -> bool {
    let (Ok(dir), Ok(parent)) = (fs::canonicalize(dir), fs::canonicalize(parent_of(file))) else {
        return false;
    };
    parent.starts_with(dir)
}

/// Checks an input file: it exists and is a regular file or a pipe.
pub fn input_file(flag: &str, path: &Path) -> Result<(), CliError> {
    if path.as_os_str().is_empty() {
        return Err(CliError::BadInput(format!("{flag}: the path is empty")));
    }
    input_problem(path).map_or(Ok(()), |why| Err(bad(flag, path, why)))
}

/// The file an output path will replace: the path itself, or for a symbolic link the
/// regular file it names. Fails for a dangling link and for anything that is not a regular
/// file (so special files are never replaced). `Ok(None)` when nothing is there yet.
pub fn replaced_file(path: &Path) -> io::Result<Option<PathBuf>> {
    let link = match fs::symlink_metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e),
    };
    let (target, m) = if link.file_type().is_symlink() {
        let target = fs::canonicalize(path).map_err(|_| {
            io::Error::new(
                io::ErrorKind::InvalidInput,
                "is a symbolic link to nothing (dangling)",
            )
        })?;
        let m = fs::metadata(&target)?;
        (target, m)
    } else {
        (path.to_path_buf(), link)
    };
    if m.is_file() {
        Ok(Some(target))
    } else {
        let via = if target.as_path() == path {
            String::new()
        } else {
            format!(" (through the link to `{}`)", target.display())
        };
        Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "is {}{via}, not a regular file; eha writes whole files and never replaces \
                 special files",
                kind(&m)
            ),
        ))
    }
}

/// Checks an output file path (`-` is standard output and always fine) against the inputs
/// it must not overwrite.
pub fn output_file(flag: &str, path: &Path, inputs: &[&Path]) -> Result<(), CliError> {
    if is_stdout(path) {
        return Ok(());
    }
    if path.as_os_str().is_empty() {
        return Err(CliError::BadInput(format!("{flag}: the path is empty")));
    }
    if path.file_name().is_none()
        || matches!(path.components().next_back(), Some(Component::ParentDir))
    {
        return Err(bad(flag, path, "does not name a file"));
    }
    let existing = replaced_file(path).map_err(|e| bad(flag, path, describe(&e)))?;
    if let Some(target) = &existing {
        for input in inputs {
            if same_file(target, input) {
                return Err(bad(
                    flag,
                    path,
                    format!(
                        "is the input `{}`; eha never overwrites its input (name another file)",
                        input.display()
                    ),
                ));
            }
        }
    }
    let written = existing.unwrap_or_else(|| path.to_path_buf());
    writable_folder(flag, path, parent_of(&written))
}

/// Checks an output folder: an existing folder holding only files `owned` names (none of
/// the inputs), or one that can be created; either in a folder where eha can create files
/// (its staging folder goes there).
pub fn output_dir(
    flag: &str,
    path: &Path,
    inputs: &[&Path],
    owned: &[&str],
) -> Result<(), CliError> {
    if path.as_os_str().is_empty() {
        return Err(CliError::BadInput(format!("{flag}: the path is empty")));
    }
    if path.file_name().is_none() {
        return Err(bad(
            flag,
            path,
            "names no folder by its name; eha replaces its output folder whole: name one",
        ));
    }
    let existing = folder_to_be(flag, path, inputs)?;
    if existing != path {
        return writable_folder(flag, path, existing);
    }
    if let Some(why) = super::folder::problem(path, owned, inputs) {
        return Err(bad(flag, path, why));
    }
    // The folder is replaced by one staged beside it: beside the folder a link names.
    let place = fs::canonicalize(path).map_err(|e| bad(flag, path, describe(&e)))?;
    writable_folder(flag, path, parent_of(&place))
}

/// The nearest existing ancestor of the output folder `path` (or `path`), which must be a
/// folder (create_dir_all makes the rest); `path` must be none of `inputs`.
fn folder_to_be<'p>(flag: &str, path: &'p Path, inputs: &[&Path]) -> Result<&'p Path, CliError> {
    for input in inputs {
        if same_file(path, input) {
            return Err(bad(
                flag,
                path,
                format!("is the input `{}`, not a folder", input.display()),
            ));
        }
    }
    // The nearest existing ancestor must be a folder (create_dir_all makes the rest).
    let mut existing = path;
    loop {
        match fs::metadata(existing) {
            Ok(m) if m.is_dir() => break,
            Ok(m) => {
                return Err(bad(
                    flag,
                    path,
                    if existing == path {
                        format!("is {}, not a folder", kind(&m))
                    } else {
                        format!("`{}` is {}, not a folder", existing.display(), kind(&m))
                    },
                ))
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                existing = parent_of(existing);
            }
            Err(e) => return Err(bad(flag, path, describe(&e))),
        }
    }
    Ok(existing)
}

/// Checks a folder a command keeps across runs and writes outputs into one by one (`eha
/// fleet --out`, which holds its kept diagnoses), never replaced whole: not an input, and an
/// existing folder, or one that can be created, in which eha can create files.
pub fn kept_dir(flag: &str, path: &Path, inputs: &[&Path]) -> Result<(), CliError> {
    if path.as_os_str().is_empty() {
        return Err(CliError::BadInput(format!("{flag}: the path is empty")));
    }
    let existing = folder_to_be(flag, path, inputs)?;
    writable_folder(flag, path, existing)
}

/// Checks that every output differs from every other (`-` may repeat only once: two JSON
/// documents on one standard output would not parse).
pub fn distinct(outputs: &[(&str, &Path)]) -> Result<(), CliError> {
    for (i, (fa, a)) in outputs.iter().enumerate() {
        for (fb, b) in &outputs[..i] {
            let clash = if is_stdout(a) || is_stdout(b) {
                is_stdout(a) && is_stdout(b)
            } else {
                same_destination(a, b)
            };
            if clash {
                return Err(CliError::BadInput(format!(
                    "{fb} and {fa} both name `{}`: give each output its own path",
                    a.display()
                )));
            }
        }
    }
    Ok(())
}

/// The folder a file path lies in (`.` for a bare name).
fn parent_of(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// The probe file process `pid` creates in `folder` ([`writable_folder`]) and removes
/// at once; only a process killed between the two leaves it.
pub fn probe_path(folder: &Path, pid: u32) -> PathBuf {
    folder.join(format!(".eha-probe-{pid}"))
}

/// Creates and removes a probe file in `folder`: the one honest test that files can be
/// created there (permissions, read-only file systems, a full quota, running as root).
fn writable_folder(flag: &str, path: &Path, folder: &Path) -> Result<(), CliError> {
    match fs::metadata(folder) {
        Ok(m) if m.is_dir() => {}
        Ok(m) => {
            return Err(bad(
                flag,
                path,
                format!("`{}` is {}, not a folder", folder.display(), kind(&m)),
            ))
        }
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Err(bad(
                flag,
                path,
                format!("the folder `{}` does not exist", folder.display()),
            ))
        }
        Err(e) => return Err(bad(flag, path, describe(&e))),
    }
    let probe = probe_path(folder, std::process::id());
    match OpenOptions::new().write(true).create_new(true).open(&probe) {
        Ok(_) => {
            let _ = fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => Err(bad(
            flag,
            path,
            format!(
                "cannot create files in `{}`: {}",
                folder.display(),
                describe(&e)
            ),
        )),
    }
}

/// Whether two output paths, existing or not, name one destination.
fn same_destination(a: &Path, b: &Path) -> bool {
    if same_file(a, b) {
        return true;
    }
    let key = |p: &Path| {
        let dir = fs::canonicalize(parent_of(p)).ok()?;
        Some(dir.join(p.file_name()?))
    };
    match (key(a), key(b)) {
        (Some(x), Some(y)) => x == y,
        _ => a == b,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        crate::output::scratch::scratch_dir(&format!("paths-{name}"))
    }

    #[test]
    fn outputs_that_are_inputs_or_each_other_are_refused() {
        let d = scratch("same");
        let input = d.join("in.csv");
        fs::write(&input, "x").unwrap();
        let e = output_file("--json", &input, &[&input]).unwrap_err();
        assert!(e.to_string().contains("is the input"), "{e}");
        assert_eq!(e.exit_status(), 2);
        // Through another spelling of the same path.
        let other = d.join(".").join("in.csv");
        assert!(output_file("--json", &other, &[&input]).is_err());
        assert!(output_file("--json", &d.join("out.json"), &[&input]).is_ok());
        let a = d.join("a.json");
        assert!(distinct(&[("--out", &a), ("--json", &d.join(".").join("a.json"))]).is_err());
        assert!(distinct(&[("--out", &a), ("--json", Path::new("-"))]).is_ok());
        // The probe leaves nothing behind.
        assert_eq!(fs::read_dir(&d).unwrap().count(), 1);
        fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn special_files_are_refused_and_links_followed() {
        let d = scratch("special");
        let e = output_file("--out", Path::new("/dev/null"), &[]).unwrap_err();
        assert!(e.to_string().contains("character device"), "{e}");
        let real = d.join("real.csv");
        fs::write(&real, "x").unwrap();
        let link = d.join("link.csv");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        assert_eq!(
            replaced_file(&link).unwrap(),
            Some(fs::canonicalize(&real).unwrap())
        );
        let dangling = d.join("dangling.csv");
        std::os::unix::fs::symlink(d.join("nowhere"), &dangling).unwrap();
        assert!(output_file("--out", &dangling, &[]).is_err());
        assert!(input_file("LOG", Path::new("/dev/zero")).is_err());
        assert!(input_file("LOG", &d).is_err());
        fs::remove_dir_all(&d).unwrap();
    }
}
