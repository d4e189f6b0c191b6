//! `goldray grade`: scoring folders of student renders against golden images.
//!
//! A [rubric](rubric) names the files every submission must hold and, for each, the render it is
//! compared with (a TOML case or a course scene with the course's flags), which picture of that
//! render (colour, normals or depth), the pass and partial-credit limits, and the points. The
//! golden renders are made once per run (or read from the cache), then every student folder is
//! graded in parallel; the report is `grades.csv`, `grades.json`, diff heatmaps and an HTML page
//! per student under the report directory.
//!
//! ```no_run
//! use goldray::grade::{GradeOptions, grade_class};
//! # fn main() -> Result<(), goldray::grade::GradeError> {
//! use goldray::progress::Silent;
//! let options = GradeOptions { out: "report".into(), cache: None };
//! let report = grade_class("rubrics/mit6837.toml".as_ref(), "submissions".as_ref(), &options, &Silent)?;
//! for student in &report.students {
//!     println!("{}: {} / {}", student.name, student.total, student.max_points);
//! }
//! # Ok(())
//! # }
//! ```

mod diagnose;
mod error;
mod golden;
mod html;
mod integrity;
mod outcome;
mod report;
mod rubric;
mod score;
mod similarity;
mod submission;

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;

use crate::progress::Progress;
pub use diagnose::{
    Closest, Confidence, Diagnosis, DiagnosisRun, FAILING_REDUCTION, MISTAKES_DIR, RMSE_REDUCTION, RenderDiagnosis,
    Residual, UNEXPLAINED, explains, loses_points,
};
pub use error::{GradeError, RubricError};
pub use golden::{GoldenRender, Goldens, default_cache_dir, prepare_goldens};
pub use integrity::{Integrity, LinkPolicy, PUBLISHED_COPY};
pub use outcome::Outcome;
pub use report::{ClassReport, RubricSummary, diagnoses_of, flags, mistakes_of};
pub use rubric::{ImageSpec, Output, RenderSource, Rubric, Rule, load_rubric, parse_rubric};
pub use score::{ImageResult, StudentResult, Submission, grade_image, judge};
use similarity::similar_pairs;
pub use similarity::{NEAR_IDENTICAL, SimilarPair};

/// Where the report and the golden cache go.
#[derive(Clone, Debug)]
pub struct GradeOptions {
    pub out: PathBuf,
    /// `None`: [`default_cache_dir`].
    pub cache: Option<PathBuf>,
}

/// Whether grading names the mistake behind each image that lost points (see [`Diagnosis`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Diagnose {
    Yes,
    No,
}

/// Loads the rubric, prepares the goldens, grades every student folder of `submissions` on the
/// current rayon pool, diagnoses the images that lost points and writes the whole report.
/// Golden renders, then graded students, then diagnosed images are reported to `progress`.
/// Returns an error only when grading could not run; what students handed in never makes it
/// fail.
pub fn grade_class(
    rubric_path: &Path,
    submissions: &Path,
    options: &GradeOptions,
    progress: &dyn Progress,
) -> Result<ClassReport, GradeError> {
    grade_class_diagnosing(rubric_path, submissions, options, Diagnose::Yes, progress)
}

/// [`grade_class`], diagnosing or not.
pub fn grade_class_diagnosing(
    rubric_path: &Path,
    submissions: &Path,
    options: &GradeOptions,
    diagnose: Diagnose,
    progress: &dyn Progress,
) -> Result<ClassReport, GradeError> {
    let rubric = load_rubric(rubric_path)?;
    let out = &options.out;
    let cache = options.cache.clone().unwrap_or_else(default_cache_dir);
    let (folders, ignored) = student_folders(submissions, &[out, &cache])?;
    let goldens = prepare_goldens(&rubric, &cache, out, progress)?;

    let names: Vec<String> = folders.keys().cloned().collect();
    let folders: Vec<Submission> = folders
        .into_iter()
        .zip(report::slugs(&names))
        .collect::<Vec<_>>()
        .into_par_iter()
        .map(|((name, path), slug)| Submission::new(name, path, slug))
        .collect();
    // One task per image rather than per student, so that both cores stay busy to the end of a
    // small class.
    let per_student = rubric.images.len();
    let published = integrity::published_hashes(&rubric.integrity, &rubric.images);
    progress.begin("grading", (folders.len() * per_student) as u64);
    // Images left per student, so that the last one to finish can say the student is done.
    let left: Vec<AtomicUsize> = folders.iter().map(|_| AtomicUsize::new(per_student)).collect();
    let results = (0..folders.len() * per_student)
        .into_par_iter()
        .map(|task| {
            let (student, image) = (task / per_student, task % per_student);
            let spec = &rubric.images[image];
            let result = grade_image(
                spec,
                &goldens.images[image],
                goldens.allowances[image].as_deref().map(Vec::as_slice),
                &folders[student],
                &rubric.integrity,
                published.get(&spec.file).copied(),
                out,
            );
            progress.advance(1);
            if left[student].fetch_sub(1, Ordering::Relaxed) == 1 {
                progress.done(&folders[student].name);
            }
            result
        })
        .collect::<Result<Vec<_>, _>>()?;
    progress.finish();
    let mut results = results.into_iter();
    let mut students: Vec<StudentResult> = folders
        .iter()
        .map(|submission| StudentResult::new(submission, results.by_ref().take(per_student).collect()))
        .collect();
    let diagnosis = if diagnose == Diagnose::Yes {
        let run = diagnose::diagnose_class(&rubric, &goldens, &cache, &mut students, out, progress)?;
        diagnose::prefer_consistent(&mut students);
        diagnose::apply_credit(&rubric, &mut students);
        Some(run)
    } else {
        None
    };
    let similar = similar_pairs(
        &students
            .iter()
            .flat_map(|student| {
                student.images.iter().enumerate().filter_map(|(order, image)| {
                    Some(similarity::Entry {
                        student: &student.name,
                        file: &image.file,
                        order,
                        path: image.graded_file.as_deref()?,
                        fingerprint: image.fingerprint.as_ref()?,
                    })
                })
            })
            .collect::<Vec<_>>(),
    );

    let report = ClassReport {
        goldray: env!("CARGO_PKG_VERSION"),
        rubric: RubricSummary::of(&rubric),
        submissions: submissions.to_path_buf(),
        cache: cache.clone(),
        goldens: goldens.renders,
        diagnosis,
        ignored,
        students,
        similar,
    };
    report::write_data(&report, out)?;
    html::write_html(&report, out)?;
    Ok(report)
}

/// Student folders by name, and the names of the other entries. Hidden entries and `__MACOSX` are
/// skipped silently, and so are the report and cache directories when they sit inside
/// `submissions` (so that grading twice does not grade the first report).
fn student_folders(
    submissions: &Path,
    own: &[&PathBuf],
) -> Result<(BTreeMap<String, PathBuf>, Vec<String>), GradeError> {
    let error = |source| GradeError::Submissions {
        path: submissions.to_path_buf(),
        source,
    };
    let own: Vec<PathBuf> = own.iter().filter_map(|p| p.canonicalize().ok()).collect();
    let mut folders = BTreeMap::new();
    let mut ignored = Vec::new();
    for entry in fs::read_dir(submissions).map_err(error)? {
        let entry = entry.map_err(error)?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let path = entry.path();
        if name.starts_with('.') || name == "__MACOSX" || path.canonicalize().is_ok_and(|p| own.contains(&p)) {
            continue;
        }
        if path.is_dir() {
            folders.insert(name, path);
        } else {
            ignored.push(name);
        }
    }
    ignored.sort();
    Ok((folders, ignored))
}

/// What the TA reads on the terminal: how many of each verdict, and where the report is.
pub fn summary(report: &ClassReport, out: &Path) -> String {
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    for result in report.students.iter().flat_map(|s| &s.images) {
        *counts.entry(result.outcome.word()).or_default() += 1;
    }
    let counts: Vec<String> = counts.iter().map(|(word, n)| format!("{n} {word}")).collect();
    let rendered = report.goldens.iter().filter(|g| !g.cached).count();
    let diagnosis = report.diagnosis.as_ref().map_or(String::new(), |run| {
        let renders: usize = run.renders.iter().map(|r| r.rendered).sum();
        let cached: usize = run.renders.iter().map(|r| r.cached).sum();
        format!(
            "\ndiagnosed {} images that lost points: {} explained by a known mistake ({renders} mistake renders, {cached} cached, {:.1} s)",
            run.images, run.explained, run.seconds
        )
    });
    format!(
        "graded {} students on {} images ({}); {} golden renders ({rendered} rendered, {} cached in {}){diagnosis}\nreport: {}",
        report.students.len(),
        report.rubric.images.len(),
        if counts.is_empty() {
            "nothing graded".to_owned()
        } else {
            counts.join(", ")
        },
        report.goldens.len(),
        report.goldens.len() - rendered,
        report.cache.display(),
        out.join("index.html").display()
    )
}
