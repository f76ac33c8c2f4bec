//! From byte offsets to line numbers and key paths, for error messages.

use std::path::Path;

use std::ops::Range;
use toml::de::{DeTable, DeValue};
use toml::Spanned;

use super::error::ModelError;
use super::raw::ARRAY_TABLES;

/// The 1-based line holding byte `offset` of `text`.
pub(crate) fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The 1-based column (in characters) of byte `offset` of `text`.
fn column_of(text: &str, offset: usize) -> usize {
    let mut end = offset.min(text.len());
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    let line_start = text[..end].rfind('\n').map_or(0, |i| i + 1);
    text[line_start..end].chars().count() + 1
}

/// One step of a key path.
enum Seg {
    Key(String),
    Index(usize),
}

fn render(path: &[Seg]) -> String {
    let mut out = String::new();
    for seg in path {
        match seg {
            Seg::Key(k) => {
                if !out.is_empty() {
                    out.push('.');
                }
                out.push_str(k);
            }
            Seg::Index(i) => out.push_str(&format!("[{i}]")),
        }
    }
    out
}

fn walk_table(table: &DeTable<'_>, offset: usize, path: &mut Vec<Seg>) -> bool {
    for (key, value) in table.iter() {
        path.push(Seg::Key(key.get_ref().to_string()));
        // Look inside first: the span of a `[table]` or `[[table]]` is its header
        // only, so its keys lie outside it.
        if walk_value(value, offset, path)
            || key.span().contains(&offset)
            || value.span().contains(&offset)
        {
            return true;
        }
        path.pop();
    }
    false
}

fn walk_value(value: &Spanned<DeValue<'_>>, offset: usize, path: &mut Vec<Seg>) -> bool {
    match value.get_ref() {
        DeValue::Table(table) => walk_table(table, offset, path),
        DeValue::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                path.push(Seg::Index(i));
                if walk_value(item, offset, path) || item.span().contains(&offset) {
                    return true;
                }
                path.pop();
            }
            false
        }
        _ => false,
    }
}

/// The key path (`beam[1].arc.sweep`) of the key or value at byte `offset`,
/// found in the (possibly partial) parse of `text`; falls back to the enclosing
/// `[table]` header found by reading the text.
pub(crate) fn key_path_at(text: &str, offset: usize) -> String {
    let (doc, _) = DeTable::parse_recoverable(text);
    let mut path = Vec::new();
    if walk_table(doc.get_ref(), offset, &mut path) {
        return render(&path);
    }
    header_path_before(text, offset)
}

/// Reads the text up to `offset` for the last table header, counting
/// `[[array]]` headers to give the entry's index, and adds the bare key of the
/// line holding `offset` if it has one.
fn header_path_before(text: &str, offset: usize) -> String {
    let end = offset.min(text.len());
    let mut counts: Vec<(String, usize)> = Vec::new();
    let mut current = String::new();
    let mut line_start = 0;
    for line in text.split_inclusive('\n') {
        let this_start = line_start;
        line_start += line.len();
        let trimmed = line.trim();
        if this_start > end {
            break;
        }
        if let Some((is_array, name)) = table_header(trimmed) {
            if is_array {
                let index = match counts.iter_mut().find(|(n, _)| *n == name) {
                    Some((_, c)) => {
                        *c += 1;
                        *c - 1
                    }
                    None => {
                        counts.push((name.clone(), 1));
                        0
                    }
                };
                current = format!("{name}[{index}]");
            } else {
                current = name;
            }
        } else if end < line_start || line_start == text.len() {
            // The line holding the offset: add its key.
            if let Some((key, _)) = trimmed.split_once('=') {
                let key = key.trim();
                if !key.is_empty()
                    && key
                        .chars()
                        .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.')
                {
                    return if current.is_empty() {
                        key.to_string()
                    } else {
                        format!("{current}.{key}")
                    };
                }
            }
        }
    }
    current
}

/// `Some((is_array_of_tables, name))` if the trimmed line looks like a table
/// header (`[a.b]` or `[[a]]`, optionally followed by a comment), not like a row
/// of a multi-line array.
fn table_header(trimmed: &str) -> Option<(bool, String)> {
    let (is_array, rest) = match trimmed.strip_prefix("[[") {
        Some(rest) => (true, rest),
        None => (false, trimmed.strip_prefix('[')?),
    };
    let close = if is_array { "]]" } else { "]" };
    let (inner, after) = rest.split_once(close)?;
    let after = after.trim();
    let key_like = !inner.trim().is_empty()
        && inner
            .chars()
            .all(|c| c.is_alphanumeric() || "_-. \"'".contains(c));
    (key_like && (after.is_empty() || after.starts_with('#')))
        .then(|| (is_array, inner.trim().to_string()))
}

/// Makes serde's wording read as model-file wording.
fn reword(message: &str) -> String {
    without_type_names(message)
        .replace("unknown field", "unknown key")
        .replace("missing field", "missing key")
        .replace("duplicate field", "duplicate key")
        .replace("expected f64", "expected a number")
        .replace("expected i64", "expected an integer")
        .replace("expected usize", "expected a non-negative integer")
        .replace("expected a sequence", "expected a list")
}

/// Replaces the loader's internal type names (`struct RawBeam with 8
/// elements`) by what the file should hold (`a table of keys`).
fn without_type_names(message: &str) -> String {
    let mut out = message.to_string();
    while let Some(start) = out.find("struct Raw") {
        let rest = &out[start + "struct ".len()..];
        let name_len = rest
            .find(|c: char| !c.is_alphanumeric())
            .unwrap_or(rest.len());
        let mut end = start + "struct ".len() + name_len;
        if let Some(tail) = out[end..].strip_prefix(" with ") {
            if let Some(n) = tail.find(" elements") {
                if tail[..n].bytes().all(|b| b.is_ascii_digit()) {
                    end += " with ".len() + n + " elements".len();
                }
            }
        }
        out.replace_range(start..end, "a table (keys = values)");
    }
    out
}

/// Turns a TOML syntax error into a [`ModelError`].
pub(crate) fn syntax_error(text: &str, file: &Path, err: &toml::de::Error) -> ModelError {
    let span = err.span();
    let line = span.as_ref().map(|s| line_of(text, s.start));
    let key = span
        .as_ref()
        .map(|s| header_path_before(text, s.start))
        .unwrap_or_default();
    let column = span
        .as_ref()
        .map(|s| format!(" at column {}", column_of(text, s.start)))
        .unwrap_or_default();
    let mut message = format!("TOML syntax error{column}: {}", err.message());
    if err.message().contains("duplicate key") && ARRAY_TABLES.contains(&key.as_str()) {
        message.push_str(&format!(
            "; each entry of `{key}` needs its own [[{key}]] header (double brackets)"
        ));
    }
    ModelError::new(file, key, line, message)
}

/// Turns a deserialisation error (unknown key, wrong type, ...) into a
/// [`ModelError`] naming the key path.
pub(crate) fn deserialize_error(text: &str, file: &Path, err: &toml::de::Error) -> ModelError {
    let span = err.span();
    let line = span.as_ref().map(|s| line_of(text, s.start));
    let mut key = span
        .as_ref()
        .map(|s| key_path_at(text, s.start))
        .unwrap_or_default();
    let mut message = reword(err.message());
    if ARRAY_TABLES.contains(&key.as_str()) && message.contains("expected a list") {
        message.push_str(&format!(
            "; `{key}` is an array of tables: write [[{key}]] (double brackets)"
        ));
    }
    for single in ["solver", "output"] {
        let array = key.starts_with(&format!("{single}["));
        if array || (key == single && message.contains("invalid type")) {
            message = if array {
                format!("`{single}` is a single table: write [{single}], not [[{single}]]")
            } else {
                format!(
                    "`{single}` must be a table: write a [{single}] section with its keys below it"
                )
            };
            key = single.to_string();
        }
    }
    ModelError::new(file, key, line, message)
}

/// The span of the key (or, for an array entry, the item) at the key path
/// `path` (`joint[0].lift.table[2]`) in `text`, if it is there.
pub(crate) fn span_at(text: &str, path: &str) -> Option<Range<usize>> {
    let (doc, _) = DeTable::parse_recoverable(text);
    let mut segs = Vec::new();
    for part in path.split('.') {
        let (key, mut rest) = part.split_once('[').map_or((part, ""), |(k, r)| (k, r));
        segs.push(Seg::Key(key.to_string()));
        while let Some((index, tail)) = rest.split_once(']') {
            segs.push(Seg::Index(index.parse().ok()?));
            rest = tail.strip_prefix('[').unwrap_or(tail);
        }
    }
    let mut table = doc.get_ref();
    let mut current: Option<&Spanned<DeValue<'_>>> = None;
    let mut span = None;
    for seg in &segs {
        match seg {
            Seg::Key(k) => {
                if let Some(v) = current {
                    match v.get_ref() {
                        DeValue::Table(t) => table = t,
                        _ => return None,
                    }
                }
                let (key, value) = table.iter().find(|(key, _)| key.get_ref() == k)?;
                span = Some(key.span());
                current = Some(value);
            }
            Seg::Index(i) => match current?.get_ref() {
                DeValue::Array(items) => {
                    let item = items.get(*i)?;
                    span = Some(item.span());
                    current = Some(item);
                }
                _ => return None,
            },
        }
    }
    span
}
