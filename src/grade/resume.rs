//! Resuming: each student's result is written (atomically) as soon as the student is done, as
//! `REPORT/students/SLUG/result.json`, with a fingerprint of everything that decided it. A rerun
//! with the same arguments reuses every result whose fingerprint still matches and grades the
//! rest, so a killed run loses only the students in flight. A result file that is missing,
//! truncated, unparsable, or fingerprinted for other inputs is not trusted: that student is
//! graded again.
//!
//! The run's fingerprint covers goldray's version, the rubric as graded (every image's rule,
//! output and points, the mistake credits, the integrity settings and the published images'
//! pixels), the golden renders' cache keys (which name the scene, its assets and the goldray
//! executable) and whether diagnosis ran. A student's adds the student's name and report name,
//! where the files are shown and the platform's id, the folder's file list and refused files, and for each expected file where it was found, where a link points
//! and every byte of it.

use std::collections::HashMap;
use std::fs;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::Diagnose;
use super::golden::Goldens;
use super::report::RubricSummary;
use super::rubric::Rubric;
use super::score::{StudentResult, Submission};
use super::similarity::Fingerprint;
use super::timing::Timings;
use crate::atomic_write::replace_file;
use crate::film::OutputError;

/// The file a student's result is kept in, inside the student's folder of the report.
pub const RESULT_FILE: &str = "result.json";

/// What `result.json` holds.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StudentRecord {
    /// The run's fingerprint ([`run_fingerprint`]): shards of one class share it.
    pub run: String,
    /// The student's fingerprint ([`student_fingerprint`]).
    pub inputs: String,
    pub result: StudentResult,
    /// What finding copies between students needs of each image, parallel to `result.images`.
    pub fingerprints: Vec<Option<Fingerprint>>,
    /// What grading this student cost when it was graded.
    pub timings: Timings,
}

impl StudentRecord {
    pub fn new(run: &str, inputs: String, result: StudentResult, timings: Timings) -> StudentRecord {
        StudentRecord {
            run: run.to_owned(),
            inputs,
            fingerprints: result.images.iter().map(|i| i.fingerprint.clone()).collect(),
            result,
            timings,
        }
    }

    /// The student's result with the fingerprints put back on its images.
    pub fn into_result(self) -> StudentResult {
        let mut result = self.result;
        for (image, fingerprint) in result.images.iter_mut().zip(self.fingerprints) {
            image.fingerprint = fingerprint;
        }
        result
    }
}

/// Where a student's record is, relative to the report directory.
pub fn record_path(slug: &str) -> PathBuf {
    Path::new("students").join(slug).join(RESULT_FILE)
}

/// The record of `slug` in `out`, if there is a whole, parsable one with `images` images.
pub fn read_record(out: &Path, slug: &str, images: usize) -> Option<StudentRecord> {
    let text = fs::read_to_string(out.join(record_path(slug))).ok()?;
    let record: StudentRecord = serde_json::from_str(&text).ok()?;
    (record.result.images.len() == images && record.fingerprints.len() == images).then_some(record)
}

/// Writes the record atomically: a reader sees the old file or the whole new one. Not synced
/// (a class writes one per student): after a power failure a record may be missing or damaged,
/// and is then not trusted, which only costs grading that student again.
pub fn write_record(out: &Path, slug: &str, record: &StudentRecord) -> Result<(), OutputError> {
    // Serialising plain data cannot fail; infinite numbers (PSNR) become null and read back as
    // infinite.
    let json = serde_json::to_string(record).unwrap_or_default();
    replace_file(&out.join(record_path(slug)), json.as_bytes())?;
    Ok(())
}

/// The run's fingerprint (see the module documentation), 16 hex digits.
pub fn run_fingerprint(
    rubric: &Rubric,
    goldens: &Goldens,
    published: &HashMap<String, u64>,
    diagnose: Diagnose,
) -> String {
    let mut hasher = DefaultHasher::new();
    env!("CARGO_PKG_VERSION").hash(&mut hasher);
    serde_json::to_string(&RubricSummary::of(rubric))
        .unwrap_or_default()
        .hash(&mut hasher);
    format!("{:?}", rubric.integrity).hash(&mut hasher);
    let mut published: Vec<(&String, &u64)> = published.iter().collect();
    published.sort();
    published.hash(&mut hasher);
    goldens.keys.hash(&mut hasher);
    (diagnose == Diagnose::Yes).hash(&mut hasher);
    format!("{:016x}", hasher.finish())
}

/// A student's fingerprint (see the module documentation), 16 hex digits.
pub fn student_fingerprint(run: &str, submission: &Submission, rubric: &Rubric) -> String {
    let mut hasher = DefaultHasher::new();
    run.hash(&mut hasher);
    submission.name.hash(&mut hasher);
    submission.slug.hash(&mut hasher);
    // Where the files are shown, not where they are read: a download's student is staged in
    // another temporary folder each run.
    submission.shown.hash(&mut hasher);
    serde_json::to_string(&submission.lms)
        .unwrap_or_default()
        .hash(&mut hasher);
    submission.hash_inputs(rubric.images.iter().map(|i| i.file.as_str()), &mut hasher);
    format!("{:016x}", hasher.finish())
}
