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
//! let options = GradeOptions { out: "report".into(), ..GradeOptions::default() };
//! let report = grade_class("rubrics/mit6837.toml".as_ref(), "submissions".as_ref(), &options, &Silent)?;
//! for student in &report.students {
//!     println!("{}: {} / {}", student.name, student.total, student.max_points);
//! }
//! # Ok(())
//! # }
//! ```

mod class;
mod diagnose;
mod diagnosis;
mod error;
mod feedback;
mod golden;
mod html;
mod integrity;
mod judge;
mod lms;
mod outcome;
mod program_run;
mod report;
mod resume;
mod rubric;
mod rubric_platform;
mod run_limits;
mod score;
mod shard;
mod similarity;
mod submission;
mod timing;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::progress::Progress;
pub use diagnose::{FAILING_REDUCTION, MISTAKES_DIR, RMSE_REDUCTION, explains, loses_points};
pub use diagnosis::{Closest, Confidence, Diagnosis, DiagnosisRun, RenderDiagnosis, Residual, UNEXPLAINED};
pub use error::{GradeError, RubricError};
pub use feedback::{image_feedback, student_feedback};
pub use golden::{CacheMode, GoldenRender, Goldens, default_cache_dir, prepare_goldens, write_golden_pictures};
pub use integrity::{Integrity, LinkPolicy, PUBLISHED_COPY};
pub use judge::{format_points, judge};
pub use lms::{Layout, LmsId, Refusal};
pub use outcome::Outcome;
pub use program_run::ProgramRun;
pub use report::{ClassReport, RubricSummary, diagnoses_of, flags, mistakes_of};
pub use resume::{RESULT_FILE, StudentRecord};
pub use rubric::{ImageSpec, Output, RenderOrigin, RenderSource, Rubric, Rule, load_rubric, parse_rubric};
pub use rubric_platform::{GradescopeSettings, ProgramSection, Visibility};
pub use score::{Golden, ImageResult, StudentResult, Submission, grade_image};
pub use shard::{MANIFEST, Manifest, Shard, ShardError};
pub use similarity::{NEAR_IDENTICAL, SimilarPair};
pub use submission::student_folders;
pub use timing::{RunCost, Timings};

/// Where the report and the golden cache go, which slice of the class to grade, and whether
/// results kept from an earlier run may be reused.
#[derive(Clone, Debug)]
pub struct GradeOptions {
    pub out: PathBuf,
    /// `None`: [`default_cache_dir`].
    pub cache: Option<PathBuf>,
    /// [`Shard::WHOLE`], or one slice of the class: its report folder is then only for
    /// [`merge_shards`], and the cache is only read.
    pub shard: Shard,
    /// Grade every student again, even those whose result an earlier run left and whose files
    /// have not changed.
    pub force: bool,
}

impl Default for GradeOptions {
    fn default() -> GradeOptions {
        GradeOptions {
            out: PathBuf::from("grade-report"),
            cache: None,
            shard: Shard::WHOLE,
            force: false,
        }
    }
}

/// Whether grading names the mistake behind each image that lost points (see [`Diagnosis`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Diagnose {
    Yes,
    No,
}

/// Loads the rubric, prepares the goldens, grades every student folder of `submissions` on the
/// current rayon pool, diagnoses the images that lost points and writes the whole report.
/// Golden renders, then graded students, are reported to `progress`. Returns an error only when
/// grading could not run; what students handed in never makes it fail.
pub fn grade_class(
    rubric_path: &Path,
    submissions: &Path,
    options: &GradeOptions,
    progress: &dyn Progress,
) -> Result<ClassReport, GradeError> {
    grade_class_diagnosing(rubric_path, submissions, options, Diagnose::Yes, progress)
}

pub use class::grade as grade_class_diagnosing;
pub use class::grade_one;

/// Combines the report folders of the N shards of a class into `out`, as one run over the whole
/// class would have written it; refuses shards of different rubrics, golden renders or classes,
/// and overlapping or missing slices.
pub fn merge_shards(out: &Path, shards: &[PathBuf]) -> Result<ClassReport, GradeError> {
    class::merge(out, shards)
}

/// What `--prepare` made: the golden renders, and how many mistakes' pictures were rendered.
pub struct Prepared {
    pub goldens: Vec<GoldenRender>,
    pub mistakes_rendered: usize,
}

/// Fills the golden cache for `rubric_path` (and, when diagnosing, the single mistakes' pictures)
/// once, so that the shards of a class, which only read the cache, find everything there.
pub fn prepare_cache(
    rubric_path: &Path,
    cache: &Path,
    diagnose: Diagnose,
    progress: &dyn Progress,
) -> Result<Prepared, GradeError> {
    let rubric = load_rubric(rubric_path)?;
    let goldens = prepare_goldens(&rubric, cache, CacheMode::ReadWrite, progress)?;
    let mistakes_rendered = match diagnose {
        Diagnose::Yes => diagnose::prepare_mistakes(&rubric, &goldens, cache),
        Diagnose::No => 0,
    };
    Ok(Prepared {
        goldens: goldens.renders,
        mistakes_rendered,
    })
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
        // Counted over the class: students kept from an earlier run keep their diagnoses.
        let diagnosed: Vec<&Diagnosis> = report
            .students
            .iter()
            .flat_map(|s| &s.images)
            .filter_map(|i| i.diagnosis.as_ref())
            .collect();
        let explained = diagnosed.iter().filter(|d| d.id != UNEXPLAINED).count();
        format!(
            "\ndiagnosed {} images that lost points: {explained} explained by a known mistake ({renders} mistake renders, {cached} cached, {:.1} s)",
            diagnosed.len(),
            run.seconds
        )
    });
    let refused: usize = report.refused.len() + report.students.iter().map(|s| s.refused.len()).sum::<usize>();
    let layout = match (report.layout, refused) {
        (Layout::Folders, 0) => String::new(),
        (layout, 0) => format!(" from {}", layout.describe()),
        (layout, n) => format!(" from {} ({n} files refused: see the report)", layout.describe()),
    };
    format!(
        "graded {} students{layout} on {} images ({}); {} golden renders ({rendered} rendered, {} cached in {}){diagnosis}\n{}\nreport: {}",
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
        time_spent(&report.cost),
        out.join("index.html").display()
    )
}

/// Where the time went: the run's wall-clock time, the students graded and kept, and per graded
/// student the seconds of each step.
pub fn time_spent(cost: &RunCost) -> String {
    let kept = if cost.reused > 0 {
        format!(", {} kept from an earlier run", cost.reused)
    } else {
        String::new()
    };
    let shards = if cost.shards > 1 {
        format!(" over {} shards", cost.shards)
    } else {
        String::new()
    };
    let mut text = format!(
        "time: {:.1} s{shards} ({} students graded{kept})",
        cost.seconds, cost.graded
    );
    if cost.graded > 0 {
        let each = cost.timings.per(cost.graded);
        text.push_str(&format!(
            "; per graded student {:.3} s: decode {:.3} s, compare {:.3} s, FLIP {:.3} s, diagnosis {:.3} s, report {:.3} s",
            each.total(),
            each.decode,
            each.compare,
            each.flip,
            each.diagnosis,
            each.report
        ));
    }
    text
}
