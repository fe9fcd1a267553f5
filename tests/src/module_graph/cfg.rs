//! Test-only code: the tokens of items, statements and fields under a test-only `#[cfg(..)]`,
//! which the graph skips.

use super::tokens::*;

pub(super) struct TestOnly {
    /// Per token: inside an item (or statement, field) under a test-only `#[cfg]`.
    pub(super) skip: Vec<bool>,
    /// The file starts with `#![cfg(test)]`.
    pub(super) first_is_inner_test_cfg: bool,
}

/// Three-valued cfg predicate with `test` false and every other option unknown.
pub(super) fn eval_cfg(t: &[Token], i: &mut usize) -> Option<bool> {
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
pub(super) fn is_test_only_cfg(t: &[Token], open: usize) -> bool {
    if ident(t.get(open + 1)) != Some("cfg") || !punct(t.get(open + 2), '(') {
        return false;
    }
    let mut i = open + 3;
    eval_cfg(t, &mut i) == Some(false)
}

pub(super) fn test_only_tokens(t: &[Token]) -> TestOnly {
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
pub(super) fn item_end(t: &[Token], mut i: usize) -> usize {
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
