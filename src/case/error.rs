//! Errors that point at the spot in the case file a person has to edit.

use std::fmt;
use std::io;
use std::path::{Path, PathBuf};

/// A position in a case file, 1-based. Columns count characters rather than bytes so that they
/// match what an editor shows on lines with non-ASCII text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SourceLocation {
    pub file: PathBuf,
    pub line: usize,
    pub column: usize,
}

impl SourceLocation {
    /// Converts a byte offset from toml's spans. The offset is clamped to the text and to a
    /// character boundary instead of trusted, so that no span can make error reporting panic.
    pub(crate) fn from_offset(file: &Path, text: &str, offset: usize) -> Self {
        let mut end = offset.min(text.len());
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        let before = &text[..end];
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        SourceLocation {
            file: file.to_path_buf(),
            line: before.matches('\n').count() + 1,
            column: before[line_start..].chars().count() + 1,
        }
    }
}

impl fmt::Display for SourceLocation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file.display(), self.line, self.column)
    }
}

#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    #[error("{}: cannot read case file: {source}", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: io::Error,
    },
    #[error("{location}: invalid TOML: {message}")]
    Syntax { location: SourceLocation, message: String },
    /// Public so that later stages (loading an OBJ named by `ObjectSpec::location`) can report
    /// their failures in the same `file:line:column` form.
    #[error("{location}: {message}")]
    Invalid { location: SourceLocation, message: String },
    /// Something absent from the file, which therefore has no line to point at.
    #[error("{}: {message}", file.display())]
    Missing { file: PathBuf, message: String },
}

impl CaseError {
    pub fn location(&self) -> Option<&SourceLocation> {
        match self {
            CaseError::Syntax { location, .. } | CaseError::Invalid { location, .. } => Some(location),
            CaseError::Read { .. } | CaseError::Missing { .. } => None,
        }
    }
}

/// The candidate closest to `word`, if close enough that suggesting it is more help than noise.
/// Case is ignored because `Radius` for `radius` is the same slip as a transposition.
pub(crate) fn nearest<'c>(word: &str, candidates: &[&'c str]) -> Option<&'c str> {
    let word = word.to_lowercase();
    let budget = (word.chars().count() / 3).max(1);
    candidates
        .iter()
        .map(|c| (strsim::damerau_levenshtein(&word, &c.to_lowercase()), *c))
        .filter(|&(distance, _)| distance <= budget)
        .min_by_key(|&(distance, _)| distance)
        .map(|(_, c)| c)
}

/// The tail of an "unknown name" message: the nearest candidate if one is close, then all of them,
/// e.g. "; did you mean `radius`? valid keys: center, radius".
pub(crate) fn suggest(word: &str, candidates: &[&str], noun: &str) -> String {
    let all = if candidates.is_empty() {
        "(none)".to_owned()
    } else {
        candidates.join(", ")
    };
    match nearest(word, candidates) {
        Some(c) => format!("; did you mean `{c}`? valid {noun}: {all}"),
        None => format!("; valid {noun}: {all}"),
    }
}
