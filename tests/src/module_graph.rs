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

use std::collections::{BTreeMap, BTreeSet, HashMap, VecDeque};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

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

/// A path found in a file, not yet resolved.
struct Ref {
    /// The module the path is relative to (file module, then inline modules).
    base: Vec<String>,
    /// The path as written (`crate`, `super`, `self`, names).
    segments: Vec<String>,
    line: u32,
    text: String,
    reexport: bool,
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

// ---------------------------------------------------------------------------------------------
// Tokens

#[derive(Debug, Clone, PartialEq, Eq)]
enum Tok {
    Ident(String),
    /// `::`
    PathSep,
    Punct(char),
    /// A string literal's text.
    Str(String),
    /// A char or number literal or a lifetime.
    Other,
}

#[derive(Debug, Clone)]
struct Token {
    tok: Tok,
    line: u32,
}

fn is_ident_start(c: char) -> bool {
    c.is_alphabetic() || c == '_'
}

fn is_ident_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

fn tokenize(text: &str) -> Vec<Token> {
    let c: Vec<char> = text.chars().collect();
    let at = |i: usize| c.get(i).copied().unwrap_or('\0');
    let mut out = Vec::new();
    let mut i = 0;
    let mut line = 1u32;
    while i < c.len() {
        let ch = c[i];
        let start_line = line;
        if ch == '\n' {
            line += 1;
            i += 1;
        } else if ch.is_whitespace() {
            i += 1;
        } else if ch == '/' && at(i + 1) == '/' {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if ch == '/' && at(i + 1) == '*' {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && at(i + 1) == '*' {
                    depth += 1;
                    i += 2;
                } else if c[i] == '*' && at(i + 1) == '/' {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    line += u32::from(c[i] == '\n');
                    i += 1;
                }
            }
        } else if let Some((body, raw_hashes)) = string_start(&c, i) {
            let (end, content) = skip_string(&c, body, raw_hashes);
            line += c[i..end].iter().filter(|&&x| x == '\n').count() as u32;
            i = end;
            out.push(Token {
                tok: Tok::Str(content),
                line: start_line,
            });
        } else if ch == 'b' && at(i + 1) == '\'' {
            i = skip_char_literal(&c, i + 1);
            out.push(Token {
                tok: Tok::Other,
                line,
            });
        } else if ch == 'r' && at(i + 1) == '#' && is_ident_start(at(i + 2)) {
            let start = i + 2;
            i = start;
            while i < c.len() && is_ident_char(c[i]) {
                i += 1;
            }
            out.push(Token {
                tok: Tok::Ident(c[start..i].iter().collect()),
                line,
            });
        } else if is_ident_start(ch) {
            let start = i;
            while i < c.len() && is_ident_char(c[i]) {
                i += 1;
            }
            out.push(Token {
                tok: Tok::Ident(c[start..i].iter().collect()),
                line,
            });
        } else if ch.is_ascii_digit() {
            while i < c.len()
                && (is_ident_char(c[i]) || (c[i] == '.' && at(i + 1).is_ascii_digit()))
            {
                i += 1;
            }
            out.push(Token {
                tok: Tok::Other,
                line,
            });
        } else if ch == '\'' {
            // A char literal ('x', '\n', '\u{1F600}') or a lifetime / label ('a).
            if at(i + 1) == '\\' || at(i + 2) == '\'' {
                i = skip_char_literal(&c, i);
            } else {
                i += 1;
                while i < c.len() && is_ident_char(c[i]) {
                    i += 1;
                }
            }
            out.push(Token {
                tok: Tok::Other,
                line,
            });
        } else if ch == ':' && at(i + 1) == ':' {
            out.push(Token {
                tok: Tok::PathSep,
                line,
            });
            i += 2;
        } else {
            out.push(Token {
                tok: Tok::Punct(ch),
                line,
            });
            i += 1;
        }
    }
    out
}

/// At a string literal (`".."`, `r#".."#`, `b".."`, `br".."`, `c".."`, `cr".."`): the index after
/// its opening quote and, for a raw string, its number of `#`.
fn string_start(c: &[char], i: usize) -> Option<(usize, Option<usize>)> {
    let at = |i: usize| c.get(i).copied().unwrap_or('\0');
    let mut j = i;
    if matches!(at(j), 'b' | 'c') {
        j += 1;
    }
    let mut raw = None;
    if at(j) == 'r' {
        j += 1;
        let mut hashes = 0;
        while at(j) == '#' {
            hashes += 1;
            j += 1;
        }
        raw = Some(hashes);
    }
    (at(j) == '"').then_some((j + 1, raw))
}

/// From after the opening quote: the index after the closing one, and the text in between
/// (escapes left as written).
fn skip_string(c: &[char], body: usize, raw_hashes: Option<usize>) -> (usize, String) {
    let mut i = body;
    while i < c.len() {
        match raw_hashes {
            None if c[i] == '\\' => i += 1,
            None if c[i] == '"' => return (i + 1, c[body..i].iter().collect()),
            Some(h) if c[i] == '"' && (1..=h).all(|k| c.get(i + k) == Some(&'#')) => {
                return (i + 1 + h, c[body..i].iter().collect());
            }
            _ => {}
        }
        i += 1;
    }
    (c.len(), c[body.min(c.len())..].iter().collect())
}

/// `i` is at the opening `'`; returns the index after the closing one.
fn skip_char_literal(c: &[char], mut i: usize) -> usize {
    i += 1;
    while i < c.len() && c[i] != '\'' {
        if c[i] == '\\' {
            i += 1;
        }
        i += 1;
    }
    i + 1
}

// ---------------------------------------------------------------------------------------------
// Test-only code

struct TestOnly {
    /// Per token: inside an item (or statement, field) under a test-only `#[cfg]`.
    skip: Vec<bool>,
    /// The file starts with `#![cfg(test)]`.
    first_is_inner_test_cfg: bool,
}

fn ident(t: Option<&Token>) -> Option<&str> {
    match t {
        Some(Token {
            tok: Tok::Ident(s), ..
        }) => Some(s),
        _ => None,
    }
}

fn punct(t: Option<&Token>, p: char) -> bool {
    matches!(t, Some(Token { tok: Tok::Punct(q), .. }) if *q == p)
}

/// Index of the bracket closing the one at `open` (or the end).
fn matching_close(t: &[Token], open: usize) -> usize {
    let mut depth = 0i32;
    for (k, tok) in t.iter().enumerate().skip(open) {
        match tok.tok {
            Tok::Punct('(' | '[' | '{') => depth += 1,
            Tok::Punct(')' | ']' | '}') => {
                depth -= 1;
                if depth == 0 {
                    return k;
                }
            }
            _ => {}
        }
    }
    t.len().saturating_sub(1)
}

/// Three-valued cfg predicate with `test` false and every other option unknown.
fn eval_cfg(t: &[Token], i: &mut usize) -> Option<bool> {
    let name = ident(t.get(*i)).unwrap_or("").to_string();
    *i += 1;
    if punct(t.get(*i), '(') {
        *i += 1;
        let mut args = Vec::new();
        while *i < t.len() && !punct(t.get(*i), ')') {
            args.push(eval_cfg(t, i));
            if punct(t.get(*i), ',') {
                *i += 1;
            }
        }
        *i += 1;
        return match name.as_str() {
            "all" => {
                if args.contains(&Some(false)) {
                    Some(false)
                } else if args.iter().all(|a| *a == Some(true)) {
                    Some(true)
                } else {
                    None
                }
            }
            "any" => {
                if args.contains(&Some(true)) {
                    Some(true)
                } else if args.iter().all(|a| *a == Some(false)) {
                    Some(false)
                } else {
                    None
                }
            }
            "not" => args.first().copied().flatten().map(|v| !v),
            _ => None,
        };
    }
    if punct(t.get(*i), '=') {
        *i += 2; // key = "value"
        return None;
    }
    if name == "test" { Some(false) } else { None }
}

/// Is the attribute whose `[` is at `open` a `cfg` that is false outside tests?
fn is_test_only_cfg(t: &[Token], open: usize) -> bool {
    if ident(t.get(open + 1)) != Some("cfg") || !punct(t.get(open + 2), '(') {
        return false;
    }
    let mut i = open + 3;
    eval_cfg(t, &mut i) == Some(false)
}

fn test_only_tokens(t: &[Token]) -> TestOnly {
    let mut skip = vec![false; t.len()];
    let mut first_is_inner_test_cfg = false;
    let mut before_items = true;
    let mut i = 0;
    while i < t.len() {
        if !punct(t.get(i), '#') {
            before_items = false;
            i += 1;
            continue;
        }
        let inner = punct(t.get(i + 1), '!');
        let open = if inner { i + 2 } else { i + 1 };
        if !punct(t.get(open), '[') {
            i += 1;
            continue;
        }
        let close = matching_close(t, open);
        if !is_test_only_cfg(t, open) {
            i = close + 1;
            continue;
        }
        if inner {
            // `#![cfg(test)]`: the enclosing module (at the top of a file: the whole file).
            first_is_inner_test_cfg |= before_items;
            i = close + 1;
            continue;
        }
        let end = item_end(t, close + 1);
        for s in &mut skip[i..end] {
            *s = true;
        }
        i = end;
    }
    TestOnly {
        skip,
        first_is_inner_test_cfg,
    }
}

/// The end (exclusive) of the item, statement, field or arm starting at `i` (after one
/// attribute): further attributes, then up to a `;` (or `,`, for fields, arms and expressions)
/// at its own depth or the `}` closing its body.
fn item_end(t: &[Token], mut i: usize) -> usize {
    while punct(t.get(i), '#') && punct(t.get(i + 1), '[') {
        i = matching_close(t, i + 1) + 1;
    }
    // The item's keyword, past visibility and qualifiers.
    let mut k = i;
    loop {
        match ident(t.get(k)) {
            Some("pub") => {
                k += 1;
                if punct(t.get(k), '(') {
                    k = matching_close(t, k) + 1;
                }
            }
            Some("unsafe" | "async" | "default" | "extern") => k += 1,
            Some("const")
                if matches!(
                    ident(t.get(k + 1)),
                    Some("fn" | "unsafe" | "async" | "extern")
                ) =>
            {
                k += 1
            }
            _ => break,
        }
        if matches!(
            t.get(k),
            Some(Token {
                tok: Tok::Other,
                ..
            })
        ) {
            k += 1; // extern "C"
        }
    }
    let keyword = ident(t.get(k)).unwrap_or("");
    let semicolon_only = matches!(
        keyword,
        "use" | "const" | "static" | "type" | "let" | "crate"
    );
    let is_item = semicolon_only
        || matches!(
            keyword,
            "fn" | "mod" | "impl" | "trait" | "struct" | "enum" | "union" | "macro_rules"
        );
    let mut depth = 0i32;
    let mut j = i;
    while j < t.len() {
        match t[j].tok {
            Tok::Punct('(' | '[' | '{') => depth += 1,
            Tok::Punct(')' | ']' | '}') => {
                depth -= 1;
                if depth < 0 {
                    return j;
                }
                if depth == 0 && t[j].tok == Tok::Punct('}') && !semicolon_only {
                    // `struct S { .. }`, `fn f() { .. }`; a following `;` belongs to it too.
                    return if punct(t.get(j + 1), ';') {
                        j + 2
                    } else {
                        j + 1
                    };
                }
            }
            Tok::Punct(';') if depth == 0 => return j + 1,
            Tok::Punct(',') if depth == 0 && !is_item => return j + 1,
            _ => {}
        }
        j += 1;
    }
    t.len()
}

// ---------------------------------------------------------------------------------------------
// Paths

/// An out-of-line `mod name;`.
struct ModDecl {
    /// Inline modules around the declaration (usually none).
    inline_path: Vec<String>,
    name: String,
    path_attr: Option<String>,
}

struct FileScan {
    refs: Vec<Ref>,
    file_mods: Vec<ModDecl>,
}

/// A scope: the file itself or an inline `mod x { .. }`.
struct Scope {
    /// Inline module names from the file module down.
    inline_path: Vec<String>,
    /// Modules declared directly in this scope (file or inline).
    children: BTreeSet<String>,
    /// Token index of the `}` that ends it.
    close: usize,
}

fn scan_file(t: &[Token], skip: &[bool], file_path: &[String]) -> FileScan {
    // Pass 1: scopes (inline modules) and the modules each declares.
    let mut scopes = vec![Scope {
        inline_path: Vec::new(),
        children: BTreeSet::new(),
        close: usize::MAX,
    }];
    let mut scope_at_open: HashMap<usize, usize> = HashMap::new();
    let mut file_mods = Vec::new();
    {
        let mut stack = vec![0usize];
        let mut i = 0;
        while i < t.len() {
            while stack.len() > 1 && i > scopes[*stack.last().unwrap_or(&0)].close {
                stack.pop();
            }
            if skip[i] || ident(t.get(i)) != Some("mod") || !matches!(t[i].tok, Tok::Ident(_)) {
                i += 1;
                continue;
            }
            let Some(name) = ident(t.get(i + 1)) else {
                i += 1;
                continue;
            };
            let cur = *stack.last().unwrap_or(&0);
            scopes[cur].children.insert(name.to_string());
            if punct(t.get(i + 2), '{') {
                let close = matching_close(t, i + 2);
                let mut inline_path = scopes[cur].inline_path.clone();
                inline_path.push(name.to_string());
                scopes.push(Scope {
                    inline_path,
                    children: BTreeSet::new(),
                    close,
                });
                scope_at_open.insert(i + 2, scopes.len() - 1);
                stack.push(scopes.len() - 1);
                i += 3;
            } else {
                file_mods.push(ModDecl {
                    inline_path: scopes[cur].inline_path.clone(),
                    name: name.to_string(),
                    path_attr: path_attr_before(t, i),
                });
                i += 2;
            }
        }
    }
    // Pass 2: paths.
    let mut refs = Vec::new();
    // Names a `pub use` binds (→ where it points), and the first line each name is used on
    // outside `use` items: a parent that uses what it re-exports imports it.
    let mut reexported: BTreeMap<String, (Vec<String>, Vec<String>, u32)> = BTreeMap::new();
    let mut first_use: HashMap<String, u32> = HashMap::new();
    let mut stack = vec![0usize];
    let mut i = 0;
    while i < t.len() {
        while stack.len() > 1 && i > scopes[*stack.last().unwrap_or(&0)].close {
            stack.pop();
        }
        if let Some(&s) = scope_at_open.get(&i) {
            stack.push(s);
        }
        if skip[i] {
            i += 1;
            continue;
        }
        let scope = &scopes[*stack.last().unwrap_or(&0)];
        let mut base = file_path.to_vec();
        base.extend(scope.inline_path.iter().cloned());
        let after_sep = i > 0 && matches!(t[i - 1].tok, Tok::PathSep | Tok::Punct('.'));
        if let (false, Some(name)) = (after_sep, ident(t.get(i))) {
            let declared = i > 0 && ident(t.get(i - 1)) == Some("mod");
            let module_path = scope.children.contains(name)
                && matches!(t.get(i + 1).map(|x| &x.tok), Some(Tok::PathSep));
            // A lower-case name (a function) counts where it is called: a variable of the same
            // name is common (`plan: ReplayPlan`).
            let lower = name.starts_with(|c: char| c.is_lowercase());
            let called = punct(t.get(i + 1), '(');
            if !declared && !module_path && (!lower || called) {
                first_use.entry(name.to_string()).or_insert(t[i].line);
            }
        }
        match ident(t.get(i)) {
            Some("use") if !after_sep => {
                let reexport = is_pub_before(t, i);
                let end = (i..t.len())
                    .find(|&k| punct(t.get(k), ';'))
                    .unwrap_or(t.len());
                let mut leaves = Vec::new();
                let mut k = i + 1;
                parse_use_tree(t, &mut k, end, Vec::new(), &mut leaves);
                for (segments, line, binding) in leaves {
                    if relative_start(&segments, &scope.children) {
                        if let (true, Some(name)) = (reexport, binding) {
                            reexported
                                .entry(name)
                                .or_insert_with(|| (base.clone(), segments.clone(), line));
                        }
                        refs.push(Ref {
                            base: base.clone(),
                            text: segments.join("::"),
                            segments,
                            line,
                            reexport,
                        });
                    }
                }
                i = end + 1;
                continue;
            }
            Some(first)
                if !after_sep && matches!(t.get(i + 1).map(|x| &x.tok), Some(Tok::PathSep)) =>
            {
                let dollar = i > 0 && punct(t.get(i - 1), '$');
                // `pub(in crate::a)` restricts visibility, it imports nothing.
                let visibility =
                    i > 1 && ident(t.get(i - 1)) == Some("in") && punct(t.get(i - 2), '(');
                if visibility {
                    i += 1;
                } else if first == "crate"
                    || matches!(first, "super" | "self")
                    || scope.children.contains(first)
                {
                    let mut segments = vec![first.to_string()];
                    let mut k = i + 1;
                    while matches!(t.get(k).map(|x| &x.tok), Some(Tok::PathSep)) {
                        let Some(seg) = ident(t.get(k + 1)) else {
                            break;
                        };
                        segments.push(seg.to_string());
                        k += 2;
                    }
                    let text = if dollar {
                        format!("${}", segments.join("::"))
                    } else {
                        segments.join("::")
                    };
                    refs.push(Ref {
                        base,
                        segments,
                        line: t[i].line,
                        text,
                        reexport: false,
                    });
                    i = k;
                } else {
                    i += 1;
                }
            }
            _ => i += 1,
        }
    }
    for (name, (base, segments, line)) in reexported {
        if let Some(&used) = first_use.get(&name) {
            refs.push(Ref {
                base,
                text: format!(
                    "{name} (`pub use {}` on line {line}, used here)",
                    segments.join("::")
                ),
                segments,
                line: used,
                reexport: false,
            });
        }
    }
    FileScan { refs, file_mods }
}

/// Does a use path start inside this crate (`crate`, `super`, `self`, a declared module)?
fn relative_start(segments: &[String], children: &BTreeSet<String>) -> bool {
    segments
        .first()
        .is_some_and(|s| matches!(s.as_str(), "crate" | "super" | "self") || children.contains(s))
}

/// `pub use`, `pub(crate) use`, `pub(in path) use`.
fn is_pub_before(t: &[Token], use_at: usize) -> bool {
    if use_at == 0 {
        return false;
    }
    let mut k = use_at - 1;
    if punct(t.get(k), ')') {
        // back to the matching `(`
        while k > 0 && !punct(t.get(k), '(') {
            k -= 1;
        }
        if k == 0 {
            return false;
        }
        k -= 1;
    }
    ident(t.get(k)) == Some("pub")
}

/// `#[path = "x"]` among the attributes right before the `mod` at `mod_at` (past visibility).
fn path_attr_before(t: &[Token], mod_at: usize) -> Option<String> {
    let mut k = mod_at;
    if k > 0 && punct(t.get(k - 1), ')') {
        while k > 0 && !punct(t.get(k), '(') {
            k -= 1;
        }
    }
    if k > 0 && ident(t.get(k - 1)) == Some("pub") {
        k -= 1;
    }
    // Attributes, last to first: `# [ .. ]`.
    while k > 0 && punct(t.get(k - 1), ']') {
        let close = k - 1;
        let mut depth = 0i32;
        let mut open = close;
        loop {
            match t[open].tok {
                Tok::Punct(']' | ')' | '}') => depth += 1,
                Tok::Punct('[' | '(' | '{') => depth -= 1,
                _ => {}
            }
            if depth == 0 || open == 0 {
                break;
            }
            open -= 1;
        }
        if ident(t.get(open + 1)) == Some("path")
            && punct(t.get(open + 2), '=')
            && let Some(Token {
                tok: Tok::Str(p), ..
            }) = t.get(open + 3)
        {
            return Some(p.clone());
        }
        if open == 0 || !punct(t.get(open - 1), '#') {
            return None;
        }
        k = open - 1;
    }
    None
}

/// Collects every leaf path of the use tree starting at `*k` (before `end`), with its line and
/// the name it binds (none for a glob or `as _`).
fn parse_use_tree(
    t: &[Token],
    k: &mut usize,
    end: usize,
    prefix: Vec<String>,
    out: &mut Vec<(Vec<String>, u32, Option<String>)>,
) {
    let mut path = prefix;
    if matches!(t.get(*k).map(|x| &x.tok), Some(Tok::PathSep)) {
        // `::std::..`: another crate.
        path.push("::".to_string());
        *k += 1;
    }
    while *k < end {
        let line = t[*k].line;
        match &t[*k].tok {
            Tok::Ident(s) => {
                path.push(s.clone());
                *k += 1;
                if matches!(t.get(*k).map(|x| &x.tok), Some(Tok::PathSep)) {
                    *k += 1;
                    continue;
                }
                let mut binding = if s == "self" {
                    path.iter().rev().nth(1).cloned()
                } else {
                    Some(s.clone())
                };
                if ident(t.get(*k)) == Some("as") {
                    binding = ident(t.get(*k + 1)).map(str::to_string);
                    *k += 2;
                }
                out.push((path, line, binding.filter(|b| b != "_")));
                return;
            }
            Tok::Punct('*') => {
                *k += 1;
                out.push((path, line, None));
                return;
            }
            Tok::Punct('{') => {
                let close = matching_close(t, *k);
                *k += 1;
                while *k < close {
                    let before = *k;
                    parse_use_tree(t, k, close, path.clone(), out);
                    if punct(t.get(*k), ',') || *k == before {
                        *k += 1;
                    }
                }
                *k = close + 1;
                return;
            }
            _ => {
                *k += 1;
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests;
