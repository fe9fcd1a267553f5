//! The token stream of a source file: identifiers, `::`, punctuation and string literals;
//! comments, chars, numbers and lifetimes are dropped or reduced to one token.

#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum Tok {
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
pub(super) struct Token {
    pub(super) tok: Tok,
    pub(super) line: u32,
}

pub(super) fn is_ident_start(c: char) -> bool {
    c.is_alphabetic() || c == '_'
}

pub(super) fn is_ident_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

pub(super) fn tokenize(text: &str) -> Vec<Token> {
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
pub(super) fn string_start(c: &[char], i: usize) -> Option<(usize, Option<usize>)> {
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
pub(super) fn skip_string(c: &[char], body: usize, raw_hashes: Option<usize>) -> (usize, String) {
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
pub(super) fn skip_char_literal(c: &[char], mut i: usize) -> usize {
    i += 1;
    while i < c.len() && c[i] != '\'' {
        if c[i] == '\\' {
            i += 1;
        }
        i += 1;
    }
    i + 1
}

pub(super) fn ident(t: Option<&Token>) -> Option<&str> {
    match t {
        Some(Token {
            tok: Tok::Ident(s), ..
        }) => Some(s),
        _ => None,
    }
}

pub(super) fn punct(t: Option<&Token>, p: char) -> bool {
    matches!(t, Some(Token { tok: Tok::Punct(q), .. }) if *q == p)
}

/// Index of the bracket closing the one at `open` (or the end).
pub(super) fn matching_close(t: &[Token], open: usize) -> usize {
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
