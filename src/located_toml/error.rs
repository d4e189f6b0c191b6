//! A mistake at a spot in a TOML file, whatever the file is for.

use std::io;
use std::path::{Path, PathBuf};

use super::SourceLocation;

/// A hand-written file that could not be read at all: there is no line to point at, only the
/// file and what it was meant to be ("case file", "the rubric").
#[derive(Debug, thiserror::Error)]
#[error("{}: cannot read {what}: {source}", path.display())]
pub struct ReadError {
    pub path: PathBuf,
    pub what: &'static str,
    #[source]
    pub source: io::Error,
}

impl ReadError {
    /// The file's bytes, or why they cannot be had.
    pub fn read(path: &Path, what: &'static str) -> Result<Vec<u8>, ReadError> {
        std::fs::read(path).map_err(|source| ReadError {
            path: path.to_path_buf(),
            what,
            source,
        })
    }

    /// The file as UTF-8 text (text that is not UTF-8 is a read error).
    pub fn read_text(path: &Path, what: &'static str) -> Result<String, ReadError> {
        std::fs::read_to_string(path).map_err(|source| ReadError {
            path: path.to_path_buf(),
            what,
            source,
        })
    }
}

/// What the readers report. It knows nothing of what the file means: the case loader and the
/// rubric loader each wrap it in an error of their own, next to the mistakes only they can find.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LocatedError {
    /// The text is not TOML; `message` is the TOML parser's.
    #[error("{location}: invalid TOML: {message}")]
    Syntax { location: SourceLocation, message: String },
    /// Valid TOML, but not what the reader asked for.
    #[error("{location}: {message}")]
    Invalid { location: SourceLocation, message: String },
}

impl LocatedError {
    pub fn location(&self) -> &SourceLocation {
        match self {
            LocatedError::Syntax { location, .. } | LocatedError::Invalid { location, .. } => location,
        }
    }
}
