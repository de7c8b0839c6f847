//! Writing output files atomically: the bytes go to a fresh temporary file in the target's
//! directory, which is flushed to disk and then renamed over the target. A reader (or a
//! user after a crash or an error) sees the old file or the complete new one, never a
//! half-written one; on any error or interruption the temporary file is removed.
//!
//! A symbolic link is followed: the file it names is replaced and the link stays. Anything
//! but a regular file (a FIFO, a device node, a socket, a folder) is never replaced.

use std::fs::{self, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};

/// Distinguishes temporary files of concurrent writers in one process (the sweep writes
/// from several threads); the process id distinguishes processes.
static COUNTER: AtomicU32 = AtomicU32::new(0);

/// Writes `bytes` to `path` atomically (temporary file in the same directory, then rename).
pub fn write(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_with(path, |w| w.write_all(bytes))
}

/// Writes to `path` atomically through `fill`, which receives a buffered writer; nothing
/// appears at `path` unless `fill` succeeds.
pub fn write_with<F>(path: &Path, fill: F) -> io::Result<()>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let target = super::paths::replaced_file(path)?.unwrap_or_else(|| path.to_path_buf());
    let tmp = temporary_path(&target)?;
    let _cleanup = super::interrupt::remove_on_interrupt(&tmp);
    let result = (|| {
        let file = OpenOptions::new().write(true).create_new(true).open(&tmp)?;
        let mut w = io::BufWriter::new(file);
        fill(&mut w)?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        fs::rename(&tmp, &target)
    })();
    if result.is_err() {
        // Best effort: the error that matters is the one being returned.
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Moves the finished file `from` onto `to` (same file system), with [`write`]'s rules for
/// what `to` may be: a symbolic link is followed, a special file is never replaced.
pub fn rename_into(from: &Path, to: &Path) -> io::Result<()> {
    let target = super::paths::replaced_file(to)?.unwrap_or_else(|| to.to_path_buf());
    fs::rename(from, target)
}

/// `dir/.name.tmp-<pid>-<n>`: same directory (rename must not cross file systems), hidden,
/// unique.
fn temporary_path(path: &Path) -> io::Result<PathBuf> {
    let name = path.file_name().ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("`{}` does not name a file", path.display()),
        )
    })?;
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".tmp-{}-{n}", std::process::id()));
    Ok(path.with_file_name(tmp_name))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch_dir(name: &str) -> PathBuf {
        crate::output::scratch_dir(&format!("atomic-{name}"))
    }

    #[test]
    fn writes_whole_file_and_leaves_no_temporary() {
        let d = scratch_dir("ok");
        let p = d.join("out.txt");
        write(&p, b"hello").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"hello");
        assert_eq!(fs::read_dir(&d).unwrap().count(), 1);
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn failed_fill_leaves_nothing_and_keeps_the_old_file() {
        let d = scratch_dir("fail");
        let p = d.join("out.txt");
        write(&p, b"old").unwrap();
        let r = write_with(&p, |w| {
            w.write_all(b"partial")?;
            Err(io::Error::other("simulated failure"))
        });
        assert!(r.is_err());
        assert_eq!(fs::read(&p).unwrap(), b"old");
        assert_eq!(fs::read_dir(&d).unwrap().count(), 1);
        let fresh = d.join("fresh.txt");
        assert!(write_with(&fresh, |_| Err(io::Error::other("x"))).is_err());
        assert!(!fresh.exists());
        fs::remove_dir_all(&d).unwrap();
    }
}
