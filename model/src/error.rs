//! The error type of the model-file loader.

use std::fmt;
use std::path::{Path, PathBuf};

/// Why a model file could not be loaded: which file, which key, where, and what
/// was wrong.
///
/// Displays as ``<file>:<line>: key `<key>`: <message>``, for example
/// ``data/x.toml:12: key `solver.dt`: must be > 0, found -0.01``. The line is left
/// out when it is not known, and the key when the error concerns the whole file
/// (an unreadable file, say).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub struct ModelError {
    file: PathBuf,
    key: String,
    line: Option<usize>,
    message: String,
}

impl ModelError {
    /// An error about key `key` (a path such as `solver.dt` or `joint[0].slave`;
    /// empty for the whole file) of `file`, at 1-based `line` if known.
    pub fn new(
        file: impl Into<PathBuf>,
        key: impl Into<String>,
        line: Option<usize>,
        message: impl Into<String>,
    ) -> Self {
        ModelError {
            file: file.into(),
            key: shorten(&key.into()),
            line,
            message: shorten(&message.into()),
        }
    }

    /// The model file the error is about.
    pub fn file(&self) -> &Path {
        &self.file
    }

    /// The key path, e.g. `solver.dt`, `beam[2].elements`, `joint[0].slave`
    /// (array-of-tables entries are counted from 0 in file order). Empty when the
    /// error concerns the whole file.
    pub fn key(&self) -> &str {
        &self.key
    }

    /// The 1-based line of the offending key or value, when known.
    pub fn line(&self) -> Option<usize> {
        self.line
    }

    /// What was found and what was expected, without the location prefix.
    pub fn message(&self) -> &str {
        &self.message
    }
}

/// Longest word (run of non-blank characters) an error message repeats from
/// the file: a key or value longer than this is cut, with its length told.
const ECHO_WORD: usize = 80;
/// Longest message: the rest is cut, with its length told.
const ECHO_MESSAGE: usize = 4000;

/// Cuts what a message echoes from the file to a readable size (a 1 MB key
/// is quoted by its first characters and its length, not in full).
fn shorten(text: &str) -> String {
    let mut out = String::with_capacity(text.len().min(ECHO_MESSAGE + 64));
    for (k, word) in text.split(' ').enumerate() {
        if k > 0 {
            out.push(' ');
        }
        if word.chars().count() > ECHO_WORD {
            let head: String = word.chars().take(ECHO_WORD / 2).collect();
            out.push_str(&format!("{head}… ({} bytes)", word.len()));
        } else {
            out.push_str(word);
        }
    }
    if out.chars().count() > ECHO_MESSAGE {
        let total = out.len();
        out = out.chars().take(ECHO_MESSAGE).collect();
        out.push_str(&format!("… (message cut, {total} bytes)"));
    }
    out
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        write!(f, ": ")?;
        if !self.key.is_empty() {
            write!(f, "key `{}`: ", self.key)?;
        }
        write!(f, "{}", self.message)
    }
}
