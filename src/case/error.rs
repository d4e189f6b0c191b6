//! Errors that point at the spot in the case file a person has to edit.

use std::path::PathBuf;

use crate::located_toml::{LocatedError, ReadError};
// The course-scene importer locates and words its own mistakes with these.
pub(crate) use crate::located_toml::{SourceLocation, suggest};

#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    #[error(transparent)]
    Read(#[from] ReadError),
    /// A mistake in a TOML case file, at its line and column.
    #[error(transparent)]
    Toml(#[from] LocatedError),
    /// A mistake at a spot in a file that is not TOML (a course scene). Public so that later
    /// stages (loading an OBJ named by `ObjectSpec::location`) can report their failures in the
    /// same `file:line:column` form.
    #[error("{location}: {message}")]
    Invalid { location: SourceLocation, message: String },
    /// Something absent from the file, which therefore has no line to point at.
    #[error("{}: {message}", file.display())]
    Missing { file: PathBuf, message: String },
}

impl CaseError {
    pub fn location(&self) -> Option<&SourceLocation> {
        match self {
            CaseError::Toml(error) => Some(error.location()),
            CaseError::Invalid { location, .. } => Some(location),
            CaseError::Read(_) | CaseError::Missing { .. } => None,
        }
    }
}
