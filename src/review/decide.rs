//! Accepting and rejecting a pending golden, with the files `cargo insta accept` and `cargo insta
//! reject` leave (cargo-insta's `SnapshotContainer::commit` for a file snapshot):
//!
//! - **accept**: `golden/NAME.snap` is the pending header less `assertion_line` (see
//!   [`super::snapshot`]), `golden/NAME.snap.EXT` the pending bytes; the golden's old binary
//!   file (under its own header's extension), `NAME.snap.new` and `NAME.snap.new.EXT` are gone;
//! - **reject**: `NAME.snap.new` and `NAME.snap.new.EXT` are gone, the golden untouched.
//!
//! Nothing else in the project is written. The two new files replace the golden together
//! ([`write_files_atomic`]), so an interrupted accept leaves the old golden or the new one, never
//! a header of one beside the bytes of the other; the pending files go only once the golden is
//! in place.

use std::io;
use std::path::{Path, PathBuf};

use super::error::ReviewError;
use super::pending::{Pending, Project};
use crate::atomic_write::write_files_atomic;

/// What a decision did, for the caller to report.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Decision {
    pub name: String,
    pub accepted: bool,
    pub written: Vec<PathBuf>,
    pub removed: Vec<PathBuf>,
}

/// Accepts the pending golden `name` (looked up among the pending ones).
pub fn accept(project: &Project, name: &str) -> Result<Decision, ReviewError> {
    accept_pending(project, &project.find(name)?)
}

/// Rejects the pending golden `name`: its pending files are removed, the golden kept.
pub fn reject(project: &Project, name: &str) -> Result<Decision, ReviewError> {
    let pending = project.find(name)?;
    let mut removed = Vec::new();
    for path in [pending.snap_new.clone(), pending.new_data()] {
        if remove(&path)? {
            removed.push(path);
        }
    }
    Ok(Decision {
        name: pending.name,
        accepted: false,
        written: Vec::new(),
        removed,
    })
}

/// Accepts every pending golden, in name order. Stops at the first that cannot be accepted;
/// those before it stay accepted (the error names the one that failed).
pub fn accept_all(project: &Project) -> Result<Vec<Decision>, ReviewError> {
    let list = project.pending()?;
    list.pending.iter().map(|p| accept_pending(project, p)).collect()
}

fn accept_pending(project: &Project, pending: &Pending) -> Result<Decision, ReviewError> {
    let new_data = pending.new_data();
    // insta cannot accept a pending header without its bytes either (it stops with a panic).
    let bytes = std::fs::read(&new_data).map_err(|source| ReviewError::Read {
        path: new_data.clone(),
        source,
    })?;
    let old_data = pending.old_data()?;
    let header = pending.header.accepted();
    let data = pending.data();
    write_files_atomic(
        &project.golden_dir(),
        &[(pending.snap.as_path(), header.as_bytes()), (data.as_path(), &bytes)],
    )?;
    let mut removed = Vec::new();
    let stale = old_data.filter(|old| *old != data);
    for path in stale.into_iter().chain([pending.snap_new.clone(), new_data]) {
        if remove(&path)? {
            removed.push(path);
        }
    }
    Ok(Decision {
        name: pending.name.clone(),
        accepted: true,
        written: vec![pending.snap.clone(), data],
        removed,
    })
}

/// Removes `path`; `Ok(false)` when it was already gone (as cargo-insta, which goes on).
fn remove(path: &Path) -> Result<bool, ReviewError> {
    match std::fs::remove_file(path) {
        Ok(()) => Ok(true),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(false),
        Err(source) => Err(ReviewError::Remove {
            path: path.to_path_buf(),
            source,
        }),
    }
}
