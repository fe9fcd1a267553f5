//! Scenario errors that name the file, the line and the key. Serde errors carry toml's own span;
//! semantic errors carry a key path that is looked up in the spanned document.

use std::fmt;
use toml::de::{DeTable, DeValue};

/// One step of a key path: a table key or an array index.
#[derive(Clone, Debug, PartialEq)]
pub enum Seg {
    Key(String),
    Index(usize),
}

/// A key path such as `robots[1].sensors.laser.rate`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct KeyPath(pub Vec<Seg>);

impl KeyPath {
    pub fn key(&self, k: &str) -> KeyPath {
        let mut v = self.0.clone();
        v.push(Seg::Key(k.to_string()));
        KeyPath(v)
    }
    pub fn index(&self, i: usize) -> KeyPath {
        let mut v = self.0.clone();
        v.push(Seg::Index(i));
        KeyPath(v)
    }
}

impl fmt::Display for KeyPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, s) in self.0.iter().enumerate() {
            match s {
                Seg::Key(k) if i == 0 => write!(f, "{k}")?,
                Seg::Key(k) => write!(f, ".{k}")?,
                Seg::Index(n) => write!(f, "[{n}]")?,
            }
        }
        Ok(())
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct ScenarioError {
    pub file: String,
    pub line: Option<usize>,
    pub column: Option<usize>,
    pub key: Option<String>,
    pub message: String,
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
            if let Some(c) = self.column {
                write!(f, ":{c}")?;
            }
        }
        write!(f, ": ")?;
        if let Some(k) = &self.key {
            write!(f, "`{k}`: ")?;
        }
        write!(f, "{}", self.message)
    }
}

impl std::error::Error for ScenarioError {}

/// 1-based line and column of a byte offset.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// Byte span of the key (or array element) at `path`, or of its closest existing ancestor.
pub fn span_of(root: &DeTable<'_>, path: &KeyPath) -> Option<std::ops::Range<usize>> {
    let mut best = None;
    let mut table = Some(root);
    let mut value: Option<&DeValue<'_>> = None;
    for seg in &path.0 {
        match seg {
            Seg::Key(k) => {
                let t = match (table, value) {
                    (Some(t), None) => t,
                    (_, Some(DeValue::Table(t))) => t,
                    _ => return best,
                };
                let Some((key, v)) = t
                    .iter()
                    .find(|(key, _)| key.get_ref().as_ref() == k.as_str())
                else {
                    return best;
                };
                best = Some(key.span());
                table = None;
                value = Some(v.get_ref());
            }
            Seg::Index(i) => {
                let Some(DeValue::Array(a)) = value else {
                    return best;
                };
                let Some(v) = a.get(*i) else {
                    return best;
                };
                best = Some(v.span());
                value = Some(v.get_ref());
            }
        }
    }
    best
}

/// Depth-first search for the deepest key whose name or scalar value contains `offset`
/// (tables opened by `[a.b]` headers do not span their contents, so every branch is searched).
fn search(v: &DeValue<'_>, offset: usize, path: &mut KeyPath, best: &mut Option<KeyPath>) {
    match v {
        DeValue::Table(t) => {
            for (k, v) in t.iter() {
                path.0.push(Seg::Key(k.get_ref().to_string()));
                let scalar = !matches!(v.get_ref(), DeValue::Table(_) | DeValue::Array(_));
                if k.span().contains(&offset) || (scalar && v.span().contains(&offset)) {
                    *best = Some(path.clone());
                }
                search(v.get_ref(), offset, path, best);
                path.0.pop();
            }
        }
        DeValue::Array(a) => {
            for (i, item) in a.iter().enumerate() {
                path.0.push(Seg::Index(i));
                let scalar = !matches!(item.get_ref(), DeValue::Table(_) | DeValue::Array(_));
                if scalar && item.span().contains(&offset) {
                    *best = Some(path.clone());
                }
                search(item.get_ref(), offset, path, best);
                path.0.pop();
            }
        }
        _ => {}
    }
}

/// The deepest key whose name or value contains byte `offset`.
pub fn key_at(root: &DeTable<'_>, offset: usize) -> Option<KeyPath> {
    let mut best = None;
    search(
        &DeValue::Table(root.clone()),
        offset,
        &mut KeyPath::default(),
        &mut best,
    );
    best
}

/// Builds errors for one scenario text.
pub struct ErrorContext<'a> {
    pub file: String,
    pub text: &'a str,
    pub doc: Option<DeTable<'a>>,
}

impl<'a> ErrorContext<'a> {
    pub fn new(file: String, text: &'a str) -> Self {
        let doc = DeTable::parse(text).ok().map(|t| t.into_inner());
        ErrorContext { file, text, doc }
    }

    pub fn at(&self, path: &KeyPath, message: impl Into<String>) -> ScenarioError {
        let span = self.doc.as_ref().and_then(|d| span_of(d, path));
        let (line, column) = match span {
            Some(s) => {
                let (l, c) = line_col(self.text, s.start);
                (Some(l), Some(c))
            }
            None => (None, None),
        };
        ScenarioError {
            file: self.file.clone(),
            line,
            column,
            key: Some(path.to_string()),
            message: message.into(),
        }
    }

    pub fn from_toml(&self, e: &toml::de::Error) -> ScenarioError {
        let (line, column) = match e.span() {
            Some(s) => {
                let (l, c) = line_col(self.text, s.start);
                (Some(l), Some(c))
            }
            None => (None, None),
        };
        let key = match (e.span(), &self.doc) {
            (Some(s), Some(doc)) => key_at(doc, s.start).map(|k| k.to_string()),
            _ => None,
        };
        ScenarioError {
            file: self.file.clone(),
            line,
            column,
            key,
            message: e.message().trim().to_string(),
        }
    }
}
