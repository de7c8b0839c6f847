//! The README and `docs/` cannot drift from the code they describe: the README's fault
//! table is the firmware's enumeration (every code once, in order, with the firmware's own
//! words), the bring-up guide's fault table has every code, and every relative link in the
//! README and `docs/` names a file of the repository.

use firmware::FaultCode;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ is one level below the root")
        .to_path_buf()
}

fn read(relative: &str) -> String {
    std::fs::read_to_string(root().join(relative)).unwrap_or_else(|e| panic!("{relative}: {e}"))
}

/// The cells of a markdown table row, trimmed.
fn cells(row: &str) -> Vec<&str> {
    row.trim()
        .trim_matches('|')
        .split('|')
        .map(str::trim)
        .collect()
}

#[test]
fn the_readme_fault_table_is_the_firmwares_enumeration() {
    let readme = read("README.md");
    let start = readme
        .find("<!-- fault-table")
        .expect("the README marks its fault table");
    let end = readme[start..]
        .find("<!-- end fault-table -->")
        .expect("the fault table's end marker")
        + start;
    let rows: Vec<Vec<&str>> = readme[start..end]
        .lines()
        .filter(|l| l.starts_with('|'))
        .skip(2) // header and rule
        .map(cells)
        .collect();
    assert_eq!(rows.len(), FaultCode::ALL.len(), "one row per fault code");
    for (row, fault) in rows.iter().zip(FaultCode::ALL) {
        assert_eq!(row.len(), 3, "{row:?}");
        assert_eq!(row[0], fault.code().to_string(), "{row:?}");
        assert_eq!(row[1], fault.description(), "code {}", fault.code());
        assert!(!row[2].is_empty(), "code {}: what to check", fault.code());
    }
}

#[test]
fn the_bring_up_guide_covers_every_fault_code() {
    let guide = read("docs/bring-up.md");
    let section = &guide[guide
        .find("## 5. Fault codes")
        .expect("the guide's fault section")..];
    for fault in FaultCode::ALL {
        let row = format!("\n| {} |", fault.code());
        assert!(section.contains(&row), "code {} missing", fault.code());
    }
}

/// The relative link targets of a markdown text (external links and anchors aside).
fn relative_links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("](") {
        rest = &rest[i + 2..];
        let Some(end) = rest.find(')') else { break };
        let target = &rest[..end];
        let path = target.split('#').next().unwrap_or("");
        if !path.is_empty() && !path.contains("://") && !path.starts_with("mailto:") {
            out.push(path.to_string());
        }
    }
    out
}

#[test]
fn every_relative_link_in_the_readme_and_docs_names_a_file() {
    let mut files = vec![root().join("README.md")];
    for dir in ["docs", "docs/contracts"] {
        for e in std::fs::read_dir(root().join(dir)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "md") {
                files.push(p);
            }
        }
    }
    let mut checked = 0;
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        let base = file.parent().unwrap();
        for link in relative_links(&text) {
            assert!(
                base.join(&link).exists(),
                "{}: link `{link}` names no file",
                file.display()
            );
            checked += 1;
        }
    }
    assert!(checked >= 20, "only {checked} links found");
}
