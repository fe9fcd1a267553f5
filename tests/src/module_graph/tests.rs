use super::*;

/// A crate of `files` (paths under its folder, `src/lib.rs` first) in a temporary folder.
fn krate(files: &[(&str, &str)]) -> (tempfile::TempDir, ModuleGraph) {
    let dir = tempfile::tempdir().unwrap();
    for (path, text) in files {
        let p = dir.path().join("k").join(path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    }
    let g = ModuleGraph::load(&dir.path().join("k/src/lib.rs")).unwrap();
    (dir, g)
}

fn cycle_names(g: &ModuleGraph) -> Vec<Vec<&str>> {
    g.cycles()
        .iter()
        .map(|c| c.iter().map(|&m| g.modules[m].path.as_str()).collect())
        .collect()
}

#[test]
fn file_modules_are_the_nodes() {
    let (_d, g) = krate(&[
        (
            "src/lib.rs",
            "mod a;\npub mod b;\nmod inline { pub fn f() {} }\n",
        ),
        ("src/a.rs", "mod deep;\n"),
        ("src/a/deep.rs", ""),
        ("src/b/mod.rs", "#[path = \"elsewhere.rs\"]\nmod c;\n"),
        ("src/b/elsewhere.rs", ""),
    ]);
    let names: Vec<&str> = g.modules.iter().map(|m| m.path.as_str()).collect();
    assert_eq!(names, ["crate", "a", "a::deep", "b", "b::c"]);
    assert!(
        g.modules[4].file.ends_with("k/src/b/elsewhere.rs"),
        "{}",
        g.modules[4].file
    );
}

#[test]
fn a_planted_two_cycle_is_found_with_both_paths() {
    let (_d, g) = krate(&[
        ("src/lib.rs", "mod a;\nmod b;\n"),
        ("src/a.rs", "use crate::b::B;\npub struct A;\n"),
        ("src/b.rs", "pub struct B;\n\nuse super::a::A;\n"),
    ]);
    assert_eq!(cycle_names(&g), [["a", "b"]]);
    let text = g.describe_cycles();
    assert!(text.contains("cycle 1: a → b → a"), "{text}");
    assert!(text.contains("k/src/a.rs:1  crate::b::B"), "{text}");
    assert!(text.contains("k/src/b.rs:3  super::a::A"), "{text}");
}

#[test]
fn a_three_cycle_of_inline_paths_is_found() {
    let (_d, g) = krate(&[
        ("src/lib.rs", "mod a;\nmod b;\nmod c;\n"),
        ("src/a.rs", "pub fn f() { crate::b::g() }\n"),
        ("src/b.rs", "pub fn g() { let _ = super::c::H; }\n"),
        (
            "src/c.rs",
            "pub const H: u8 = 0;\nfn k() { crate::a::f() }\n",
        ),
    ]);
    assert_eq!(cycle_names(&g), [["a", "b", "c"]]);
    let text = g.describe_cycles();
    assert!(text.contains("a → b → c → a"), "{text}");
    assert!(text.contains("k/src/c.rs:2  crate::a::f"), "{text}");
}

#[test]
fn a_parent_re_exporting_its_child_does_not_import_it() {
    let (_d, g) = krate(&[
        ("src/lib.rs", "pub mod p;\n"),
        (
            "src/p/mod.rs",
            "mod c;\nmod d;\npub use c::C;\npub(crate) use self::d::{D, E as F};\npub struct P;\n",
        ),
        ("src/p/c.rs", "use super::P;\npub struct C;\n"),
        (
            "src/p/d.rs",
            "pub struct D;\npub struct E;\nfn f() -> crate::p::P { super::P }\n",
        ),
    ]);
    assert!(g.cycles().is_empty(), "{}", g.describe_cycles());
    assert!(g.imports("p::c", "p"));
    assert!(g.imports("p::d", "p"));
    assert!(!g.imports("p", "p::c"));
    assert!(!g.imports("p", "p::d"));
}

#[test]
fn a_parent_that_uses_its_child_imports_it() {
    // A private `use`, a path to the child in code, or a re-exported name used in the parent's
    // own code: each is an import, so the child importing the parent back is a cycle.
    for parent in [
        "mod c;\nuse c::helper;\npub struct P;\n",
        "mod c;\npub struct P;\nfn f() { c::helper() }\n",
        "mod c;\npub use c::Helper;\npub struct P(Helper);\n",
    ] {
        let (_d, g) = krate(&[
            ("src/lib.rs", "pub mod p;\n"),
            ("src/p/mod.rs", parent),
            (
                "src/p/c.rs",
                "use super::P;\npub fn helper() {}\npub struct Helper;\n",
            ),
        ]);
        assert_eq!(cycle_names(&g), [["p", "p::c"]], "{parent}");
    }
}

#[test]
fn a_pub_use_of_a_module_that_is_not_a_descendant_counts() {
    let (_d, g) = krate(&[
        ("src/lib.rs", "mod a;\nmod b;\n"),
        ("src/a.rs", "pub use crate::b::B;\npub struct A;\n"),
        ("src/b.rs", "use crate::a::A;\npub struct B;\n"),
    ]);
    assert_eq!(cycle_names(&g), [["a", "b"]]);
}

#[test]
fn use_trees_resolve_to_the_longest_file_module_prefix() {
    let (_d, g) = krate(&[
        ("src/lib.rs", "mod a;\nmod b;\nmod x;\n"),
        (
            "src/a.rs",
            "pub struct A;\npub mod inner { pub struct I; }\n",
        ),
        ("src/b/mod.rs", "pub mod c;\npub struct B;\n"),
        ("src/b/c.rs", "pub struct C;\n"),
        (
            "src/x.rs",
            "use crate::{\n    a::{self, inner::I as J},\n    b::{c::{C}, *},\n};\nuse ::std::fmt;\nuse std::io;\n",
        ),
    ]);
    let x = g.find("x").unwrap();
    let targets: Vec<&str> = g
        .edges
        .keys()
        .filter(|(a, _)| *a == x)
        .map(|&(_, b)| g.modules[b].path.as_str())
        .collect();
    assert_eq!(targets, ["a", "b", "b::c"]);
    let a = g.find("a").unwrap();
    let sites = &g.edges[&(x, a)];
    assert_eq!(sites.iter().map(|s| s.line).collect::<Vec<_>>(), [2, 2]);
    assert_eq!(sites[1].text, "crate::a::inner::I");
}

#[test]
fn test_only_code_is_ignored() {
    let (_d, g) = krate(&[
        ("src/lib.rs", "mod a;\nmod b;\n"),
        (
            "src/a.rs",
            r#"pub struct A;
#[cfg(test)]
mod tests;
#[cfg(test)]
#[path = "more_tests.rs"]
mod more;
#[cfg(test)]
mod inline {
    use crate::b::B;
    fn f() { crate::b::g() }
}
#[cfg(test)]
use crate::b::C;
#[cfg(all(test, feature = "x"))]
use crate::b::D;
#[cfg(test)]
pub(crate) fn helper() -> crate::b::B { crate::b::B }
impl A {
    #[cfg(test)]
    fn only_in_tests(&self) { crate::b::g(); }
    pub fn kept(&self) {}
}
pub struct S {
    #[cfg(test)]
    probe: crate::b::B,
    pub kept: u8,
}
"#,
        ),
        ("src/a/tests.rs", "use crate::b::B;\n"),
        ("src/a/more_tests.rs", "use crate::b::B;\n"),
        (
            "src/b.rs",
            "use crate::a::A;\npub struct B;\npub fn g() {}\n",
        ),
    ]);
    assert!(g.cycles().is_empty(), "{}", g.describe_cycles());
    assert!(g.find("a::tests").is_none() && g.find("a::more").is_none());
    assert!(!g.imports("a", "b"));
}

#[test]
fn cfg_that_holds_outside_tests_is_kept() {
    for attr in [
        "#[cfg(not(test))]",
        "#[cfg(any(test, unix))]",
        "#[cfg(unix)]",
    ] {
        let (_d, g) = krate(&[
            ("src/lib.rs", "mod a;\nmod b;\n"),
            (
                "src/a.rs",
                &format!("{attr}\nuse crate::b::B;\npub struct A;\n"),
            ),
            ("src/b.rs", "use crate::a::A;\npub struct B;\n"),
        ]);
        assert_eq!(cycle_names(&g), [["a", "b"]], "{attr}");
    }
}

#[test]
fn comments_and_literals_are_ignored() {
    let (_d, g) = krate(&[
        ("src/lib.rs", "mod a;\nmod b;\n"),
        (
            "src/a.rs",
            r####"//! See [`crate::b::B`].
// use crate::b::B;
/* crate::b::g() /* nested: crate::b::B */ still a comment: use crate::b::B; */
/// Calls [`crate::b::g`].
pub struct A;
const S: &str = "use crate::b::B; \" crate::b::g()";
const R: &str = r#"crate::b::B "quoted" "#;
const BS: &[u8] = b"crate::b::B";
const Q: char = '"';
const E: char = '\'';
fn keep<'a>(x: &'a str) -> &'a str { x }
"####,
        ),
        (
            "src/b.rs",
            "use crate::a::A;\npub struct B;\npub fn g() {}\n",
        ),
    ]);
    assert!(g.cycles().is_empty(), "{}", g.describe_cycles());
    assert!(!g.imports("a", "b"));
    assert!(g.imports("b", "a"));
}

#[test]
fn a_lower_folder_importing_a_higher_one_breaks_the_layering() {
    let (_d, g) = krate(&[
        ("src/lib.rs", "mod low;\nmod high;\nmod side;\nmod other;\n"),
        ("src/low/mod.rs", "mod x;\n"),
        ("src/low/x.rs", "fn f() { crate::high::h() }\n"),
        ("src/high.rs", "use crate::low::L;\npub fn h() {}\n"),
        ("src/side.rs", "use crate::other::O;\n"),
        ("src/other.rs", "use crate::side::S;\n"),
    ]);
    let levels: &[&[&str]] = &[&["low"], &["high", "side", "other"]];
    let problems = g.layer_violations(levels);
    assert_eq!(problems.len(), 2, "{problems:#?}");
    assert!(
        problems[0].starts_with("low (level 0) imports high (level 1)"),
        "{}",
        problems[0]
    );
    assert!(
        problems[0].contains("k/src/low/x.rs:1  crate::high::h"),
        "{}",
        problems[0]
    );
    // the same level: one way is fine, both ways is a cycle between the folders
    assert!(
        problems[1].starts_with("folders import each other"),
        "{}",
        problems[1]
    );
    let fine: &[&[&str]] = &[&["low", "high"], &["side"], &["other"]];
    assert_eq!(
        g.layer_violations(fine).len(),
        2,
        "side imports other, a higher level"
    );
    let missing = g.layer_violations(&[&["low"], &["high"]]);
    assert!(
        missing.iter().any(|p| p.starts_with("side (")),
        "{missing:#?}"
    );
}
