//! Reviewing changed goldens: the pending snapshots the golden suite leaves (insta's
//! `golden/NAME.snap.new`), each compared with its golden as the suite compared them, shown on a
//! page with the pictures and their linear values, and accepted or rejected with exactly the
//! files `cargo insta accept` and `cargo insta reject` leave.
//!
//! - [`pending`]: which goldens are pending; a name from outside is only ever looked up there;
//! - [`snapshot`]: insta's snapshot files, read and written as insta does;
//! - [`decide`]: accept and reject;
//! - [`case_review`]: one case compared, with its provenance and pictures;
//! - [`payload`], [`page`], [`site`]: the page, its pixel values and its files;
//! - [`requests`], [`server`]: what the local server accepts, and the server.
//!
//! The page is the same whether served (with buttons), written to a folder (`--static`) or
//! written as one file for any two images (`goldray diff --html`).

pub mod case_review;
pub mod decide;
mod error;
pub mod page;
pub mod payload;
pub mod pending;
pub mod requests;
pub mod server;
pub mod site;
pub mod snapshot;

use std::path::{Path, PathBuf};

pub use case_review::CaseReview;
pub use decide::{Decision, accept, accept_all, reject};
pub use error::ReviewError;
pub use pending::{Pending, PendingList, Project};
pub use server::{Event, Server};

use crate::atomic_write::write_file_atomic;
use crate::compare::ToleranceOverrides;
use page::{Heading, Resources};
use pending::relative;
use site::Site;

/// The heading and the reviews of every pending golden of `project`: what the server shows and
/// `--static` writes (`decisions`: whether the page has buttons).
pub fn review_project(project: &Project, decisions: bool) -> Result<(Heading, Vec<CaseReview>), ReviewError> {
    let list = project.pending()?;
    let mut notes: Vec<String> = list
        .skipped
        .iter()
        .map(|(path, reason)| format!("skipped {}: {reason}", relative(&project.root, path)))
        .collect();
    // A case that cannot be shown (its new render does not decode) is named, and the others
    // are still shown.
    let mut reviews = Vec::with_capacity(list.pending.len());
    for pending in &list.pending {
        match CaseReview::of_pending(project, pending) {
            Ok(review) => reviews.push(review),
            Err(error) => notes.push(format!("cannot show {}: {error}", pending.name)),
        }
    }
    let count = reviews.len();
    if !decisions && count > 0 {
        notes.push(
            "A read-only copy. To decide, run `goldray review` in the project (or `goldray review --accept NAME`)."
                .to_owned(),
        );
    }
    let plural = if count == 1 { "" } else { "s" };
    let heading = Heading {
        title: format!("goldray review: {count} pending golden{plural}"),
        notes,
        decisions,
    };
    Ok((heading, reviews))
}

/// Writes the page of `project`'s pending goldens into `dir` without buttons (`index.html`,
/// `img/`, `data/`), e.g. as a CI artifact; returns the page's path and how many cases it shows.
pub fn write_static(project: &Project, dir: &Path) -> Result<(PathBuf, usize), ReviewError> {
    let (heading, reviews) = review_project(project, false)?;
    let page = Site::build(&heading, &reviews, Resources::Linked)?.write(dir)?;
    Ok((page, reviews.len()))
}

/// Writes the one-case page of any two images to `out`, everything inside the one file:
/// `goldray diff --html`.
pub fn write_diff_page(
    expected: &Path,
    actual: &Path,
    overrides: &ToleranceOverrides,
    out: &Path,
) -> Result<CaseReview, ReviewError> {
    let review = CaseReview::of_files(expected, actual, overrides)?;
    let heading = Heading {
        title: format!("goldray diff: {}", review.title),
        notes: Vec::new(),
        decisions: false,
    };
    let site = Site::build(&heading, std::slice::from_ref(&review), Resources::Embedded)?;
    write_file_atomic(out, site.index())?;
    Ok(review)
}
