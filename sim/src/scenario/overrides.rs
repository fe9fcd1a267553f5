//! Parameter overrides: key paths into the scenario TOML (`robots.0.localization.1.particles`,
//! `robots[name=r1].sensors.laser.rate`) applied to the parsed document with toml_edit, so the
//! file keeps its layout and the overridden text goes through the normal scenario loading and
//! validation, exactly like a scenario file.

use toml_edit::{DocumentMut, InlineTable, Item, TableLike, Value};

/// One step of a key path.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// A table key; on an array, a key made of digits is an index (`robots.0`).
    Key(String),
    /// `[N]`.
    Index(usize),
    /// `[key=value]`: the array item whose `key` equals `value` (`robots[name=r1]`).
    Select { key: String, value: String },
}

/// One `key=value` of a `--set`, `--sweep` or `--zip`.
#[derive(Clone, Debug)]
pub struct Override {
    /// The flag it came from, for messages.
    pub flag: &'static str,
    /// The key as given.
    pub key: String,
    pub path: Vec<Step>,
    /// The value as given.
    pub text: String,
    pub value: Value,
}

fn bare_key(k: &str) -> bool {
    !k.is_empty()
        && k.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// Most parts (keys and array items) an override's key may have.
pub const MAX_KEY_PARTS: usize = 32;

/// Parses a key path: keys separated by dots, array items as `.N`, `[N]` or `[key=value]`.
/// A key or value as messages show it: whole up to 80 characters, else its first 60 and `…`.
fn shorten(text: &str) -> String {
    if text.chars().count() > 80 {
        text.chars().take(60).chain("…".chars()).collect()
    } else {
        text.to_string()
    }
}

pub fn parse_path(flag: &str, key: &str) -> anyhow::Result<Vec<Step>> {
    let shown = shorten(key);
    let bad = |why: &str| {
        anyhow::anyhow!(
            "{flag} {shown}: {why} (expected keys separated by dots, array items as .N, [N] or \
             [name=VALUE], e.g. robots[name=r1].sensors.laser.rate)"
        )
    };
    // scenario keys have a handful of parts; one of thousands would recurse as deep when
    // applied and overflow the stack
    let parts = key.split('.').count() + key.matches('[').count();
    if parts > MAX_KEY_PARTS {
        return Err(bad(&format!(
            "{parts} parts, more than any scenario key has (at most {MAX_KEY_PARTS})"
        )));
    }
    let mut steps = Vec::new();
    for part in key.split('.') {
        let (base, mut rest) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        if base.is_empty() && (rest.is_empty() || steps.is_empty()) {
            return Err(bad("empty key"));
        }
        if !base.is_empty() {
            if !bare_key(base) {
                return Err(bad(&format!(
                    "`{base}` is not a key (letters, digits, _ and - only)"
                )));
            }
            steps.push(Step::Key(base.to_string()));
        }
        while !rest.is_empty() {
            let close = rest
                .find(']')
                .filter(|_| rest.starts_with('['))
                .ok_or_else(|| bad(&format!("unbalanced brackets in `{part}`")))?;
            let inner = &rest[1..close];
            rest = &rest[close + 1..];
            if let Ok(i) = inner.trim().parse::<usize>() {
                steps.push(Step::Index(i));
            } else if let Some((k, v)) = inner.split_once('=') {
                let (k, v) = (k.trim(), v.trim().trim_matches(|c| c == '"' || c == '\''));
                if !bare_key(k) || v.is_empty() {
                    return Err(bad(&format!("bad selector `[{inner}]`")));
                }
                steps.push(Step::Select {
                    key: k.to_string(),
                    value: v.to_string(),
                });
            } else {
                return Err(bad(&format!("bad selector `[{inner}]`")));
            }
        }
    }
    Ok(steps)
}

/// A value as TOML (number, bool, string, array, inline table), or else the text as a string.
pub fn parse_value(text: &str) -> Value {
    text.parse::<Value>()
        .unwrap_or_else(|_| Value::from(text.to_string()))
}

impl Override {
    pub fn new(flag: &'static str, key: &str, text: &str) -> anyhow::Result<Override> {
        let path = parse_path(flag, key)?;
        Ok(Override {
            flag,
            key: key.to_string(),
            path,
            text: text.to_string(),
            value: parse_value(text),
        })
    }

    /// Whether it sets the scenario's top-level `seed`.
    pub fn is_seed(&self) -> bool {
        matches!(self.path.as_slice(), [Step::Key(k)] if k == "seed")
    }

    /// How it was given: `--sweep key=value` (a key or value of over 80 characters
    /// shortened).
    pub fn describe(&self) -> String {
        format!(
            "{} {}={}",
            self.flag,
            shorten(&self.key),
            shorten(&self.text)
        )
    }

    /// Sets the value in `doc`; returns the path with every array item as its index
    /// (`robots[0].sensors.laser.rate`), as scenario errors name keys.
    pub fn apply(&self, doc: &mut DocumentMut) -> anyhow::Result<String> {
        let mut at = String::new();
        set_in_table(doc.as_table_mut(), &self.path, self.value.clone(), &mut at)
            .map_err(|e| anyhow::anyhow!("{}: {e}", self.describe()))?;
        Ok(at)
    }
}

fn push_key(at: &mut String, k: &str) {
    if !at.is_empty() {
        at.push('.');
    }
    at.push_str(k);
}

fn value_kind(v: &Value) -> &'static str {
    match v {
        Value::String(_) => "a string",
        Value::Integer(_) => "an integer",
        Value::Float(_) => "a number",
        Value::Boolean(_) => "a boolean",
        Value::Datetime(_) => "a date",
        Value::Array(_) => "an array",
        Value::InlineTable(_) => "a table",
    }
}

/// Keeps the spacing and comment around a replaced value.
fn replace_value(old: &mut Value, mut new: Value) {
    *new.decor_mut() = old.decor().clone();
    *old = new;
}

fn set_in_table(
    t: &mut dyn TableLike,
    steps: &[Step],
    v: Value,
    at: &mut String,
) -> Result<(), String> {
    let (step, rest) = steps.split_first().ok_or("empty key")?;
    let Step::Key(k) = step else {
        let what = if at.is_empty() { "the scenario" } else { at };
        return Err(format!("`{what}` is a table, not an array: use .KEY"));
    };
    push_key(at, k);
    if rest.is_empty() {
        match t.get_mut(k) {
            Some(Item::Value(old)) => replace_value(old, v),
            Some(item) => *item = Item::Value(v),
            None => {
                t.insert(k, Item::Value(v));
            }
        }
        return Ok(());
    }
    if t.get(k).is_none() {
        t.insert(k, Item::Value(Value::InlineTable(InlineTable::new())));
    }
    match t.get_mut(k) {
        Some(item) => set_in_item(item, rest, v, at),
        None => Err(format!("cannot create `{at}`")),
    }
}

/// The index `step` selects among `len` items (`name_of(i)` is item i's value of a selector key).
fn item_index(
    step: &Step,
    len: usize,
    at: &str,
    value_of: impl Fn(usize, &str) -> Option<String>,
) -> Result<usize, String> {
    let i = match step {
        Step::Index(i) => *i,
        Step::Key(k) => k.parse::<usize>().map_err(|_| {
            format!("`{at}` is an array: select an item with {at}.N, {at}[N] or {at}[name=VALUE]")
        })?,
        Step::Select { key, value } => {
            return (0..len)
                .find(|&i| value_of(i, key).as_deref() == Some(value.as_str()))
                .ok_or_else(|| {
                    let have: Vec<String> = (0..len).filter_map(|i| value_of(i, key)).collect();
                    format!(
                        "`{at}` has no item with {key} = {value} (its items' {key}: {})",
                        if have.is_empty() {
                            "none".to_string()
                        } else {
                            have.join(", ")
                        }
                    )
                });
        }
    };
    if i >= len {
        return Err(format!(
            "`{at}` has {len} item{}: index {i} is out of range",
            if len == 1 { "" } else { "s" }
        ));
    }
    Ok(i)
}

/// Whether `step` is the index one past the end of an array of `len` items (which adds one).
fn appends(step: &Step, len: usize) -> bool {
    match step {
        Step::Index(i) => *i == len,
        Step::Key(k) => k.parse::<usize>().is_ok_and(|i| i == len),
        Step::Select { .. } => false,
    }
}

fn scalar_text(v: Option<&Value>) -> Option<String> {
    match v? {
        Value::String(s) => Some(s.value().clone()),
        Value::Array(_) | Value::InlineTable(_) => None,
        other => Some(other.to_string().trim().to_string()),
    }
}

fn set_in_item(item: &mut Item, steps: &[Step], v: Value, at: &mut String) -> Result<(), String> {
    match item {
        Item::Table(t) => set_in_table(t, steps, v, at),
        Item::ArrayOfTables(a) => {
            let len = a.len();
            if appends(&steps[0], len) {
                // one past the end: a new item, the whole table or its first key
                a.push(toml_edit::Table::new());
                at.push_str(&format!("[{len}]"));
                let t = a.get_mut(len).ok_or_else(|| format!("`{at}` is missing"))?;
                return match (&steps[1..], v) {
                    ([], Value::InlineTable(it)) => {
                        for (k, item) in it.iter() {
                            t.insert(k, Item::Value(item.clone()));
                        }
                        Ok(())
                    }
                    ([], other) => Err(format!(
                        "`{at}` adds an item to an array of tables: give a table \
                         ({at}={{type=\"..\", ..}}), not {}",
                        value_kind(&other)
                    )),
                    (rest, v) => set_in_table(t, rest, v, at),
                };
            }
            let i = item_index(&steps[0], len, at, |i, key| {
                scalar_text(a.get(i)?.get(key)?.as_value())
            })?;
            at.push_str(&format!("[{i}]"));
            let Some(t) = a.get_mut(i) else {
                return Err(format!("`{at}` is missing"));
            };
            match &steps[1..] {
                [] => Err(format!(
                    "`{at}` is a whole table: set one of its keys ({at}.KEY=VALUE)"
                )),
                rest => set_in_table(t, rest, v, at),
            }
        }
        Item::Value(val) => set_in_value(val, steps, v, at),
        Item::None => Err(format!("`{at}` is missing")),
    }
}

fn set_in_value(val: &mut Value, steps: &[Step], v: Value, at: &mut String) -> Result<(), String> {
    match val {
        Value::InlineTable(t) => set_in_table(t, steps, v, at),
        Value::Array(a) => {
            let len = a.len();
            if appends(&steps[0], len) && steps.len() == 1 {
                at.push_str(&format!("[{len}]"));
                a.push_formatted(v);
                return Ok(());
            }
            let i = item_index(&steps[0], len, at, |i, key| {
                scalar_text(a.get(i)?.as_inline_table()?.get(key))
            })?;
            at.push_str(&format!("[{i}]"));
            let Some(item) = a.get_mut(i) else {
                return Err(format!("`{at}` is missing"));
            };
            match &steps[1..] {
                [] => {
                    replace_value(item, v);
                    Ok(())
                }
                rest => set_in_value(item, rest, v, at),
            }
        }
        other => Err(format!(
            "`{at}` is {}, not a table or an array: it has no `{}`",
            value_kind(other),
            match &steps[0] {
                Step::Key(k) => k.clone(),
                Step::Index(i) => format!("[{i}]"),
                Step::Select { key, value } => format!("[{key}={value}]"),
            }
        )),
    }
}

/// The overrides a scenario error is about: those whose resolved path (see
/// [`Override::apply`]) lies on the error's key path, or under it.
pub fn blame<'a>(overrides: &'a [(Override, String)], error_key: &str) -> Vec<&'a Override> {
    let under = |long: &str, short: &str| {
        long == short
            || long
                .strip_prefix(short)
                .is_some_and(|r| r.starts_with('.') || r.starts_with('['))
    };
    overrides
        .iter()
        .filter(|(_, at)| under(at, error_key) || under(error_key, at))
        .map(|(o, _)| o)
        .collect()
}

#[cfg(test)]
mod tests;
