//! Why a submission could not be graded at all. What the student handed in (or what their
//! program did) is never an error: it is a verdict in the grade.

use std::path::PathBuf;

use crate::atomic_write::AtomicWriteError;
use crate::grade::{GradeError, RubricError};
use crate::run::RunError;

#[derive(Debug, thiserror::Error)]
pub enum AutogradeError {
    #[error(transparent)]
    Rubric(#[from] RubricError),

    #[error(transparent)]
    Run(#[from] RunError),

    #[error(transparent)]
    Grade(#[from] GradeError),

    #[error("a program is to be run, but no sandbox was given to run it in")]
    NoSandbox,

    #[error("{}: grading produced no result for the submission", .0.display())]
    NotGraded(PathBuf),

    #[error("cannot write the results: {0}")]
    Write(#[from] AtomicWriteError),
}
