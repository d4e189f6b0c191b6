//! The library's top-level error: every stage's error, each of which already names its file.

use crate::build_error::BuildError;
use crate::case::CaseError;
use crate::film::OutputError;
use crate::provenance::ProvenanceError;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(transparent)]
    Case(#[from] CaseError),
    #[error(transparent)]
    Build(#[from] BuildError),
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error(transparent)]
    Provenance(#[from] ProvenanceError),
}
