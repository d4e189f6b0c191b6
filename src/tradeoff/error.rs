//! Why a tradeoff sweep could not run or could not write its report. Every message names what
//! to fix (the file, or the flag and its limit), because these reach the terminal with nothing
//! else beside them.

use std::io;
use std::path::PathBuf;

use crate::atomic_write::AtomicWriteError;
use crate::build_error::BuildError;
use crate::case::CaseError;

#[derive(Debug, thiserror::Error)]
pub enum TradeoffError {
    #[error(transparent)]
    Case(#[from] CaseError),

    #[error(transparent)]
    Build(#[from] BuildError),

    /// The sweep asked for is inconsistent (say, a reference no more converged than the settings
    /// it judges): found before anything renders.
    #[error("{0}")]
    Plan(String),

    /// A render that cannot be compared with the reference: a bug, since every render of a sweep
    /// has the reference's size.
    #[error("the render of {setting} does not match the reference's size or channels")]
    Mismatch { setting: String },

    /// A file the report would replace holds something goldray did not write.
    #[error("{} exists and was not written by goldray tradeoff; pass --force to replace it", path.display())]
    NotOurs { path: PathBuf },

    #[error("cannot inspect {} before replacing it: {source}", path.display())]
    Inspect {
        path: PathBuf,
        #[source]
        source: io::Error,
    },

    #[error("cannot draw the plot: {0}")]
    Plot(String),

    #[error("cannot write the report: {0}")]
    Write(#[from] AtomicWriteError),

    #[error("cannot start worker threads: {0}")]
    Threads(#[from] rayon::ThreadPoolBuildError),
}
