//! Typed, located reads over toml's spanned document tree, for files people write by hand.
//!
//! serde's derive loses spans inside tagged enums and words its own messages, so these files are
//! read by walking `toml::de::DeTable` by hand: every key and value keeps its byte span, and every
//! error can name its file, line and column, quote what was written and say what would be valid
//! (with the nearest valid name when a name is misspelt).
//!
//! Nothing here knows what a file means. Case files ([`crate::case`]) and grading rubrics
//! ([`crate::grade`]) are both read with it, so both report mistakes the same way, and each wraps
//! [`LocatedError`] in its own error type beside the mistakes only it can find.

mod error;
mod location;
mod reader;
mod suggest;

#[cfg(test)]
mod tests;

use std::ops::Range;
use std::path::Path;

use toml::Spanned;
use toml::de::DeTable;

pub use self::error::{LocatedError, ReadError};
pub use self::location::SourceLocation;
pub(crate) use self::reader::{Field, Table};
pub(crate) use self::suggest::suggest;

pub(crate) type Result<T> = std::result::Result<T, LocatedError>;

/// Parses `text` into the tree the readers walk; `file` names it in the syntax error.
pub(crate) fn parse<'i>(text: &'i str, file: &Path) -> Result<Spanned<DeTable<'i>>> {
    DeTable::parse(text).map_err(|e| {
        let at = e.span().map_or(0, |s| s.start);
        let message = match e.message() {
            "duplicate key" => duplicate_key(text, at),
            other => other.to_owned(),
        };
        LocatedError::Syntax {
            location: SourceLocation::from_offset(file, text, at),
            message,
        }
    })
}

/// toml says only "duplicate key"; a person needs the key and where it was first given. `at` is
/// the second occurrence: a key (`bounces = 2`) or a table header (`[render]`).
fn duplicate_key(text: &str, at: usize) -> String {
    let rest = &text[at.min(text.len())..];
    let key: String = rest
        .chars()
        .take_while(|c| !matches!(c, '=' | ']' | '\n' | '\r'))
        .collect::<String>()
        .trim()
        .to_owned();
    if key.is_empty() {
        return "duplicate key".to_owned();
    }
    let is_header = text[..at].trim_end_matches([' ', '\t']).ends_with('[');
    let line_start = text[..at].rfind('\n').map_or(0, |newline| newline + 1);
    let before: Vec<&str> = text[..line_start].lines().collect();
    // A table header may repeat anywhere above; a key only within the table it is in, so the
    // search for it walks back to that table's header.
    let first = before
        .iter()
        .enumerate()
        .rev()
        .take_while(|(_, line)| is_header || !line.trim_start().starts_with('['))
        .filter_map(|(number, line)| {
            let line = line.trim();
            let same = if is_header {
                line.starts_with('[') && line.trim_start_matches('[').trim_end_matches(']').trim() == key
            } else {
                line.strip_prefix(key.as_str())
                    .is_some_and(|after| after.trim_start().starts_with('='))
            };
            same.then_some(number + 1)
        })
        .last();
    let what = if is_header { "table" } else { "key" };
    match first {
        Some(line) => format!("duplicate {what} `{key}`: already given on line {line} (each may appear once)"),
        None => format!("duplicate {what} `{key}` (each may appear once)"),
    }
}

/// What every reader needs to know about the file being read.
pub(crate) struct Doc<'a> {
    pub file: &'a Path,
    pub text: &'a str,
    /// Relative paths written in the file are resolved against this, not the working directory.
    pub dir: &'a Path,
}

impl Doc<'_> {
    pub fn location(&self, offset: usize) -> SourceLocation {
        SourceLocation::from_offset(self.file, self.text, offset)
    }

    pub fn error_at(&self, span: &Range<usize>, message: impl Into<String>) -> LocatedError {
        LocatedError::Invalid {
            location: self.location(span.start),
            message: message.into(),
        }
    }

    /// What the user wrote at `span`, on one line and short enough to quote in a message.
    fn excerpt(&self, span: &Range<usize>) -> String {
        const LIMIT: usize = 60;
        let raw = self.text.get(span.clone()).unwrap_or("");
        let one_line = raw.split_whitespace().collect::<Vec<_>>().join(" ");
        if one_line.chars().count() <= LIMIT {
            one_line
        } else {
            one_line.chars().take(LIMIT - 1).chain(['…']).collect()
        }
    }
}
