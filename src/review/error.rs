//! Why a review could not list, show or decide a pending golden.

use std::io;
use std::path::PathBuf;

use crate::atomic_write::AtomicWriteError;
use crate::compare::CompareError;
use crate::film::OutputError;

#[derive(Debug, thiserror::Error)]
pub enum ReviewError {
    #[error("{}: cannot list the goldens: {source}", path.display())]
    List {
        path: PathBuf,
        #[source]
        source: io::Error,
    },

    #[error("cannot read {}: {source}", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: io::Error,
    },

    /// A name asked for on the command line or by the page that is not a pending golden. Names
    /// are checked against the list, never joined to a path unchecked.
    #[error("`{name}` is not a pending golden{}", pending_list(.pending))]
    NotPending { name: String, pending: Vec<String> },

    /// A `.snap` or `.snap.new` file whose metadata is not what insta writes for a binary
    /// snapshot: accepting it the way insta would is not certain, so nothing is done.
    #[error("{}: {message}; review it with `cargo insta review`", path.display())]
    Snapshot { path: PathBuf, message: String },

    #[error("cannot remove {}: {source}", path.display())]
    Remove {
        path: PathBuf,
        #[source]
        source: io::Error,
    },

    #[error(transparent)]
    Write(#[from] AtomicWriteError),

    #[error(transparent)]
    Output(#[from] OutputError),

    #[error(transparent)]
    Compare(#[from] CompareError),

    #[error("cannot serve the review page on {address}: {message}")]
    Serve { address: String, message: String },
}

fn pending_list(pending: &[String]) -> String {
    if pending.is_empty() {
        " (none is pending)".to_owned()
    } else {
        format!(" (pending: {})", pending.join(", "))
    }
}
