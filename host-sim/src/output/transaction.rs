//! All of a command's outputs as one transaction: each is staged whole beside its place
//! (a hidden temporary file, or a hidden staging folder, written and synced), and
//! [`Outputs::commit`] moves them all into place together at the end, or none. This is
//! `tempfile`'s persist and a final rename for one file, made to hold for several files
//! and folders:
//!
//! - a failure while staging (a full disk on the last output, a bad value found late)
//!   removes what was staged: nothing of the command is written;
//! - the commit is a rename per output, with the replaced outputs kept aside until all are
//!   in place and put back if one rename fails;
//! - the signals are held off during the commit ([`super::interrupt::held`]): Ctrl-C at any
//!   point of the write phase leaves every output or none, and the message says which;
//! - standard output (tables, `--json -`) is written after the files are in place.
//!
//! An output file that is a symbolic link to a regular file replaces that file (the link
//! stays); a special file is never replaced ([`super::paths::replaced_file`]). An output
//! folder is replaced whole, so no file of an earlier run stays beside the new ones and no
//! link inside it is written through; what it may hold before is checked
//! ([`super::folder`]).

use super::error::CliError;
use super::file_kind::describe;
use super::folder;
use super::hooks;
use super::interrupt::{self, Guard};
use super::paths;
use super::stdout::{is_stdout, print_stdout};
use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Outputs moved into place so far in this process (the test hooks' `committed:N`).
static COMMITTED: AtomicUsize = AtomicUsize::new(0);
/// Distinguishes the kept-aside copies of replaced outputs within a process.
static ASIDE: AtomicUsize = AtomicUsize::new(0);

/// The outputs of one command, staged until [`commit`](Outputs::commit).
#[must_use = "nothing is written until the outputs are committed"]
#[derive(Default)]
pub struct Outputs {
    staged: Vec<Staged>,
    /// Folders created to hold a staging folder (the output folder's missing parents),
    /// outermost first; removed again unless committed.
    created: Vec<(PathBuf, Guard)>,
    stdout: String,
    committed: bool,
}

/// One staged output.
struct Staged {
    /// As the command line named it.
    shown: PathBuf,
    /// Where it goes: the path, or the regular file (folder) a link there names.
    place: PathBuf,
    temp: Temp,
    /// For a folder: what the folder it replaces may hold.
    owned: &'static [&'static str],
    _guard: Guard,
}

/// A staged file or folder, removed when dropped unless committed.
enum Temp {
    File(tempfile::TempPath),
    Folder(tempfile::TempDir),
}

impl Temp {
    fn path(&self) -> &Path {
        match self {
            Temp::File(t) => t,
            Temp::Folder(t) => t.path(),
        }
    }

    fn keep(&mut self) {
        match self {
            Temp::File(t) => t.disable_cleanup(true),
            Temp::Folder(t) => t.disable_cleanup(true),
        }
    }
}

/// A folder being staged: the files of an output folder are written here, by name.
pub struct StagedFolder {
    shown: PathBuf,
    dir: PathBuf,
}

impl StagedFolder {
    /// Where the file `name` is staged (for writers that take a path).
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// The file `name` as the user will see it, for messages.
    pub fn shown(&self, name: &str) -> PathBuf {
        self.shown.join(name)
    }

    /// Writes the file `name`.
    pub fn file(&self, name: &str, bytes: &[u8]) -> Result<(), CliError> {
        self.file_with(name, |w| w.write_all(bytes))
    }

    /// Writes the file `name` through `fill`.
    pub fn file_with<F>(&self, name: &str, fill: F) -> Result<(), CliError>
    where
        F: FnOnce(&mut dyn Write) -> io::Result<()>,
    {
        let write = || {
            // New (never through a link or over a file) in a folder only eha writes.
            let file = fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(self.path(name))?;
            let mut w = BufWriter::new(file);
            fill(&mut w)?;
            w.into_inner().map_err(|e| e.into_error())?.sync_all()
        };
        write().map_err(|source| CliError::Write {
            file: self.shown(name),
            source,
        })
    }
}

/// The folder holding `path` (`.` for a bare name).
fn parent_of(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// `.NAME.` for the hidden names staged beside `place`.
fn hidden_prefix(place: &Path) -> String {
    let name = place
        .file_name()
        .map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
    format!(".{name}.")
}

/// The suffix of a file staged beside its place (`.NAME.RANDOM.eha-tmp`).
const STAGED_FILE_SUFFIX: &str = ".eha-tmp";

/// Removes the files staged for `place` that a process killed before its commit left
/// beside it (a killed process cannot remove them itself, [`interrupt`]).
pub fn remove_staged_files(place: &Path) {
    let prefix = hidden_prefix(place);
    let Ok(entries) = fs::read_dir(parent_of(place)) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if name.starts_with(&prefix) && name.ends_with(STAGED_FILE_SUFFIX) {
            let _ = fs::remove_file(entry.path());
        }
    }
}

impl Outputs {
    /// No outputs yet.
    pub fn new() -> Outputs {
        Outputs::default()
    }

    /// Stages the file `path` (given by `flag`) holding `bytes`.
    pub fn file(&mut self, flag: &str, path: &Path, bytes: &[u8]) -> Result<(), CliError> {
        self.file_with(flag, path, |w| w.write_all(bytes))
    }

    /// Stages the file `path` (given by `flag`), written through `fill`.
    pub fn file_with<F>(&mut self, flag: &str, path: &Path, fill: F) -> Result<(), CliError>
    where
        F: FnOnce(&mut dyn Write) -> io::Result<()>,
    {
        let failed = |source| CliError::Write {
            file: path.to_path_buf(),
            source,
        };
        let existing = paths::replaced_file(path).map_err(|e| bad(flag, path, &e))?;
        let place = existing.clone().unwrap_or_else(|| path.to_path_buf());
        let prefix = hidden_prefix(&place);
        let (file, guard) = interrupt::held(|pending| {
            let file =
                staging_builder(&prefix, STAGED_FILE_SUFFIX).tempfile_in(parent_of(&place))?;
            let guard = pending.register(file.path());
            Ok((file, guard))
        })
        .map_err(failed)?;
        let (file, temp) = file.into_parts();
        let write = || {
            let mut w = BufWriter::new(file);
            fill(&mut w)?;
            let file = w.into_inner().map_err(|e| e.into_error())?;
            let n = hooks::staged()?;
            if let Some(old) = &existing {
                // A replaced file keeps its permissions.
                fs::set_permissions(&temp, fs::metadata(old)?.permissions())?;
            }
            file.sync_all()?;
            Ok(n)
        };
        let n = write().map_err(failed)?;
        self.push(n, path, place, Temp::File(temp), &[], guard);
        Ok(())
    }

    /// Stages `value` as pretty-printed JSON in the file `path`, or for `-` on standard
    /// output.
    pub fn json(
        &mut self,
        flag: &str,
        path: &Path,
        value: &serde_json::Value,
    ) -> Result<(), CliError> {
        let mut text =
            serde_json::to_string_pretty(value).map_err(|e| CliError::Failed(e.to_string()))?;
        text.push('\n');
        if is_stdout(path) {
            self.print(&text);
            Ok(())
        } else {
            self.file(flag, path, text.as_bytes())
        }
    }

    /// Adds `text` to what is printed on standard output once the files are in place.
    pub fn print(&mut self, text: &str) {
        self.stdout.push_str(text);
    }

    /// Stages the folder `path` (given by `flag`), its files written by `fill` into a new
    /// staging folder beside it. The folder replaces an existing one whole, which may hold
    /// only files `owned` names ([`folder::problem`], checked before the run by
    /// [`paths::check`] and again here).
    pub fn folder<F>(
        &mut self,
        flag: &str,
        path: &Path,
        owned: &'static [&'static str],
        fill: F,
    ) -> Result<(), CliError>
    where
        F: FnOnce(&StagedFolder) -> Result<(), CliError>,
    {
        let failed = |source| CliError::Write {
            file: path.to_path_buf(),
            source,
        };
        let place = folder_place(path).map_err(failed)?;
        if place.exists() {
            if let Some(why) = folder::problem(&place, owned, &[]) {
                return Err(CliError::BadInput(format!(
                    "{flag} `{}`: {why}",
                    path.display()
                )));
            }
        }
        let parent = parent_of(&place).to_path_buf();
        self.create_parents(&parent).map_err(failed)?;
        let (dir, guard) = interrupt::held(|pending| {
            let dir = tempfile::Builder::new()
                .prefix(&hidden_prefix(&place))
                .suffix(".eha-staging")
                .tempdir_in(&parent)?;
            let guard = pending.register(dir.path());
            Ok((dir, guard))
        })
        .map_err(failed)?;
        let staged = StagedFolder {
            shown: path.to_path_buf(),
            dir: dir.path().to_path_buf(),
        };
        fill(&staged)?;
        let settle = || {
            let n = hooks::staged()?;
            sync_folder(dir.path())?;
            Ok(n)
        };
        let n = settle().map_err(failed)?;
        self.push(n, path, place, Temp::Folder(dir), owned, guard);
        Ok(())
    }

    /// Keeps the `n`-th output staged in this process.
    fn push(
        &mut self,
        n: usize,
        shown: &Path,
        place: PathBuf,
        temp: Temp,
        owned: &'static [&'static str],
        guard: Guard,
    ) {
        self.staged.push(Staged {
            shown: shown.to_path_buf(),
            place,
            temp,
            owned,
            _guard: guard,
        });
        hooks::reached(&format!("staged:{n}"), false);
    }

    /// Creates the missing folders of `dir`, outermost first, each registered for removal.
    fn create_parents(&mut self, dir: &Path) -> io::Result<()> {
        let mut missing = Vec::new();
        let mut d = dir;
        while !d.as_os_str().is_empty() && fs::symlink_metadata(d).is_err() {
            missing.push(d.to_path_buf());
            d = parent_of(d);
            if d == Path::new(".") {
                break;
            }
        }
        for d in missing.into_iter().rev() {
            let guard = interrupt::held(|pending| {
                fs::create_dir(&d)?;
                Ok::<_, io::Error>(pending.register(&d))
            })?;
            self.created.push((d, guard));
        }
        Ok(())
    }

    /// Moves every staged output into place, the signals held off, then writes standard
    /// output. If any move fails, the ones made are undone: nothing of the command is
    /// written.
    pub fn commit(mut self) -> Result<(), CliError> {
        let staged = std::mem::take(&mut self.staged);
        let created: Vec<PathBuf> = self.created.iter().map(|(d, _)| d.clone()).collect();
        let moved = interrupt::held(|pending| {
            // Everything checked before anything moves.
            for s in &staged {
                s.still_replaceable()?;
            }
            let mut aside = Vec::new();
            for s in &staged {
                match s.move_into_place() {
                    Ok(a) => aside.push(a),
                    Err(e) => {
                        for (s, a) in staged.iter().zip(aside).rev() {
                            s.undo(a);
                        }
                        return Err(e);
                    }
                }
                let n = COMMITTED.fetch_add(1, Ordering::SeqCst) + 1;
                hooks::reached(&format!("committed:{n}"), true);
            }
            for (s, a) in staged.iter().zip(aside) {
                s.discard(a);
                pending.forget(s.temp.path());
            }
            for d in &created {
                pending.forget(d);
            }
            pending.committed();
            Ok(())
        });
        hooks::released();
        interrupt::wait_if_interrupted();
        moved?;
        self.committed = true;
        let mut staged = staged;
        for s in &mut staged {
            s.temp.keep();
        }
        for place in staged.iter().map(|s| parent_of(&s.place)) {
            // The renames made durable; best effort (not every file system syncs folders).
            let _ = fs::File::open(place).and_then(|d| d.sync_all());
        }
        hooks::reached("done", false);
        if self.stdout.is_empty() {
            return Ok(());
        }
        print_stdout(&self.stdout).map_err(|e| match e {
            CliError::Stdout { source, .. } => CliError::Stdout {
                source,
                files_written: staged.len(),
            },
            e => e,
        })
    }
}

impl Drop for Outputs {
    fn drop(&mut self) {
        // Uncommitted: the staged outputs remove themselves; the folders made for them go
        // too, innermost first, if nothing else came into them.
        self.staged.clear();
        if !self.committed {
            for (d, _) in self.created.iter().rev() {
                let _ = fs::remove_dir(d);
            }
        }
    }
}

/// What was done to an output's place when it was moved in: the replaced output's copy
/// kept aside, and whether it was moved (not linked) there.
struct Aside {
    copy: Option<PathBuf>,
    moved: bool,
}

impl Staged {
    fn is_folder(&self) -> bool {
        matches!(self.temp, Temp::Folder(_))
    }

    fn failed(&self, source: io::Error) -> CliError {
        CliError::Write {
            file: self.shown.clone(),
            source,
        }
    }

    /// Checks that the place is still what was staged for: the same file (not replaced by
    /// a link or a special file since), or a folder holding only the command's files.
    fn still_replaceable(&self) -> Result<(), CliError> {
        let changed = |why: String| {
            CliError::BadInput(format!(
                "`{}` changed while eha ran: {why}",
                self.shown.display()
            ))
        };
        if self.is_folder() {
            let place = folder_place(&self.shown).map_err(|e| self.failed(e))?;
            if place != self.place {
                return Err(changed(format!("it now names `{}`", place.display())));
            }
            if let Some(why) = place
                .exists()
                .then(|| folder::problem(&place, self.owned, &[]))
                .flatten()
            {
                return Err(changed(why));
            }
        } else {
            let place = paths::replaced_file(&self.shown)
                .map_err(|e| changed(describe(&e)))?
                .unwrap_or_else(|| self.shown.clone());
            if place != self.place {
                return Err(changed(format!("it now names `{}`", place.display())));
            }
        }
        Ok(())
    }

    /// Moves the staged output into place, the output it replaces kept aside.
    fn move_into_place(&self) -> Result<Aside, CliError> {
        let exists = fs::symlink_metadata(&self.place).is_ok();
        let copy = exists.then(|| {
            let n = ASIDE.fetch_add(1, Ordering::SeqCst);
            parent_of(&self.place).join(format!(
                "{}eha-old-{}-{n}",
                hidden_prefix(&self.place),
                std::process::id()
            ))
        });
        let mut moved = false;
        if let Some(copy) = &copy {
            // A file stays in place while its copy is kept (a hard link); a folder, or a
            // file on a file system without links, is moved aside.
            if self.is_folder() || fs::hard_link(&self.place, copy).is_err() {
                fs::rename(&self.place, copy).map_err(|e| self.failed(e))?;
                moved = true;
            }
        }
        if let Err(e) = fs::rename(self.temp.path(), &self.place) {
            if let (Some(copy), true) = (&copy, moved) {
                let _ = fs::rename(copy, &self.place);
            } else if let Some(copy) = &copy {
                let _ = fs::remove_file(copy);
            }
            return Err(self.failed(e));
        }
        Ok(Aside { copy, moved })
    }

    /// Puts back what the output replaced (or removes the output where nothing was).
    fn undo(&self, aside: Aside) {
        let _ = if self.is_folder() {
            fs::remove_dir_all(&self.place)
        } else if aside.copy.is_none() || aside.moved {
            fs::remove_file(&self.place)
        } else {
            Ok(())
        };
        if let Some(copy) = aside.copy {
            let _ = fs::rename(copy, &self.place);
        }
    }

    /// Drops the replaced output's copy once everything is in place.
    fn discard(&self, aside: Aside) {
        if let Some(copy) = aside.copy {
            let _ = if self.is_folder() {
                fs::remove_dir_all(copy)
            } else {
                fs::remove_file(copy)
            };
        }
    }
}

/// Where an output folder goes: `path`, or the folder a symbolic link there names.
fn folder_place(path: &Path) -> io::Result<PathBuf> {
    match fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => fs::canonicalize(path),
        Ok(_) => Ok(path.to_path_buf()),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(path.to_path_buf()),
        Err(e) => Err(e),
    }
}

/// Syncs every file of a staged folder and the folder itself.
fn sync_folder(dir: &Path) -> io::Result<()> {
    for entry in fs::read_dir(dir)? {
        let path = entry?.path();
        if fs::symlink_metadata(&path)?.is_file() {
            fs::File::open(&path)?.sync_all()?;
        }
    }
    // Not every file system can sync a folder; the files are what matters.
    let _ = fs::File::open(dir).and_then(|d| d.sync_all());
    Ok(())
}

/// A builder of hidden files named `prefix…suffix`, readable as a new output file is (read and
/// write for all, less the umask; tempfile's own default is the owner only).
fn staging_builder<'a>(prefix: &'a str, suffix: &'static str) -> tempfile::Builder<'a, 'static> {
    let mut b = tempfile::Builder::new();
    b.prefix(prefix).suffix(suffix);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(fs::Permissions::from_mode(0o666));
    }
    b
}

fn bad(flag: &str, path: &Path, e: &io::Error) -> CliError {
    paths::bad(flag, path, describe(e))
}
