//! A mistake at a spot in a TOML file, whatever the file is for.

use super::SourceLocation;

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
