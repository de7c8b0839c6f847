//! The checker on small synthetic crates written to a temporary folder, each result worked
//! out by hand from the files' text.

use super::findings::{check, Circle, Edge};
use super::modules::load;
use std::path::{Path, PathBuf};

/// Writes `files` (path relative to the crate's `src/`, text) and returns `src/`.
fn crate_with(dir: &Path, files: &[(&str, &str)]) -> PathBuf {
    let src = dir.join("src");
    for (path, text) in files {
        let p = src.join(path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    }
    src
}

/// The edges of the crate rooted at `src/lib.rs` as (from, to, names), paths relative to
/// `src`.
fn edges(src: &Path) -> Vec<(String, String, Vec<String>)> {
    let tree = load(&src.join("lib.rs")).unwrap();
    let rel = |f: usize| {
        tree.files[f]
            .strip_prefix(src)
            .unwrap()
            .display()
            .to_string()
    };
    tree.edges()
        .into_iter()
        .map(|((a, b), n)| (rel(a), rel(b), n.into_iter().collect()))
        .collect()
}

fn e(from: &str, to: &str, names: &[&str]) -> (String, String, Vec<String>) {
    (
        from.to_string(),
        to.to_string(),
        names.iter().map(|s| s.to_string()).collect(),
    )
}

#[test]
fn a_true_circle_is_found_with_the_names_that_tie_it() {
    let dir = tempfile::tempdir().unwrap();
    let src = crate_with(
        dir.path(),
        &[
            ("lib.rs", "mod a;\nmod b;\nmod c;\n"),
            // a imports B; b names a's item by a full path in a type; c only uses b.
            (
                "a.rs",
                "use crate::b::B;\npub struct A;\npub fn make() -> B { B }\n",
            ),
            ("b.rs", "pub struct B;\npub fn take(_: crate::a::A) {}\n"),
            ("c.rs", "pub fn go() { crate::b::take(crate::a::A); }\n"),
        ],
    );
    let found = check(std::slice::from_ref(&src), &[], 650).unwrap();
    assert_eq!(found.files, 4);
    assert!(found.long_files.is_empty());
    assert_eq!(
        found.circles,
        vec![Circle {
            files: vec![src.join("a.rs"), src.join("b.rs")],
            edges: vec![
                Edge {
                    from: src.join("a.rs"),
                    to: src.join("b.rs"),
                    names: vec!["B".into()],
                },
                Edge {
                    from: src.join("b.rs"),
                    to: src.join("a.rs"),
                    names: vec!["A".into()],
                },
            ],
        }]
    );
    assert!(!found.clean());
}

#[test]
fn a_re_export_leads_to_the_defining_file_and_is_no_circle() {
    let dir = tempfile::tempdir().unwrap();
    // square.rs takes Circle through the folder's re-export: the edge goes to circle.rs,
    // so mod.rs -> square.rs (its own re-export) closes no circle.
    let src = crate_with(
        dir.path(),
        &[
            ("lib.rs", "pub mod shapes;\n"),
            (
                "shapes/mod.rs",
                "mod circle;\nmod square;\npub use circle::Circle;\npub use self::square::Square;\n",
            ),
            ("shapes/circle.rs", "pub struct Circle(pub f64);\n"),
            (
                "shapes/square.rs",
                "use super::Circle;\npub struct Square(pub f64);\n\
                 impl Square { pub fn inscribed(&self) -> Circle { Circle(self.0 / 2.0) } }\n",
            ),
        ],
    );
    assert_eq!(
        edges(&src),
        vec![
            e("shapes/mod.rs", "shapes/circle.rs", &["Circle"]),
            e("shapes/mod.rs", "shapes/square.rs", &["Square"]),
            e("shapes/square.rs", "shapes/circle.rs", &["Circle"]),
        ]
    );
    assert!(check(&[src], &[], 650).unwrap().clean());
}

#[test]
fn test_only_code_is_left_out() {
    let dir = tempfile::tempdir().unwrap();
    // a's inline test module, its test-only import and its test file all reach b, which
    // uses a: without them there is one edge b -> a and no circle. The test file does not
    // even parse: it is never read.
    let src = crate_with(
        dir.path(),
        &[
            ("lib.rs", "mod a;\nmod b;\n"),
            (
                "a.rs",
                "pub fn a() {}\n#[cfg(test)]\nuse crate::b::helper;\n\
                 #[cfg(test)]\nmod tests {\n    use crate::b::helper;\n    \
                 #[test]\n    fn t() { helper(); }\n}\n\
                 #[cfg(all(test, feature = \"x\"))]\nmod more;\n\
                 #[cfg(test)]\nmod file_tests;\n",
            ),
            ("a/file_tests.rs", "this is not rust { crate::b::helper"),
            ("b.rs", "pub fn helper() { crate::a::a(); }\n"),
        ],
    );
    assert_eq!(edges(&src), vec![e("b.rs", "a.rs", &["a"])]);
    let found = check(&[src], &[], 650).unwrap();
    assert!(found.circles.is_empty());
    // The test file is still counted as a source file (lines under src/ count).
    assert_eq!(found.files, 4);
}

#[test]
fn super_paths_climb_the_module_tree() {
    let dir = tempfile::tempdir().unwrap();
    // outer/inner.rs is the child of outer.rs (a `name.rs` with a `name/` folder), with
    // an inline module whose `super` is inner and whose `super::super` is outer.
    let src = crate_with(
        dir.path(),
        &[
            ("lib.rs", "pub struct Top;\nmod outer;\n"),
            (
                "outer.rs",
                "mod inner;\npub struct Shared;\npub fn g() { inner::h(); }\n",
            ),
            (
                "outer/inner.rs",
                "pub fn h() -> super::Shared { super::Shared }\n\
                 mod deep {\n    pub fn k() -> super::super::super::Top { super::h(); \
                 crate::Top }\n}\n",
            ),
        ],
    );
    assert_eq!(
        edges(&src),
        vec![
            e("outer.rs", "outer/inner.rs", &["h"]),
            e("outer/inner.rs", "lib.rs", &["Top"]),
            e("outer/inner.rs", "outer.rs", &["Shared"]),
        ]
    );
    let found = check(std::slice::from_ref(&src), &[], 650).unwrap();
    assert_eq!(found.circles.len(), 1);
    // Paths sort by component: `outer/inner.rs` before `outer.rs`.
    assert_eq!(
        found.circles[0].files,
        vec![src.join("outer/inner.rs"), src.join("outer.rs")]
    );
}

#[test]
fn a_path_attribute_and_a_renamed_import_are_followed() {
    let dir = tempfile::tempdir().unwrap();
    let src = crate_with(
        dir.path(),
        &[
            (
                "lib.rs",
                "#[path = \"elsewhere/impl_a.rs\"]\nmod a;\nmod b;\n",
            ),
            (
                "elsewhere/impl_a.rs",
                "use crate::b::{self, Thing as T};\npub fn f(_: T) { b::g(); }\n",
            ),
            ("b.rs", "pub struct Thing;\npub fn g() {}\n"),
        ],
    );
    assert_eq!(
        edges(&src),
        vec![e("elsewhere/impl_a.rs", "b.rs", &["Thing", "g"])]
    );
}

#[test]
fn files_over_the_limit_are_listed() {
    let dir = tempfile::tempdir().unwrap();
    let lines = |n: usize| "// a line\n".repeat(n);
    let (at, over) = (lines(10), lines(11));
    let src = crate_with(
        dir.path(),
        &[
            ("lib.rs", "mod at;\nmod over;\n"),
            ("at.rs", &at),
            ("over.rs", &over),
        ],
    );
    let found = check(std::slice::from_ref(&src), &[], 10).unwrap();
    assert_eq!(found.files, 3);
    assert_eq!(found.long_files.len(), 1);
    assert_eq!(found.long_files[0].path, src.join("over.rs"));
    assert_eq!(found.long_files[0].lines, 11);
    assert!(found.circles.is_empty());
    assert!(!found.clean());
}

#[test]
fn measured_folders_count_for_length_only() {
    // An integration test's folder: a long file, a module of it in a subfolder, and text
    // that is no Rust at all (the folder is never parsed, so it cannot fail the check).
    let dir = tempfile::tempdir().unwrap();
    let tests = dir.path().join("tests");
    std::fs::create_dir_all(tests.join("big")).unwrap();
    std::fs::write(tests.join("short.rs"), "// a line\n".repeat(10)).unwrap();
    std::fs::write(tests.join("big/main.rs"), "not rust {\n".repeat(11)).unwrap();
    std::fs::write(tests.join("notes.txt"), "// a line\n".repeat(50)).unwrap();
    let src = crate_with(dir.path(), &[("lib.rs", "pub fn f() {}\n")]);
    let found = check(std::slice::from_ref(&src), std::slice::from_ref(&tests), 10).unwrap();
    assert_eq!(found.files, 3, "lib.rs and the two .rs files below tests/");
    assert_eq!(found.long_files.len(), 1);
    assert_eq!(found.long_files[0].path, tests.join("big/main.rs"));
    assert_eq!(found.long_files[0].lines, 11);
    assert!(found.circles.is_empty());
}

#[test]
fn tarjan_finds_each_cycle_and_leaves_out_single_nodes() {
    // 0 -> 1 -> 2 -> 0 and 3 <-> 4, joined one way by 2 -> 3; 5 has a self-edge only.
    let next = vec![vec![1], vec![2], vec![0, 3], vec![4], vec![3], vec![5]];
    assert_eq!(
        super::graph::circles(6, &next),
        vec![vec![0, 1, 2], vec![3, 4]]
    );
}

#[test]
fn only_test_only_configurations_count_as_tests() {
    let attrs = |text: &str| {
        syn::parse_str::<syn::ItemFn>(&format!("{text} fn f() {{}}"))
            .unwrap()
            .attrs
    };
    assert!(super::modules::is_test(&attrs("#[cfg(test)]")));
    assert!(super::modules::is_test(&attrs(
        "#[cfg(all(test, feature = \"std\"))]"
    )));
    assert!(!super::modules::is_test(&attrs("#[cfg(not(test))]")));
    assert!(!super::modules::is_test(&attrs(
        "#[cfg(any(test, feature = \"std\"))]"
    )));
    assert!(!super::modules::is_test(&attrs(
        "#[cfg(feature = \"test\")]"
    )));
    assert!(!super::modules::is_test(&attrs("#[inline]")));
}
