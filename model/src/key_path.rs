//! Key paths: dotted paths into a model TOML, as study grids and
//! `[output] sensitivity` name model values, and their lookups.
//!
//! A key is a dotted path into the model TOML. A segment names a table key;
//! `name[i]` takes entry `i` (from 0) of the array `name`; a segment after an
//! array of tables picks the entry whose `name` field equals it
//! (`joint.screw.pitch`). A segment may be double-quoted to hold dots
//! (`joint."arm.pin".pitch`).

use std::fmt;

use toml::{Table, Value};

/// One step of a [`KeyPath`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Segment {
    /// A table key, or the `name` of an entry of an array of tables.
    Key(String),
    /// An array index, from 0.
    Index(usize),
}

/// A parsed grid key such as `joint.screw.pitch` or `beam[0].elements`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeyPath {
    /// The segments, in order.
    pub segments: Vec<Segment>,
}

impl KeyPath {
    /// The path as words: each key segment, with its indices attached
    /// (`section.rod.EI[0]` → `section`, `rod`, `EI[0]`).
    pub fn words(&self) -> Vec<String> {
        let mut words: Vec<String> = Vec::new();
        for s in &self.segments {
            match (s, words.last_mut()) {
                (Segment::Index(i), Some(last)) => last.push_str(&format!("[{i}]")),
                (Segment::Index(i), None) => words.push(format!("[{i}]")),
                (Segment::Key(k), _) => words.push(k.clone()),
            }
        }
        words
    }

    /// Parses `key`; the error says what is wrong with its syntax.
    pub fn parse(key: &str) -> Result<Self, String> {
        let mut segments = Vec::new();
        let mut rest = key;
        loop {
            // One segment: a bare or quoted name, then any number of [i].
            let name;
            if let Some(quoted) = rest.strip_prefix('"') {
                let end = quoted
                    .find('"')
                    .ok_or_else(|| "has an unclosed '\"'".to_owned())?;
                name = &quoted[..end];
                rest = &quoted[end + 1..];
            } else {
                let end = rest.find(['.', '[']).unwrap_or(rest.len());
                name = &rest[..end];
                rest = &rest[end..];
            }
            if name.is_empty() {
                return Err("has an empty segment (write keys as a.b.c or name[0].c)".into());
            }
            segments.push(Segment::Key(name.to_owned()));
            while let Some(inner) = rest.strip_prefix('[') {
                let end = inner
                    .find(']')
                    .ok_or_else(|| "has an unclosed '['".to_owned())?;
                let index = inner[..end].trim();
                let i = index
                    .parse::<usize>()
                    .ok()
                    .filter(|_| index.bytes().all(|b| b.is_ascii_digit()))
                    .ok_or_else(|| format!("has index [{index}], expected a whole number"))?;
                segments.push(Segment::Index(i));
                rest = &inner[end + 1..];
            }
            if rest.is_empty() {
                return Ok(Self { segments });
            }
            rest = rest
                .strip_prefix('.')
                .ok_or_else(|| format!("has \"{rest}\" after a segment, expected '.' or '['"))?;
        }
    }
}

impl fmt::Display for KeyPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, s) in self.segments.iter().enumerate() {
            match s {
                Segment::Key(k) => {
                    if i > 0 {
                        write!(f, ".")?;
                    }
                    if k.contains(['.', '[', ']']) {
                        write!(f, "\"{k}\"")?;
                    } else {
                        write!(f, "{k}")?;
                    }
                }
                Segment::Index(n) => write!(f, "[{n}]")?,
            }
        }
        Ok(())
    }
}

fn type_name(v: &Value) -> &'static str {
    match v {
        Value::String(_) => "a string",
        Value::Integer(_) => "an integer",
        Value::Float(_) => "a float",
        Value::Boolean(_) => "a boolean",
        Value::Datetime(_) => "a datetime",
        Value::Array(a) if !a.is_empty() && a.iter().all(Value::is_table) => "an array of tables",
        Value::Array(_) => "an array",
        Value::Table(_) => "a table",
    }
}

fn list(items: impl IntoIterator<Item = String>) -> String {
    let items: Vec<String> = items.into_iter().collect();
    if items.is_empty() {
        "(none)".into()
    } else {
        items.join(", ")
    }
}

/// Finds the value `path` addresses in `root`. The error describes the first
/// segment that does not exist and what exists there instead.
pub fn lookup_mut<'a>(root: &'a mut Table, path: &KeyPath) -> Result<&'a mut Value, String> {
    let mut prefix = String::new();
    let (first, rest) = match path.segments.split_first() {
        Some((Segment::Key(k), rest)) => (k, rest),
        _ => return Err("is empty".into()),
    };
    let keys: Vec<String> = root.keys().cloned().collect();
    let mut current = root.get_mut(first).ok_or_else(|| {
        format!(
            "the model has no top-level key `{first}`; it has: {}",
            list(keys)
        )
    })?;
    prefix.push_str(first);
    for segment in rest {
        current = match (segment, current) {
            (Segment::Key(k), Value::Table(t)) => {
                let keys: Vec<String> = t.keys().cloned().collect();
                let next = t.get_mut(k).ok_or_else(|| {
                    format!(
                        "the model has no key `{prefix}.{k}`; keys in `{prefix}`: {}",
                        list(keys)
                    )
                })?;
                prefix = format!("{prefix}.{k}");
                next
            }
            (Segment::Key(k), Value::Array(entries)) => {
                let names: Vec<Option<&str>> = entries
                    .iter()
                    .map(|e| e.get("name").and_then(Value::as_str))
                    .collect();
                let hits: Vec<usize> = (0..names.len())
                    .filter(|&i| names[i] == Some(k.as_str()))
                    .collect();
                match hits.as_slice() {
                    [i] => {
                        prefix = format!("{prefix}.{k}");
                        &mut entries[*i]
                    }
                    [] => {
                        let existing = names.iter().flatten().map(|n| format!("\"{n}\""));
                        return Err(format!(
                            "the model has no [[{prefix}]] entry named \"{k}\"; entries: {} \
                             (or address one by position, {prefix}[0] to {prefix}[{}])",
                            list(existing),
                            names.len().saturating_sub(1)
                        ));
                    }
                    _ => {
                        return Err(format!(
                            "several [[{prefix}]] entries are named \"{k}\"; address one by \
                             position, e.g. {prefix}[{}]",
                            hits[0]
                        ))
                    }
                }
            }
            (Segment::Index(i), Value::Array(entries)) => {
                let n = entries.len();
                let next = entries.get_mut(*i).ok_or_else(|| {
                    format!(
                        "`{prefix}` has {n} entries, so [{i}] does not exist (indices count from 0)"
                    )
                })?;
                prefix = format!("{prefix}[{i}]");
                next
            }
            (Segment::Key(k), other) => {
                return Err(format!(
                    "`{prefix}` is {}, so it has no key `{k}`",
                    type_name(other)
                ))
            }
            (Segment::Index(i), other) => {
                return Err(format!(
                    "`{prefix}` is {}, not an array, so [{i}] does not exist",
                    type_name(other)
                ))
            }
        };
    }
    if current.is_table()
        || matches!(current, Value::Array(a) if !a.is_empty() && a.iter().all(Value::is_table))
    {
        return Err(format!(
            "`{prefix}` is {}; a grid key must name a single value inside it",
            type_name(current)
        ));
    }
    Ok(current)
}

/// Checks that `path` addresses a value of the model table `model`; the
/// error says what exists instead.
pub fn check_key(model: &Table, path: &KeyPath) -> Result<(), String> {
    let mut copy = model.clone();
    lookup_mut(&mut copy, path).map(|_| ())
}
