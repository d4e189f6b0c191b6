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

pub use self::error::LocatedError;
pub use self::location::SourceLocation;
pub(crate) use self::reader::{Field, Table};
pub(crate) use self::suggest::suggest;

pub(crate) type Result<T> = std::result::Result<T, LocatedError>;

/// Parses `text` into the tree the readers walk; `file` names it in the syntax error.
pub(crate) fn parse<'i>(text: &'i str, file: &Path) -> Result<Spanned<DeTable<'i>>> {
    DeTable::parse(text).map_err(|e| LocatedError::Syntax {
        location: SourceLocation::from_offset(file, text, e.span().map_or(0, |s| s.start)),
        message: e.message().to_owned(),
    })
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
