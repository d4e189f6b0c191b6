//! One case as a reviewer sees it: the golden and the new render decoded, compared the way the
//! golden suite compared them, and how the two were made differently.
//!
//! The suite prints its report and writes three PNGs under `target/golden-diffs/`, whose place
//! depends on `CARGO_TARGET_DIR` and which a later run may have replaced; the numbers are kept
//! nowhere. So the review compares again, from the files it is about to accept or reject
//! (`golden/NAME.snap.exr` against `golden/NAME.snap.new.exr`) with the suite's comparator and
//! the case's `[tolerance]`: the same code on the same bytes gives the suite's verdict, numbers
//! and heatmap, and never a stale one.

use std::path::Path;

use crate::rgb_image::RgbImage;

use super::error::ReviewError;
use super::pending::{Pending, Project, relative};
use crate::case::{LoadOptions, load};
use crate::compare::{Comparison, Image, Tolerance, ToleranceOverrides, compare, comparison_heatmap};
use crate::film::encode_png;
use crate::provenance::{Provenance, made_differently};

/// One case of the page.
#[derive(Debug)]
pub struct CaseReview {
    /// Letters, digits, `_` and `-`: the case name, or `diff` for `goldray diff --html`. It names
    /// the case's files and elements on the page.
    pub id: String,
    pub title: String,
    pub description: Option<String>,
    /// The two files, as a person finds them (relative to the project).
    pub expected_file: String,
    pub actual_file: String,
    /// `None` for a new case (no golden yet) or a golden that cannot be read (see `notes`).
    pub expected: Option<Image>,
    pub actual: Image,
    pub comparison: Option<Comparison>,
    /// Where the tolerance came from: `cases/NAME.toml`, or why the default was used.
    pub tolerance_from: String,
    pub made_differently: Option<String>,
    pub provenance: [Option<Provenance>; 2],
    /// Anything the reviewer should know that the numbers do not say.
    pub notes: Vec<String>,
    /// No golden exists yet: accepting adds the case to the suite.
    pub new_case: bool,
}

/// The three pictures of a case as PNG bytes: the sRGB previews the suite writes as
/// `.expected.png` / `.actual.png`, and its heatmap.
#[derive(Debug, Default)]
pub struct Pictures {
    pub expected: Option<Vec<u8>>,
    pub actual: Vec<u8>,
    pub heatmap: Option<Vec<u8>>,
}

impl CaseReview {
    /// The review of a pending golden of `project`.
    pub fn of_pending(project: &Project, pending: &Pending) -> Result<CaseReview, ReviewError> {
        let root = &project.root;
        let new_data = pending.new_data();
        let new_bytes = read(&new_data)?;
        let actual_file = relative(root, &new_data);
        let actual = Image::from_exr_bytes(&new_bytes, &actual_file)?;
        let mut notes = Vec::new();
        let (tolerance, tolerance_from) = match load(&pending.case_file, &LoadOptions::default()) {
            Ok(case) => (case.tolerance, relative(root, &pending.case_file)),
            Err(error) => {
                notes.push(format!("judged with the default tolerance: {error}"));
                (Tolerance::DEFAULT, "the default tolerance".to_owned())
            }
        };
        let old_data = pending.old_data().unwrap_or_else(|error| {
            notes.push(error.to_string());
            None
        });
        let expected_file = old_data
            .as_ref()
            .map_or_else(|| relative(root, &pending.data()), |path| relative(root, path));
        let old_bytes = match &old_data {
            Some(path) => match read(path) {
                Ok(bytes) => Some(bytes),
                Err(error) => {
                    notes.push(error.to_string());
                    None
                }
            },
            None => {
                notes.push(format!("a new case: {expected_file} does not exist yet"));
                None
            }
        };
        let expected = old_bytes.as_deref().and_then(|bytes| {
            Image::from_exr_bytes(bytes, &expected_file)
                .map_err(|error| notes.push(error.to_string()))
                .ok()
        });
        let made = |bytes: Option<&[u8]>| bytes.and_then(|b| Provenance::from_bytes(b, "snapshot").ok().flatten());
        let provenance = [made(old_bytes.as_deref()), made(Some(&new_bytes))];
        let mut review = CaseReview::new(
            pending.name.clone(),
            pending.header.description(),
            (expected_file, expected),
            (actual_file, actual),
            (tolerance, tolerance_from),
            provenance,
            notes,
        );
        review.new_case = old_data.is_none() && !pending.snap.exists();
        Ok(review)
    }

    /// The review of any two image files, as `goldray diff --html` shows them: the tolerance is
    /// `overrides` over the defaults for the files' encoding.
    pub fn of_files(
        expected_path: &Path,
        actual_path: &Path,
        overrides: &ToleranceOverrides,
    ) -> Result<CaseReview, ReviewError> {
        let expected = Image::read(expected_path)?;
        let actual = Image::read(actual_path)?;
        let tolerance = overrides.tolerance(expected.encoding);
        let provenance = [expected_path, actual_path].map(|path| Provenance::read(path).ok().flatten());
        let [expected_file, actual_file] = [expected_path, actual_path].map(|p| p.display().to_string());
        Ok(CaseReview::new(
            "diff".to_owned(),
            None,
            (expected_file, Some(expected)),
            (actual_file, actual),
            (tolerance, "the command line and the defaults".to_owned()),
            provenance,
            Vec::new(),
        ))
    }

    fn new(
        id: String,
        description: Option<String>,
        (expected_file, expected): (String, Option<Image>),
        (actual_file, actual): (String, Image),
        (tolerance, tolerance_from): (Tolerance, String),
        provenance: [Option<Provenance>; 2],
        notes: Vec<String>,
    ) -> CaseReview {
        let comparison = expected.as_ref().map(|e| compare(e, &actual, &tolerance));
        let made_differently = made_differently(
            ("golden", provenance[0].as_ref()),
            ("new render", provenance[1].as_ref()),
        );
        let title = if id == "diff" {
            format!("{actual_file} against {expected_file}")
        } else {
            id.clone()
        };
        CaseReview {
            id,
            title,
            description,
            expected_file,
            actual_file,
            expected,
            actual,
            comparison,
            tolerance_from,
            made_differently,
            provenance,
            notes,
            new_case: false,
        }
    }

    /// The word the page leads with: the comparison's verdict, or `NEW` for a case without a
    /// golden and `UNREADABLE` for a golden that cannot be decoded.
    pub fn verdict_word(&self) -> &'static str {
        match &self.comparison {
            Some(comparison) => comparison.verdict.word(),
            None if self.new_case => "NEW",
            None => "UNREADABLE",
        }
    }

    /// The heatmap the suite writes: the evidence for a sampled case, the differences otherwise.
    pub fn heatmap(&self) -> Option<RgbImage> {
        let (expected, comparison) = (self.expected.as_ref()?, self.comparison.as_ref()?);
        comparison_heatmap(expected, &self.actual, comparison)
    }

    pub fn pictures(&self) -> Result<Pictures, ReviewError> {
        Ok(Pictures {
            expected: self.expected.as_ref().map(|e| encode_png(&e.preview)).transpose()?,
            actual: encode_png(&self.actual.preview)?,
            heatmap: self.heatmap().map(|h| encode_png(&h)).transpose()?,
        })
    }
}

fn read(path: &Path) -> Result<Vec<u8>, ReviewError> {
    std::fs::read(path).map_err(|source| ReviewError::Read {
        path: path.to_path_buf(),
        source,
    })
}
