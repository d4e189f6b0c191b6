//! Why grading could not run at all. Anything wrong with a student's files is a verdict in the
//! report instead (see `Outcome`), so these are only the TA's problems: a bad rubric, a golden
//! that cannot be rendered, a missing submissions folder, a report that cannot be written.

use std::io;
use std::path::PathBuf;

use crate::case::{CaseError, SourceLocation};
use crate::film::OutputError;

#[derive(Debug, thiserror::Error)]
pub enum GradeError {
    #[error("{}: cannot read the rubric: {source}", path.display())]
    ReadRubric {
        path: PathBuf,
        #[source]
        source: io::Error,
    },

    /// A mistake inside the rubric, located at `file:line:column`.
    #[error(transparent)]
    Rubric(#[from] CaseError),

    /// The case or course scene a `[render.NAME]` table points at does not load.
    #[error("{location}: render `{render}`: {source}")]
    Source {
        location: SourceLocation,
        render: String,
        #[source]
        source: Box<CaseError>,
    },

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

    #[error("cannot start worker threads: {0}")]
    Threads(#[from] rayon::ThreadPoolBuildError),
}
