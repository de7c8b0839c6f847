//! What a path names, in the words of eha's errors: the kind of file system object
//! ([`kind`]), whether it can be read as an input ([`input_problem`]: a regular file or a
//! pipe), whether two paths are one file ([`same_file`]), and an I/O error without Rust's
//! `(os error N)` suffix ([`describe`]). Every reader of a file (bench logs, rig files,
//! compensation tables) and every check of [`super::paths`] says it the same way.

use std::fs::{self, Metadata};
use std::io;
use std::path::Path;

/// What kind of file system object a path is, in words.
pub fn kind(m: &Metadata) -> &'static str {
    let t = m.file_type();
    if t.is_dir() {
        return "a folder";
    }
    if t.is_symlink() {
        return "a symbolic link";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_file() {
        "a regular file"
    } else {
        "a special file"
    }
}

fn is_fifo(m: &Metadata) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        m.file_type().is_fifo()
    }
    #[cfg(not(unix))]
    {
        let _ = m;
        false
    }
}

/// What makes `path` no readable input file, if anything.
pub fn input_problem(path: &Path) -> Option<String> {
    match fs::metadata(path) {
        Err(e) => Some(describe(&e)),
        Ok(m) if m.is_file() || is_fifo(&m) => None,
        Ok(m) => Some(format!("is {}, not a file eha can read", kind(&m))),
    }
}

/// Whether two existing paths are the same file (hard links and symbolic links included).
pub fn same_file(a: &Path, b: &Path) -> bool {
    match (fs::metadata(a), fs::metadata(b)) {
        (Ok(ma), Ok(mb)) => {
            #[cfg(unix)]
            {
                use std::os::unix::fs::MetadataExt;
                ma.dev() == mb.dev() && ma.ino() == mb.ino()
            }
            #[cfg(not(unix))]
            {
                let _ = (ma, mb);
                fs::canonicalize(a).ok() == fs::canonicalize(b).ok()
            }
        }
        _ => false,
    }
}

/// An I/O error in words, without Rust's `(os error N)` suffix; eha's own reasons (carried
/// as `InvalidInput`) as written.
pub fn describe(e: &io::Error) -> String {
    match e.kind() {
        io::ErrorKind::NotFound => "does not exist".into(),
        io::ErrorKind::PermissionDenied => "permission denied".into(),
        io::ErrorKind::NotADirectory => "a part of the path is not a folder".into(),
        io::ErrorKind::InvalidInput => e.to_string(),
        _ => {
            let s = e.to_string();
            let s = s.find(" (os error").map_or(s.as_str(), |i| &s[..i]);
            let mut c = s.chars();
            c.next()
                .map(|f| f.to_lowercase().chain(c).collect())
                .unwrap_or_default()
        }
    }
}
