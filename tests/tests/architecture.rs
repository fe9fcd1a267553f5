//! Architecture rules, checked on the sources (no crate of the workspace is linked): no module
//! imports a module that imports it back, in `systems` and `sim`, and `systems`' folders import
//! only their own level or lower ones. What counts as an import: tests/src/module_graph.rs.

use std::path::{Path, PathBuf};
use tests::module_graph::ModuleGraph;

/// `systems`' folders, lowest level first (`systems/ARCHITECTURE.md`, "Layers of `systems`"):
/// core ← world ← raycast, body ← sensors ← matching ← localization ← mapping, navigation, eval.
/// Folders of one level may import each other one way only (that is checked as a cycle between the folders).
const SYSTEMS_LEVELS: &[&[&str]] = &[
    &["core"],
    &["world"],
    &["raycast", "body"],
    &["sensors"],
    &["matching"],
    &["localization"],
    &["mapping", "navigation", "eval"],
    // re-exports from every level, and the robot bundle of components from several
    &["prelude", "robot"],
];

/// `krate`'s sources in the clone the test runs in: cargo's `CARGO_MANIFEST_DIR` at run time
/// (a test binary from a build cache shared between clones may have been compiled in another
/// one, whose sources it would check instead), else where it was compiled.
fn src(krate: &str) -> PathBuf {
    let tests_dir = std::env::var_os("CARGO_MANIFEST_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")));
    tests_dir.join("..").join(krate).join("src")
}

fn graph(root: &Path) -> ModuleGraph {
    let g = ModuleGraph::load(root).unwrap_or_else(|e| panic!("reading the crate: {e}"));
    assert!(!g.modules.is_empty());
    g
}

fn assert_no_cycles(g: &ModuleGraph, what: &str) {
    let text = g.describe_cycles();
    assert!(
        text.is_empty(),
        "{what}: modules that import each other (move what both need to the module it belongs \
         to, or to a new leaf module):\n{text}"
    );
}

#[test]
fn systems_has_no_module_cycles() {
    let g = graph(&src("systems").join("lib.rs"));
    assert!(
        g.modules.len() > 100,
        "{} modules: wrong folder?",
        g.modules.len()
    );
    assert_no_cycles(&g, "systems");
}

#[test]
fn systems_layers_point_down() {
    let g = graph(&src("systems").join("lib.rs"));
    let problems = g.layer_violations(SYSTEMS_LEVELS);
    assert!(
        problems.is_empty(),
        "systems: nothing lower imports anything higher ({SYSTEMS_LEVELS:?}, lowest first):\n{}",
        problems.join("\n")
    );
}

#[test]
fn sim_has_no_module_cycles() {
    for root in ["lib.rs", "main.rs"] {
        let g = graph(&src("sim").join(root));
        assert_no_cycles(&g, &format!("sim ({root})"));
    }
}

/// The check is not vacuous: the same sources with one import planted against an existing one
/// fail both rules.
#[test]
fn a_cycle_and_a_layer_break_planted_in_systems_are_caught() {
    let copy = tempfile::tempdir().unwrap();
    let root = copy.path().join("systems").join("src");
    copy_dir(&src("systems"), &root);
    let g = graph(&root.join("lib.rs"));
    // an edge a → b between two folder modules; b imports a back
    let (a, b) = g
        .edges
        .keys()
        .map(|&(a, b)| (&g.modules[a], &g.modules[b]))
        .find(|(a, b)| a.path.contains("::") && b.path.contains("::"))
        .expect("an edge");
    let planted = format!("\nfn planted() {{ crate::{}::planted() }}\n", a.path);
    append(&b.source, &planted);
    // and core imports mapping
    append(
        &root.join("core").join("mod.rs"),
        "\nuse crate::mapping::Planted;\n",
    );
    let g2 = graph(&root.join("lib.rs"));
    let cycles = g2.describe_cycles();
    let chain = format!("{} → {}", b.path, a.path);
    assert!(cycles.contains(&chain), "{chain} not in:\n{cycles}");
    let problems = g2.layer_violations(SYSTEMS_LEVELS).join("\n");
    assert!(
        problems.contains("core (level 0) imports mapping (level 6)"),
        "{problems}"
    );
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

fn append(file: &Path, text: &str) {
    let mut s = std::fs::read_to_string(file).unwrap();
    s.push_str(text);
    std::fs::write(file, s).unwrap();
}
