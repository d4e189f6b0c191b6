//! What can go wrong between a film and its files.

use std::io;
use std::path::PathBuf;

use crate::atomic_write::AtomicWriteError;
use crate::provenance::ProvenanceError;

/// Why an output could not be written or an EXR could not be read. Each message names the file
/// (or "EXR data"/"PNG data" for in-memory bytes) and what went wrong, because these errors end up
/// in test logs and CLI output where there is nothing else to go on.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error(transparent)]
    Write(#[from] AtomicWriteError),

    #[error(transparent)]
    Provenance(#[from] ProvenanceError),

    #[error("cannot read {}: {source}", path.display())]
    Read { path: PathBuf, source: io::Error },

    #[error("refusing to write {file}: pixel ({x}, {y}) channel {channel} is {value}")]
    NonFinite {
        file: String,
        x: u32,
        y: u32,
        channel: &'static str,
        value: f32,
    },

    #[error(
        "refusing to write {file}: the film is {width}x{height} but holds {colors} colours, \
         {depths} depths, {normals} normals and {variances} variances"
    )]
    FilmShape {
        file: String,
        width: u32,
        height: u32,
        colors: usize,
        depths: usize,
        normals: usize,
        variances: usize,
    },

    #[error("cannot encode {file}: {source}")]
    EncodeExr { file: String, source: ::exr::error::Error },

    #[error("cannot encode {file}: {source}")]
    EncodePng { file: String, source: png::EncodingError },

    #[error("{file} is not a readable EXR: {source}")]
    DecodeExr { file: String, source: ::exr::error::Error },

    #[error("{file} cannot be read as a film: {reason}")]
    UnsupportedExr { file: String, reason: String },

    #[error("{file} has no {channel} channel")]
    MissingChannel { file: String, channel: &'static str },

    #[error("output name {name:?} must be a plain file name (no directory, not empty)")]
    InvalidName { name: String },
}
