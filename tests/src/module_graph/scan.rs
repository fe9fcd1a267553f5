//! One file's module declarations and the paths it names (`use` trees and paths in code),
//! relative to the scope they appear in.

use super::tokens::*;
use std::collections::{BTreeMap, BTreeSet, HashMap};

/// A path found in a file, not yet resolved.
pub(super) struct Ref {
    /// The module the path is relative to (file module, then inline modules).
    pub(super) base: Vec<String>,
    /// The path as written (`crate`, `super`, `self`, names).
    pub(super) segments: Vec<String>,
    pub(super) line: u32,
    pub(super) text: String,
    pub(super) reexport: bool,
}

/// An out-of-line `mod name;`.
pub(super) struct ModDecl {
    /// Inline modules around the declaration (usually none).
    pub(super) inline_path: Vec<String>,
    pub(super) name: String,
    pub(super) path_attr: Option<String>,
}

pub(super) struct FileScan {
    pub(super) refs: Vec<Ref>,
    pub(super) file_mods: Vec<ModDecl>,
}

/// A scope: the file itself or an inline `mod x { .. }`.
pub(super) struct Scope {
    /// Inline module names from the file module down.
    pub(super) inline_path: Vec<String>,
    /// Modules declared directly in this scope (file or inline).
    pub(super) children: BTreeSet<String>,
    /// Token index of the `}` that ends it.
    pub(super) close: usize,
}

pub(super) fn scan_file(t: &[Token], skip: &[bool], file_path: &[String]) -> FileScan {
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
pub(super) fn relative_start(segments: &[String], children: &BTreeSet<String>) -> bool {
    segments
        .first()
        .is_some_and(|s| matches!(s.as_str(), "crate" | "super" | "self") || children.contains(s))
}

/// `pub use`, `pub(crate) use`, `pub(in path) use`.
pub(super) fn is_pub_before(t: &[Token], use_at: usize) -> bool {
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
pub(super) fn path_attr_before(t: &[Token], mod_at: usize) -> Option<String> {
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
pub(super) fn parse_use_tree(
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
