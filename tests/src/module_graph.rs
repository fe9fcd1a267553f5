//! The module import graph of a crate, read from its sources, for architecture tests: no module
//! imports a module that imports it back, and `systems`' folders import only their own level or
//! lower ones.
//!
//! A token-level scanner, not a Rust parser (no dependencies, fast enough to run on every test):
//!
//! - Nodes are file modules, found by following `mod name;` from the crate root (`lib.rs` or
//!   `main.rs`, the node `crate`): `a/b.rs` and `a/b/mod.rs` are `a::b`; `#[path]` is honoured.
//!   Inline `mod x { .. }` blocks belong to their file's node.
//! - Edges are the paths of `use` items (every leaf of a use tree; `self`, `super`, `crate`,
//!   `as`, globs) and the paths in code that start with `crate::`, `$crate::`, `super::`,
//!   `self::` or the name of a module the scope declares (`child::f()`). A path names the
//!   longest prefix of it that is a file module; paths into other crates are not edges, nor is
//!   a module naming itself.
//! - Not edges: `mod child;` declarations, and `pub use` (any visibility) of a descendant of
//!   the module (a parent re-exporting its children). A `pub use` of anything else counts, and
//!   so does a re-exported name the parent uses in its own code (`pub use graph::RoadGraph;`
//!   then `fn load() -> RoadGraph`: the parent imports `graph` too). A lower-case name (a
//!   function) counts there only where it is called, since variables often share its name.
//! - Skipped: comments (line, block, doc), string and char literals, and every item, statement
//!   or field under a test-only `#[cfg(..)]` (`cfg(test)`, `cfg(all(test, ..))`, ..), including
//!   `#[cfg(test)] mod tests;` files.
//!
//! `tokens` makes a file's token stream, `cfg` marks its test-only code, `scan` reads its module
//! declarations and paths; this module follows the declarations from the root and resolves the
//! paths into edges.

use std::collections::{BTreeMap, BTreeSet, HashMap, VecDeque};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

mod cfg;
mod scan;
mod tokens;

use cfg::*;
use scan::*;
use tokens::*;

/// One file module.
#[derive(Debug, Clone)]
pub struct Module {
    /// `crate`, `world`, `world::roads::gpx`.
    pub path: String,
    /// The file, as shown in messages (relative to the folder holding the crate folder).
    pub file: String,
    /// The file's full path.
    pub source: PathBuf,
}

/// One place where a module names another.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Site {
    pub line: u32,
    /// The path as written (`super::occupancy::OccupancyMap`).
    pub text: String,
}

/// The graph: modules, and for each importing pair every site (in file order).
#[derive(Debug, Clone)]
pub struct ModuleGraph {
    pub modules: Vec<Module>,
    pub edges: BTreeMap<(usize, usize), Vec<Site>>,
}

/// A cycle: module indices `m0 → m1 → … → m0` (the first one is not repeated at the end).
pub type Cycle = Vec<usize>;

impl ModuleGraph {
    /// Reads the crate whose root file (`src/lib.rs` or `src/main.rs`) is `root_file`.
    pub fn load(root_file: &Path) -> Result<Self, String> {
        let root_file = root_file
            .canonicalize()
            .map_err(|e| format!("{}: {e}", root_file.display()))?;
        let shown_base = root_file
            .parent()
            .and_then(Path::parent)
            .and_then(Path::parent)
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let mut loader = Loader {
            shown_base,
            modules: Vec::new(),
            index: HashMap::new(),
            scans: Vec::new(),
        };
        loader.add_file(Vec::new(), root_file, true)?;
        let mut edges: BTreeMap<(usize, usize), Vec<Site>> = BTreeMap::new();
        for (from, scan) in loader.scans.iter().enumerate() {
            for r in &scan.refs {
                let Some(target) = loader.resolve(&r.base, &r.segments) else {
                    continue;
                };
                let target_path = &loader.modules[target].0;
                let own_path = &loader.modules[from].0;
                if target == from || (r.reexport && target_path.starts_with(own_path)) {
                    continue;
                }
                edges.entry((from, target)).or_default().push(Site {
                    line: r.line,
                    text: r.text.clone(),
                });
            }
        }
        let modules = loader
            .modules
            .iter()
            .map(|(segs, file, source)| Module {
                path: if segs.is_empty() {
                    "crate".to_string()
                } else {
                    segs.join("::")
                },
                file: file.clone(),
                source: source.clone(),
            })
            .collect();
        Ok(ModuleGraph { modules, edges })
    }

    /// The module named `path` (`crate`, `a::b`).
    pub fn find(&self, path: &str) -> Option<usize> {
        self.modules.iter().position(|m| m.path == path)
    }

    /// Does `from` import `to` directly?
    pub fn imports(&self, from: &str, to: &str) -> bool {
        match (self.find(from), self.find(to)) {
            (Some(a), Some(b)) => self.edges.contains_key(&(a, b)),
            _ => false,
        }
    }

    fn successors(&self) -> Vec<Vec<usize>> {
        let mut succ = vec![Vec::new(); self.modules.len()];
        for &(a, b) in self.edges.keys() {
            succ[a].push(b);
        }
        succ
    }

    /// Every cycle needed to see each edge that lies on a cycle: for each such edge `a → b`, the
    /// shortest way back from `b` to `a`. Each cycle once, rotated to start at its smallest
    /// module path; sorted.
    pub fn cycles(&self) -> Vec<Cycle> {
        cycles_of(&self.successors(), |i| self.modules[i].path.clone())
    }

    /// Every cycle, as text: each a chain of module paths, then each edge with its file, line
    /// and the path as written. Empty when there is none.
    pub fn describe_cycles(&self) -> String {
        let mut out = String::new();
        for (n, cycle) in self.cycles().iter().enumerate() {
            let mut chain: Vec<&str> = cycle
                .iter()
                .map(|&m| self.modules[m].path.as_str())
                .collect();
            chain.push(&self.modules[cycle[0]].path);
            let _ = writeln!(out, "cycle {}: {}", n + 1, chain.join(" → "));
            for (k, &a) in cycle.iter().enumerate() {
                let b = cycle[(k + 1) % cycle.len()];
                out.push_str(&self.describe_edge(a, b));
            }
        }
        out
    }

    /// One edge `a → b` and each of its sites, as lines of text.
    pub fn describe_edge(&self, a: usize, b: usize) -> String {
        let mut out = format!("    {} → {}\n", self.modules[a].path, self.modules[b].path);
        for site in self.edges.get(&(a, b)).into_iter().flatten() {
            let _ = writeln!(
                out,
                "        {}:{}  {}",
                self.modules[a].file, site.line, site.text
            );
        }
        out
    }

    /// Checks a layering of the crate's top-level modules. `levels` lists folder names from the
    /// lowest level up. A module may import modules of its own folder, of lower levels, and of
    /// other folders of its level as long as the folders import each other without a cycle; the
    /// crate root is exempt. Returns one line block per problem (a top-level module missing from
    /// `levels`, an edge pointing up, a cycle between folders); empty when the layering holds.
    pub fn layer_violations(&self, levels: &[&[&str]]) -> Vec<String> {
        let level_of: HashMap<&str, usize> = levels
            .iter()
            .enumerate()
            .flat_map(|(l, names)| names.iter().map(move |n| (*n, l)))
            .collect();
        let folder = |m: usize| {
            self.modules[m]
                .path
                .split("::")
                .next()
                .unwrap_or("")
                .to_string()
        };
        let mut problems = Vec::new();
        for m in &self.modules {
            if !m.path.contains("::")
                && m.path != "crate"
                && !level_of.contains_key(m.path.as_str())
            {
                problems.push(format!(
                    "{} ({}) is in no level of the layering",
                    m.path, m.file
                ));
            }
        }
        // Same-level folder graph: folder → folder → the module edges behind it.
        let mut folders: Vec<String> = Vec::new();
        let mut folder_edges: BTreeMap<(usize, usize), Vec<(usize, usize)>> = BTreeMap::new();
        for &(a, b) in self.edges.keys() {
            if self.modules[a].path == "crate" || self.modules[b].path == "crate" {
                continue;
            }
            let (fa, fb) = (folder(a), folder(b));
            if fa == fb {
                continue;
            }
            let (Some(&la), Some(&lb)) = (level_of.get(fa.as_str()), level_of.get(fb.as_str()))
            else {
                continue;
            };
            if lb > la {
                problems.push(format!(
                    "{fa} (level {la}) imports {fb} (level {lb}), a higher level:\n{}",
                    self.describe_edge(a, b)
                ));
            }
            if lb != la {
                continue;
            }
            let ia = position_or_push(&mut folders, fa);
            let ib = position_or_push(&mut folders, fb);
            folder_edges.entry((ia, ib)).or_default().push((a, b));
        }
        let mut succ = vec![Vec::new(); folders.len()];
        for &(a, b) in folder_edges.keys() {
            succ[a].push(b);
        }
        for cycle in cycles_of(&succ, |i| folders[i].clone()) {
            let mut chain: Vec<&str> = cycle.iter().map(|&f| folders[f].as_str()).collect();
            chain.push(&folders[cycle[0]]);
            let mut text = format!("folders import each other: {}\n", chain.join(" → "));
            for (k, &fa) in cycle.iter().enumerate() {
                let fb = cycle[(k + 1) % cycle.len()];
                for &(a, b) in &folder_edges[&(fa, fb)] {
                    text.push_str(&self.describe_edge(a, b));
                }
            }
            problems.push(text);
        }
        problems
    }
}

fn position_or_push(list: &mut Vec<String>, name: String) -> usize {
    match list.iter().position(|f| *f == name) {
        Some(i) => i,
        None => {
            list.push(name);
            list.len() - 1
        }
    }
}

/// See [`ModuleGraph::cycles`]; `name` orders nodes.
fn cycles_of(succ: &[Vec<usize>], name: impl Fn(usize) -> String) -> Vec<Cycle> {
    let mut found: BTreeSet<Vec<String>> = BTreeSet::new();
    let mut cycles = Vec::new();
    for a in 0..succ.len() {
        for &b in &succ[a] {
            if a == b {
                continue;
            }
            // Shortest path b → a (BFS).
            let mut prev = vec![usize::MAX; succ.len()];
            prev[b] = b;
            let mut queue = VecDeque::from([b]);
            while let Some(n) = queue.pop_front() {
                if n == a {
                    break;
                }
                for &s in &succ[n] {
                    if prev[s] == usize::MAX {
                        prev[s] = n;
                        queue.push_back(s);
                    }
                }
            }
            if prev[a] == usize::MAX {
                continue;
            }
            let mut back = vec![a];
            let mut n = a;
            while n != b {
                n = prev[n];
                back.push(n);
            }
            back.reverse(); // b … a
            let mut cycle: Vec<usize> = back;
            let start = (0..cycle.len())
                .min_by_key(|&i| name(cycle[i]))
                .unwrap_or(0);
            cycle.rotate_left(start);
            if found.insert(cycle.iter().map(|&i| name(i)).collect()) {
                cycles.push(cycle);
            }
        }
    }
    cycles.sort_by_key(|c| c.iter().map(|&i| name(i)).collect::<Vec<_>>());
    cycles
}

struct Scan {
    refs: Vec<Ref>,
}

struct Loader {
    shown_base: PathBuf,
    /// Module path segments, file as shown, and file.
    modules: Vec<(Vec<String>, String, PathBuf)>,
    index: HashMap<Vec<String>, usize>,
    scans: Vec<Scan>,
}

impl Loader {
    fn add_file(&mut self, path: Vec<String>, file: PathBuf, mod_rs: bool) -> Result<(), String> {
        let text =
            std::fs::read_to_string(&file).map_err(|e| format!("{}: {e}", file.display()))?;
        let shown = file
            .strip_prefix(&self.shown_base)
            .unwrap_or(&file)
            .to_string_lossy()
            .replace('\\', "/");
        let tokens = tokenize(&text);
        let skip = test_only_tokens(&tokens);
        if skip.first_is_inner_test_cfg {
            return Ok(());
        }
        let id = self.modules.len();
        self.modules.push((path.clone(), shown, file.clone()));
        self.index.insert(path.clone(), id);
        self.scans.push(Scan { refs: Vec::new() });
        let dir = file.parent().map(Path::to_path_buf).unwrap_or_default();
        // Children of a non-mod-rs file `a/b.rs` live in `a/b/`.
        let child_dir = if mod_rs {
            dir.clone()
        } else {
            dir.join(file.file_stem().unwrap_or_default())
        };
        let scanned = scan_file(&tokens, &skip.skip, &path);
        self.scans[id].refs = scanned.refs;
        for decl in scanned.file_mods {
            let mut child = path.clone();
            child.extend(decl.inline_path.iter().cloned());
            child.push(decl.name.clone());
            let (child_file, child_mod_rs) = if let Some(p) = &decl.path_attr {
                let base = if decl.inline_path.is_empty() {
                    dir.clone()
                } else {
                    decl.inline_path
                        .iter()
                        .fold(child_dir.clone(), |d, s| d.join(s))
                };
                let f = base.join(p);
                (f, true)
            } else {
                let base = decl
                    .inline_path
                    .iter()
                    .fold(child_dir.clone(), |d, s| d.join(s));
                let flat = base.join(format!("{}.rs", decl.name));
                if flat.is_file() {
                    (flat, false)
                } else {
                    (base.join(&decl.name).join("mod.rs"), true)
                }
            };
            self.add_file(child, child_file, child_mod_rs)?;
        }
        Ok(())
    }

    fn resolve(&self, base: &[String], segments: &[String]) -> Option<usize> {
        let mut full = base.to_vec();
        for s in segments {
            match s.as_str() {
                "self" => {}
                "crate" => full.clear(),
                "super" => {
                    full.pop()?;
                }
                _ => full.push(s.clone()),
            }
        }
        (0..=full.len())
            .rev()
            .find_map(|n| self.index.get(&full[..n]).copied())
    }
}

#[cfg(test)]
mod tests;
