//! Why grading could not run at all. Anything wrong with a student's files is a verdict in the
//! report instead (see `Outcome`), so these are only the TA's problems: a bad rubric, a golden
//! that cannot be rendered, a missing submissions folder, a report that cannot be written.

use std::io;
use std::path::PathBuf;

use crate::case::CaseError;
use crate::film::OutputError;
use crate::located_toml::{LocatedError, ReadError, SourceLocation};

#[derive(Debug, thiserror::Error)]
pub enum GradeError {
    /// The rubric cannot be read, has a mistake, or names a render that does not load.
    #[error(transparent)]
    Rubric(#[from] RubricError),

    #[error("{location}: render `{render}` cannot be rendered: {source}")]
    Golden {
        location: SourceLocation,
        render: String,
        #[source]
        source: Box<crate::Error>,
    },

    #[error("{}: cannot list the submissions: {source}", path.display())]
    Submissions {
        path: PathBuf,
        #[source]
        source: io::Error,
    },

    #[error("cannot write the report: {0}")]
    Write(#[from] OutputError),

    /// Shard outputs that do not make one class: missing, overlapping, or made with another
    /// rubric, golden renders or goldray.
    #[error("cannot merge: {0}")]
    Merge(String),

    #[error("cannot start worker threads: {0}")]
    Threads(#[from] rayon::ThreadPoolBuildError),
}

/// Why a rubric could not be loaded, found before anything renders.
#[derive(Debug, thiserror::Error)]
pub enum RubricError {
    #[error(transparent)]
    Read(#[from] ReadError),

    /// A mistake inside the rubric, located at `file:line:column`.
    #[error(transparent)]
    Toml(#[from] LocatedError),

    /// Something absent from the rubric, which therefore has no line to point at.
    #[error("{}: {message}", file.display())]
    Missing { file: PathBuf, message: String },

    /// The case or course scene a `[render.NAME]` table points at does not load.
    #[error("{location}: render `{render}`: {source}")]
    Source {
        location: SourceLocation,
        render: String,
        #[source]
        source: Box<CaseError>,
    },
}
