//! Why `goldray run` could not run a rubric's commands at all. A command that ran and failed is
//! not an error: it is recorded in `run.json`.

use std::path::PathBuf;

use crate::atomic_write::AtomicWriteError;
use crate::grade::RubricError;

#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Rubric(#[from] RubricError),

    #[error("{rubric}: nothing to run: {reasons}")]
    NothingToRun { rubric: String, reasons: String },

    #[error(
        "[render.{render}]: the scene names {}, outside the scene's folder; `goldray run` lays out the \
         scene's folder only (the course's data/ folder), so keep its meshes and cube maps inside it",
        asset.display()
    )]
    AssetOutside { render: String, asset: PathBuf },

    #[error("the program `{0}` is neither a file nor a command on PATH")]
    ProgramNotFound(String),

    #[error("--program is empty: give the program to run (a path, or a command with its arguments)")]
    NoProgram,

    #[error("--build needs the submission's folder: give --submission DIR, or --program as a path inside it")]
    NeedsSubmission,

    #[error("cannot {what} {}: {source}", path.display())]
    Io {
        what: &'static str,
        path: PathBuf,
        source: std::io::Error,
    },

    #[error(transparent)]
    Write(#[from] AtomicWriteError),
}

impl RunError {
    pub fn io(what: &'static str, path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> RunError {
        let path = path.into();
        move |source| RunError::Io { what, path, source }
    }
}
