//! Parsing: one crate root's module tree, read with `syn`. Each `mod x;` is followed to
//! its file (`x.rs` or `x/mod.rs` beside a root or `mod.rs`, below `name/` beside a
//! `name.rs`, or its `#[path]`); an inline `mod x { }` is a module of the file it is
//! written in. Per module: the names it defines, its `use` bindings and globs, and the
//! items whose bodies may name other items. Whatever `#[cfg(test)]` guards (a test module
//! inline or in its own file, a test-only item or import) is left out: test code may reach
//! anywhere.

use anyhow::{Context, Result};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// One `use` leaf: the name it binds (none for a glob or `as _`) and its path as written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UseEntry {
    /// The name this import binds in its module.
    pub binding: Option<String>,
    /// The path's segments (`crate`, `super`, `self` kept as written).
    pub segments: Vec<String>,
    /// `use path::*`.
    pub glob: bool,
}

/// A module: a file, or an inline `mod x { }` within one.
pub struct Module {
    /// Its path from the crate root (`crate::a::b`).
    pub path: String,
    /// Index of its file in [`Tree::files`].
    pub file: usize,
    /// The module it is declared in.
    pub parent: Option<usize>,
    /// Its child modules by name.
    pub children: BTreeMap<String, usize>,
    /// The names of the items it defines (functions, types, traits, constants, statics).
    pub defs: BTreeSet<String>,
    /// Its imports, including those inside function bodies.
    pub uses: Vec<UseEntry>,
    /// The items whose bodies are searched for paths (everything but `mod` and `use`).
    pub body: Vec<syn::Item>,
}

/// One crate root's modules and the files they live in.
#[derive(Default)]
pub struct Tree {
    /// The files, in the order they were reached.
    pub files: Vec<PathBuf>,
    /// The modules; the root is index 0.
    pub modules: Vec<Module>,
}

/// Reads the module tree grown from `root` (a `lib.rs`, `main.rs` or `bin/` file).
pub fn load(root: &Path) -> Result<Tree> {
    let mut tree = Tree::default();
    let dir = root.parent().unwrap_or(Path::new(".")).to_path_buf();
    tree.add_file(root, "crate".to_string(), None, dir)?;
    Ok(tree)
}

/// Whether the attributes make the item test-only: `#[cfg(test)]` or `#[cfg(all(.., test, ..))]`.
pub fn is_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        if !a.path().is_ident("cfg") {
            return false;
        }
        let Ok(list) = a.meta.require_list() else {
            return false;
        };
        let text: String = list
            .tokens
            .to_string()
            .chars()
            .filter(|c| !c.is_whitespace())
            .collect();
        text == "test"
            || (text.starts_with("all(")
                && text[4..text.len().saturating_sub(1)]
                    .split(',')
                    .any(|part| part == "test"))
    })
}

/// The flattened leaves of a `use` tree, `prefix` being the path above it.
pub fn flatten_use(tree: &syn::UseTree, prefix: &mut Vec<String>, out: &mut Vec<UseEntry>) {
    match tree {
        syn::UseTree::Path(p) => {
            prefix.push(p.ident.to_string());
            flatten_use(&p.tree, prefix, out);
            prefix.pop();
        }
        syn::UseTree::Name(n) => {
            let name = n.ident.to_string();
            let (binding, segments) = if name == "self" {
                (prefix.last().cloned(), prefix.clone())
            } else {
                let mut s = prefix.clone();
                s.push(name.clone());
                (Some(name), s)
            };
            out.push(UseEntry {
                binding,
                segments,
                glob: false,
            });
        }
        syn::UseTree::Rename(r) => {
            let name = r.ident.to_string();
            let mut segments = prefix.clone();
            if name != "self" {
                segments.push(name);
            }
            let alias = r.rename.to_string();
            out.push(UseEntry {
                binding: (alias != "_").then_some(alias),
                segments,
                glob: false,
            });
        }
        syn::UseTree::Glob(_) => out.push(UseEntry {
            binding: None,
            segments: prefix.clone(),
            glob: true,
        }),
        syn::UseTree::Group(g) => {
            for t in &g.items {
                flatten_use(t, prefix, out);
            }
        }
    }
}

impl Tree {
    /// Parses `path` as module `mod_path`; `dir` is where its `mod x;` files are looked for.
    fn add_file(
        &mut self,
        path: &Path,
        mod_path: String,
        parent: Option<usize>,
        dir: PathBuf,
    ) -> Result<usize> {
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        let file = syn::parse_file(&text).with_context(|| format!("parsing {}", path.display()))?;
        self.files.push(path.to_path_buf());
        let file_index = self.files.len() - 1;
        let id = self.new_module(mod_path, file_index, parent);
        self.add_items(id, file.items, path, &dir, false)?;
        Ok(id)
    }

    fn new_module(&mut self, path: String, file: usize, parent: Option<usize>) -> usize {
        self.modules.push(Module {
            path,
            file,
            parent,
            children: BTreeMap::new(),
            defs: BTreeSet::new(),
            uses: Vec::new(),
            body: Vec::new(),
        });
        self.modules.len() - 1
    }

    /// Records `items` in module `id`, written in `file`; `dir` holds its children's files,
    /// `inline` says whether `id` is an inline module (for `#[path]`).
    fn add_items(
        &mut self,
        id: usize,
        items: Vec<syn::Item>,
        file: &Path,
        dir: &Path,
        inline: bool,
    ) -> Result<()> {
        for item in items {
            if is_test(item_attrs(&item)) {
                continue;
            }
            match item {
                syn::Item::Mod(m) => self.add_mod(id, m, file, dir, inline)?,
                syn::Item::Use(u) => {
                    flatten_use(&u.tree, &mut Vec::new(), &mut self.modules[id].uses);
                }
                syn::Item::ExternCrate(_) => {}
                other => {
                    let m = &mut self.modules[id];
                    for name in defined_names(&other) {
                        m.defs.insert(name);
                    }
                    m.body.push(other);
                }
            }
        }
        Ok(())
    }

    fn add_mod(
        &mut self,
        parent: usize,
        m: syn::ItemMod,
        file: &Path,
        dir: &Path,
        inline: bool,
    ) -> Result<()> {
        let name = m.ident.to_string();
        let mod_path = format!("{}::{name}", self.modules[parent].path);
        let child = if let Some((_, items)) = m.content {
            let f = self.modules[parent].file;
            let child = self.new_module(mod_path, f, Some(parent));
            self.add_items(child, items, file, &dir.join(&name), true)?;
            child
        } else {
            let explicit = path_attr(&m.attrs).map(|p| {
                let base = if inline {
                    dir.to_path_buf()
                } else {
                    file.parent().unwrap_or(Path::new(".")).to_path_buf()
                };
                base.join(p)
            });
            let candidates = match &explicit {
                Some(p) => vec![p.clone()],
                None => vec![
                    dir.join(format!("{name}.rs")),
                    dir.join(&name).join("mod.rs"),
                ],
            };
            let Some(path) = candidates.into_iter().find(|p| p.is_file()) else {
                anyhow::bail!(
                    "{}: `mod {name};` has no file ({}.rs or {name}/mod.rs in {})",
                    file.display(),
                    name,
                    dir.display()
                );
            };
            let child_dir = if path.file_name().is_some_and(|f| f == "mod.rs") {
                path.parent().unwrap_or(Path::new(".")).to_path_buf()
            } else {
                let stem = path.file_stem().unwrap_or_default().to_os_string();
                path.parent().unwrap_or(Path::new(".")).join(stem)
            };
            self.add_file(&path, mod_path, Some(parent), child_dir)?
        };
        self.modules[parent].children.insert(name, child);
        Ok(())
    }
}

/// The attributes of an item.
pub fn item_attrs(item: &syn::Item) -> &[syn::Attribute] {
    use syn::Item::*;
    match item {
        Const(i) => &i.attrs,
        Enum(i) => &i.attrs,
        ExternCrate(i) => &i.attrs,
        Fn(i) => &i.attrs,
        ForeignMod(i) => &i.attrs,
        Impl(i) => &i.attrs,
        Macro(i) => &i.attrs,
        Mod(i) => &i.attrs,
        Static(i) => &i.attrs,
        Struct(i) => &i.attrs,
        Trait(i) => &i.attrs,
        TraitAlias(i) => &i.attrs,
        Type(i) => &i.attrs,
        Union(i) => &i.attrs,
        Use(i) => &i.attrs,
        _ => &[],
    }
}

/// The names an item defines in its module's namespace.
fn defined_names(item: &syn::Item) -> Vec<String> {
    use syn::Item::*;
    let one = |i: &syn::Ident| vec![i.to_string()];
    match item {
        Const(i) => one(&i.ident),
        Enum(i) => one(&i.ident),
        Fn(i) => one(&i.sig.ident),
        Static(i) => one(&i.ident),
        Struct(i) => one(&i.ident),
        Trait(i) => one(&i.ident),
        TraitAlias(i) => one(&i.ident),
        Type(i) => one(&i.ident),
        Union(i) => one(&i.ident),
        ForeignMod(f) => f
            .items
            .iter()
            .filter_map(|i| match i {
                syn::ForeignItem::Fn(f) => Some(f.sig.ident.to_string()),
                syn::ForeignItem::Static(s) => Some(s.ident.to_string()),
                syn::ForeignItem::Type(t) => Some(t.ident.to_string()),
                _ => None,
            })
            .collect(),
        _ => Vec::new(),
    }
}

/// The file named by `#[path = "…"]`.
fn path_attr(attrs: &[syn::Attribute]) -> Option<String> {
    attrs.iter().find_map(|a| {
        if !a.path().is_ident("path") {
            return None;
        }
        match &a.meta.require_name_value().ok()?.value {
            syn::Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(s),
                ..
            }) => Some(s.value()),
            _ => None,
        }
    })
}
