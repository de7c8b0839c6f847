//! Name resolution over a [`Tree`]: a path as Rust 2018 reads it (`crate::`, `super::`,
//! `self::`, or a name in scope: an item, a child module, an import, a glob), followed
//! through imports and re-exports to the file that defines the item; and the edges "file A
//! uses an item defined in file B" with the names that make each. A `mod x;` line is no
//! edge; a `pub use child::X` is an edge to the file defining `X`; an import of a
//! re-exported name is an edge to the defining file, not to the re-exporting one.

use super::modules::{flatten_use, is_test, Tree, UseEntry};
use std::collections::{BTreeMap, BTreeSet};
use syn::visit::Visit;

/// Where a path leads.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Target {
    /// An item, defined in this file (index in [`Tree::files`]) under this name.
    Item { file: usize, name: String },
    /// A module (index in [`Tree::modules`]).
    Module(usize),
}

/// How deep imports are followed before giving up (a glob cycle, a misparse).
const MAX_DEPTH: u32 = 32;

/// File-level edges: (from, to) file indices and the item names that make the edge.
pub type Edges = BTreeMap<(usize, usize), BTreeSet<String>>;

impl Tree {
    /// What `name` means inside module `m`.
    fn lookup(&self, m: usize, name: &str, depth: u32) -> Option<Target> {
        if depth > MAX_DEPTH {
            return None;
        }
        let module = &self.modules[m];
        if module.defs.contains(name) {
            return Some(Target::Item {
                file: module.file,
                name: name.to_string(),
            });
        }
        if let Some(&child) = module.children.get(name) {
            return Some(Target::Module(child));
        }
        for u in &module.uses {
            if !u.glob && u.binding.as_deref() == Some(name) {
                if let Some(t) = self.resolve(m, &u.segments, depth + 1) {
                    return Some(t);
                }
            }
        }
        for u in module.uses.iter().filter(|u| u.glob) {
            if let Some(Target::Module(g)) = self.resolve(m, &u.segments, depth + 1) {
                if g != m {
                    if let Some(t) = self.lookup(g, name, depth + 1) {
                        return Some(t);
                    }
                }
            }
        }
        None
    }

    /// What the path `segments`, written in module `from`, leads to; `None` for paths out of
    /// the crate (`std::`, other crates) and names not found.
    pub fn resolve(&self, from: usize, segments: &[String], depth: u32) -> Option<Target> {
        let (first, rest) = segments.split_first()?;
        let mut current = match first.as_str() {
            "crate" => Target::Module(0),
            "self" => Target::Module(from),
            "super" => Target::Module(self.modules[from].parent?),
            name => self.lookup(from, name, depth)?,
        };
        for seg in rest {
            current = match current {
                Target::Module(m) if seg == "super" => Target::Module(self.modules[m].parent?),
                Target::Module(m) if seg == "self" => Target::Module(m),
                Target::Module(m) => self.lookup(m, seg, depth)?,
                // An enum's variant, an associated item: the item is what is used.
                item @ Target::Item { .. } => return Some(item),
            };
        }
        Some(current)
    }

    /// Every edge between files of this tree.
    pub fn edges(&self) -> Edges {
        let mut edges = Edges::new();
        for (id, module) in self.modules.iter().enumerate() {
            let mut paths = Paths::default();
            for item in &module.body {
                paths.visit_item(item);
            }
            let mut add = |target: Option<Target>, glob_name: Option<&str>| {
                let (to, name) = match target {
                    Some(Target::Item { file, name }) => (file, name),
                    Some(Target::Module(m)) if glob_name.is_some() => {
                        (self.modules[m].file, glob_name.unwrap_or("*").to_string())
                    }
                    _ => return,
                };
                if to != module.file {
                    edges.entry((module.file, to)).or_default().insert(name);
                }
            };
            for u in module.uses.iter().chain(&paths.uses) {
                add(self.resolve(id, &u.segments, 0), u.glob.then_some("*"));
            }
            for p in &paths.paths {
                add(self.resolve(id, p, 0), None);
            }
        }
        edges
    }
}

/// The paths and imports written in items' bodies (types, expressions, patterns, trait
/// bounds, macro paths and macro arguments that parse as expressions), test-only items left
/// out.
#[derive(Default)]
struct Paths {
    paths: Vec<Vec<String>>,
    uses: Vec<UseEntry>,
}

impl<'ast> Visit<'ast> for Paths {
    fn visit_path(&mut self, p: &'ast syn::Path) {
        self.paths
            .push(p.segments.iter().map(|s| s.ident.to_string()).collect());
        syn::visit::visit_path(self, p);
    }

    fn visit_item(&mut self, i: &'ast syn::Item) {
        if !is_test(super::modules::item_attrs(i)) {
            syn::visit::visit_item(self, i);
        }
    }

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        flatten_use(&u.tree, &mut Vec::new(), &mut self.uses);
    }

    fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
        if !is_test(&f.attrs) {
            syn::visit::visit_impl_item_fn(self, f);
        }
    }

    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        syn::visit::visit_macro(self, m);
        let args = m.parse_body_with(
            syn::punctuated::Punctuated::<syn::Expr, syn::Token![,]>::parse_terminated,
        );
        if let Ok(args) = args {
            for e in &args {
                self.visit_expr(e);
            }
        }
    }
}
