//! Why a comparison could not even start. Every variant names its file, because these messages
//! end up in CI logs and shell scripts where there is nothing else to go on.

use std::io;
use std::path::PathBuf;

use crate::film::OutputError;

#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    #[error("cannot read {}: {source}", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: io::Error,
    },

    #[error("{}: {source}", path.display())]
    Exr {
        path: PathBuf,
        #[source]
        source: OutputError,
    },

    #[error("{} is not a readable EXR: {source}", path.display())]
    ExrHeader {
        path: PathBuf,
        #[source]
        source: ::exr::error::Error,
    },

    #[error("{} is not a readable PNG: {source}", path.display())]
    Png {
        path: PathBuf,
        #[source]
        source: crate::rgb_image::DecodeError,
    },

    #[error("{} is neither an EXR nor a PNG (its first bytes match neither signature)", path.display())]
    UnknownFormat { path: PathBuf },

    #[error("cannot write the diff image {}: {source}", path.display())]
    WriteDiff {
        path: PathBuf,
        #[source]
        source: OutputError,
    },
}
