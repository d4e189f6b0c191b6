//! Where in a file something is, as a person editing it counts.

use std::fmt;
use std::path::{Path, PathBuf};

/// A position in a file, 1-based. Columns count characters rather than bytes so that they match
/// what an editor shows on lines with non-ASCII text.
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
