//! What an output folder may hold when eha replaces it. A command's output folder (`eha demo
//! --out`, `eha diagnose --report`) is one output, replaced whole when the command commits
//! ([`super::transaction`]): nothing of an earlier run is left beside the new files, and
//! nothing is written through a link in it. So that replacing it loses nothing of the
//! user's, an existing folder may hold only regular files of the names the command writes
//! there (its `owned` patterns, `*` standing for any text); a symbolic link, a special
//! file, a folder, another file, or an input of the command in it is refused, named,
//! before any work.

use super::file_kind::{describe, kind, same_file};
use std::fs;
use std::path::Path;

/// Whether the file `name` is one a command owning `owned` writes into its folder.
pub fn owns(owned: &[&str], name: &str) -> bool {
    owned
        .iter()
        .any(|p| glob::Pattern::new(p).is_ok_and(|p| p.matches(name)))
}

/// The patterns in a message: the first few, then an ellipsis.
fn listed(owned: &[&str]) -> String {
    let mut names: Vec<&str> = owned.iter().take(6).copied().collect();
    if owned.len() > names.len() {
        names.push("…");
    }
    names.join(", ")
}

/// What makes the existing folder `dir` no folder eha may replace with one holding the
/// files `owned` names, if anything: an entry that is not a regular file of such a name,
/// or that is one of `inputs`.
pub fn problem(dir: &Path, owned: &[&str], inputs: &[&Path]) -> Option<String> {
    let entries = match fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) => return Some(format!("cannot be listed: {}", describe(&e))),
    };
    let replaced = "eha replaces its output folder whole";
    for entry in entries {
        let entry = match entry {
            Ok(e) => e,
            Err(e) => return Some(format!("cannot be listed: {}", describe(&e))),
        };
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        let meta = match fs::symlink_metadata(&path) {
            Ok(m) => m,
            Err(e) => return Some(format!("`{name}` in it: {}", describe(&e))),
        };
        if meta.file_type().is_symlink() {
            let to = fs::read_link(&path)
                .map(|t| format!(" to `{}`", t.display()))
                .unwrap_or_default();
            return Some(format!(
                "holds `{name}`, a symbolic link{to}; {replaced} and never writes through, or \
                 removes, a link in it: remove the link or name another folder"
            ));
        }
        if let Some(input) = inputs.iter().find(|i| same_file(&path, i)) {
            return Some(format!(
                "holds the input `{}`; {replaced}: name another folder",
                input.display()
            ));
        }
        if !meta.is_file() {
            return Some(format!(
                "holds `{name}`, {}; {replaced} and never replaces special files or folders in \
                 it: move it or name another folder",
                kind(&meta)
            ));
        }
        if !owns(owned, &name) {
            return Some(format!(
                "holds `{name}`, which is none of the files eha writes there ({}); {replaced}: \
                 move the file or name another folder",
                listed(owned)
            ));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_name_the_files_a_command_writes() {
        let owned = ["report.md", "trace_*.svg", "trace_*.png"];
        assert!(owns(&owned, "report.md"));
        assert!(owns(&owned, "trace_p_pa.svg"));
        assert!(!owns(&owned, "trace_p_pa.csv"));
        assert!(!owns(&owned, "notes.md"));
    }

    #[cfg(unix)]
    #[test]
    fn links_special_files_and_foreign_files_are_named() {
        let d = crate::output::scratch::scratch_dir("folder-problem");
        let owned = ["report.md", "*.svg"];
        assert_eq!(problem(&d, &owned, &[]), None);
        fs::write(d.join("report.md"), "old").unwrap();
        assert_eq!(problem(&d, &owned, &[]), None);
        let input = d.join("in.csv");
        fs::write(&input, "x").unwrap();
        let e = problem(&d, &owned, &[&input]).unwrap();
        assert!(e.contains("the input"), "{e}");
        fs::remove_file(&input).unwrap();
        std::os::unix::fs::symlink("/etc/hostname", d.join("a.svg")).unwrap();
        let e = problem(&d, &owned, &[]).unwrap();
        assert!(
            e.contains("`a.svg`, a symbolic link to `/etc/hostname`"),
            "{e}"
        );
        fs::remove_file(d.join("a.svg")).unwrap();
        fs::write(d.join("notes.txt"), "mine").unwrap();
        let e = problem(&d, &owned, &[]).unwrap();
        assert!(
            e.contains("`notes.txt`") && e.contains("report.md, *.svg"),
            "{e}"
        );
        fs::remove_dir_all(&d).unwrap();
    }
}
