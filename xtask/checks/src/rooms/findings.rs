//! What the check finds in a set of crates: the files over the line limit, and the import
//! circles of each crate's file graph (the edges of every module tree grown from its roots,
//! joined on file paths), each with the edges that close it and the names that make them.

use super::discovery::{long_files, roots, rust_files, Sized};
use super::graph::circles;
use super::modules::load;
use anyhow::Result;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// One edge: `from` uses these items defined in `to`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Edge {
    /// The using file.
    pub from: PathBuf,
    /// The defining file.
    pub to: PathBuf,
    /// The items' names (`*` for a glob import).
    pub names: Vec<String>,
}

/// Files that reach each other through imports.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Circle {
    /// The files, sorted.
    pub files: Vec<PathBuf>,
    /// The edges between them.
    pub edges: Vec<Edge>,
}

/// The check's result over a set of crates.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Findings {
    /// Every `.rs` file read.
    pub files: usize,
    /// The files over the limit.
    pub long_files: Vec<Sized>,
    /// The circles, crate by crate.
    pub circles: Vec<Circle>,
}

impl Findings {
    /// Nothing to report.
    pub fn clean(&self) -> bool {
        self.long_files.is_empty() && self.circles.is_empty()
    }
}

/// Checks each crate whose `src/` folder is in `srcs`, and the length alone of the files
/// below each folder of `measured`, with files over `limit` lines long.
pub fn check(srcs: &[PathBuf], measured: &[PathBuf], limit: usize) -> Result<Findings> {
    let mut findings = Findings::default();
    for src in srcs {
        let files = rust_files(src)?;
        findings.files += files.len();
        findings.long_files.extend(long_files(&files, limit));
        findings.circles.extend(crate_circles(src)?);
    }
    for folder in measured {
        let files = rust_files(folder)?;
        findings.files += files.len();
        findings.long_files.extend(long_files(&files, limit));
    }
    Ok(findings)
}

/// The circles of the crate whose sources are in `src`.
fn crate_circles(src: &Path) -> Result<Vec<Circle>> {
    let mut nodes: BTreeMap<PathBuf, usize> = BTreeMap::new();
    let mut names: Vec<PathBuf> = Vec::new();
    let mut edges: BTreeMap<(usize, usize), BTreeSet<String>> = BTreeMap::new();
    for root in roots(src)? {
        let tree = load(&root)?;
        let mut node = |f: usize| {
            let path = &tree.files[f];
            *nodes.entry(path.clone()).or_insert_with(|| {
                names.push(path.clone());
                names.len() - 1
            })
        };
        for ((a, b), n) in tree.edges() {
            let (a, b) = (node(a), node(b));
            edges.entry((a, b)).or_default().extend(n);
        }
    }
    let mut next = vec![Vec::new(); names.len()];
    for &(a, b) in edges.keys() {
        next[a].push(b);
    }
    let mut out = Vec::new();
    for component in circles(names.len(), &next) {
        let inside: BTreeSet<usize> = component.iter().copied().collect();
        let mut files: Vec<PathBuf> = component.iter().map(|&i| names[i].clone()).collect();
        files.sort();
        let mut circle_edges: Vec<Edge> = edges
            .iter()
            .filter(|((a, b), _)| inside.contains(a) && inside.contains(b))
            .map(|((a, b), n)| Edge {
                from: names[*a].clone(),
                to: names[*b].clone(),
                names: n.iter().cloned().collect(),
            })
            .collect();
        circle_edges.sort_by(|x, y| (&x.from, &x.to).cmp(&(&y.from, &y.to)));
        out.push(Circle {
            files,
            edges: circle_edges,
        });
    }
    out.sort_by(|a, b| a.files.cmp(&b.files));
    Ok(out)
}
