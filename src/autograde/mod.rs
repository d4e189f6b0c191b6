//! Grading one submission where a course lives: a student's self-check (`goldray check`) and a
//! Gradescope autograder (`goldray autograde`). Both take one folder; when the course collects
//! source code (the rubric's `[program]`, or a program given on the command line) it is first
//! built and run through [`crate::run`], in the sandbox and under the rubric's limits, and its
//! outputs graded. Gradescope's `results.json` is [`gradescope`]'s.

mod error;
pub mod gradescope;

use std::path::{Path, PathBuf};

pub use error::AutogradeError;

use crate::grade::{ClassReport, Diagnose, GradeOptions, ProgramSection, StudentResult, grade_one, load_rubric};
use crate::progress::Progress;
use crate::run::{RunOptions, RunReport, run_rubric};
use crate::sandbox::{LimitOverrides, Sandbox};

/// The folder the submission's program renders into, inside the report folder.
pub const RENDERS_DIR: &str = "renders";

/// One submission to grade.
#[derive(Clone, Debug)]
pub struct SubmissionOptions {
    /// The student's folder: their pictures, or their sources when a program is run.
    pub submission: PathBuf,
    /// The student's name in the report.
    pub name: String,
    /// A program to build and run instead of the rubric's `[program]`; `None` takes the
    /// rubric's, and grades the folder's pictures when it has none.
    pub program: Option<ProgramSection>,
    pub limits: LimitOverrides,
    /// Needed only when a program runs.
    pub sandbox: Option<Sandbox>,
    /// Where the report goes (and, under [`RENDERS_DIR`], the program's outputs), and the
    /// golden cache.
    pub grade: GradeOptions,
    pub diagnose: Diagnose,
}

/// A graded submission: the student's result, the whole report it belongs to, and the run of
/// their program when there was one.
#[derive(Clone, Debug)]
pub struct GradedSubmission {
    pub student: StudentResult,
    pub report: ClassReport,
    pub run: Option<RunReport>,
}

/// Grades `options.submission` against the rubric at `rubric_path`, running its program first
/// when there is one to run.
pub fn grade_submission(
    rubric_path: &Path,
    options: &SubmissionOptions,
    progress: &dyn Progress,
) -> Result<GradedSubmission, AutogradeError> {
    let rubric = load_rubric(rubric_path)?;
    let program = options.program.clone().or(rubric.program);
    let (pictures, run) = match program {
        None => (options.submission.clone(), None),
        Some(program) => {
            let sandbox = options.sandbox.clone().ok_or(AutogradeError::NoSandbox)?;
            let renders = options.grade.out.join(RENDERS_DIR);
            let run = run_rubric(
                rubric_path,
                &RunOptions {
                    program: program.command,
                    submission: Some(options.submission.clone()),
                    build: program.build,
                    out: renders.clone(),
                    limits: options.limits.clone(),
                    sandbox,
                },
                progress,
            )?;
            (renders, Some(run))
        }
    };
    let report = grade_one(
        rubric_path,
        &pictures,
        &options.name,
        &options.grade,
        options.diagnose,
        progress,
    )?;
    let student = report
        .students
        .first()
        .cloned()
        .ok_or_else(|| AutogradeError::NotGraded(pictures.clone()))?;
    Ok(GradedSubmission { student, report, run })
}
