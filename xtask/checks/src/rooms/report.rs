//! The check's text: the long files with their line counts, then each circle with its
//! files and the edges that tie it (`a.rs -> b.rs: Foo, bar`), paths relative to the
//! workspace root, and a closing summary line.

use super::findings::Findings;
use std::fmt::Write as _;
use std::path::Path;

/// The most names listed on one edge before `…and N more`.
const NAMES_SHOWN: usize = 8;

/// The report of `f`, paths shown relative to `root`, the limit named.
pub fn text(f: &Findings, root: &Path, limit: usize) -> String {
    let rel = |p: &Path| p.strip_prefix(root).unwrap_or(p).display().to_string();
    let mut t = String::new();
    if !f.long_files.is_empty() {
        let _ = writeln!(t, "files over {limit} lines:");
        for s in &f.long_files {
            let _ = writeln!(t, "  {:>5}  {}", s.lines, rel(&s.path));
        }
    }
    for (k, c) in f.circles.iter().enumerate() {
        let files: Vec<String> = c.files.iter().map(|p| rel(p)).collect();
        let _ = writeln!(
            t,
            "circle {} ({} files): {}",
            k + 1,
            files.len(),
            files.join(", ")
        );
        for e in &c.edges {
            let shown: Vec<&str> = e
                .names
                .iter()
                .take(NAMES_SHOWN)
                .map(String::as_str)
                .collect();
            let more = e.names.len().saturating_sub(NAMES_SHOWN);
            let tail = if more > 0 {
                format!(" …and {more} more")
            } else {
                String::new()
            };
            let _ = writeln!(
                t,
                "    {} -> {}: {}{tail}",
                rel(&e.from),
                rel(&e.to),
                shown.join(", ")
            );
        }
    }
    let _ = writeln!(
        t,
        "rooms: {} files read, {} over {limit} lines, {} import circle{}",
        f.files,
        f.long_files.len(),
        f.circles.len(),
        if f.circles.len() == 1 { "" } else { "s" }
    );
    t
}
