//! Gradescope's autograder results (`/autograder/results/results.json`): the score, a summary
//! for the student, and one test per rubric image with its points, status, feedback and
//! visibility. The feedback is the self-check's words ([`crate::grade::image_feedback`]), so a
//! student reads on Gradescope what `goldray check` prints.
//!
//! The file holds nothing that changes between two gradings of the same submission (no times),
//! so a regraded submission gets the same bytes.

use std::path::Path;

use serde::Serialize;

use crate::atomic_write::{AtomicWriteError, write_file_atomic};
use crate::grade::{GradescopeSettings, StudentResult, UNEXPLAINED, format_points, image_feedback, mistakes_of};
use crate::run::RunReport;

/// Gradescope's default autograder paths.
pub const SUBMISSION: &str = "/autograder/submission";
pub const RESULTS: &str = "/autograder/results/results.json";

/// The whole results file.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Results {
    pub score: f64,
    /// The summary shown above the tests.
    pub output: String,
    /// How Gradescope shows every `output`: plain text, which needs no escaping.
    pub output_format: &'static str,
    pub visibility: String,
    pub tests: Vec<TestResult>,
}

/// One rubric image as a Gradescope test.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TestResult {
    pub name: String,
    pub score: f64,
    pub max_score: f64,
    /// `passed` at full points, else `failed`.
    pub status: &'static str,
    pub output: String,
    pub visibility: String,
}

/// The results of `student` (graded by a rubric titled `title`), with the visibilities of
/// `settings`; `run` is the run of the student's program, when there was one.
pub fn results(
    title: &str,
    student: &StudentResult,
    settings: &GradescopeSettings,
    run: Option<&RunReport>,
) -> Results {
    let tests = student
        .images
        .iter()
        .map(|image| {
            // The test's name and score already say the file and its points: the output is
            // the feedback after its first line, or for full points what was measured.
            let output = match image_feedback(image).split_once('\n') {
                Some((_, rest)) => dedent(rest),
                None if image.explanation.is_empty() => image.outcome.word().to_owned(),
                None => image.explanation.clone(),
            };
            TestResult {
                name: image.file.clone(),
                score: image.points,
                max_score: image.max_points,
                status: if image.points >= image.max_points {
                    "passed"
                } else {
                    "failed"
                },
                output,
                visibility: settings.visibility_of(&image.file).name().to_owned(),
            }
        })
        .collect();
    Results {
        score: student.total,
        output: summary(title, student, run),
        output_format: "text",
        visibility: settings.visibility.name().to_owned(),
        tests,
    }
}

/// The summary: the total, the mistakes named (each once, with its images), and how the program
/// ran when it did not run well.
fn summary(title: &str, student: &StudentResult, run: Option<&RunReport>) -> String {
    let mut lines = vec![format!(
        "{title}: {} of {} points.",
        format_points(student.total),
        format_points(student.max_points)
    )];
    for id in mistakes_of(student) {
        let images: Vec<&str> = student
            .images
            .iter()
            .filter(|image| {
                image
                    .diagnosis
                    .as_ref()
                    .is_some_and(|d| d.id.split('+').any(|part| part == id))
            })
            .map(|image| image.file.as_str())
            .collect();
        let what = match student
            .images
            .iter()
            .filter_map(|image| image.diagnosis.as_ref())
            .find(|d| d.id.split('+').any(|part| part == id))
        {
            _ if id == UNEXPLAINED => "no known mistake explains these images".to_owned(),
            Some(diagnosis) => diagnosis.explanation.clone(),
            None => String::new(),
        };
        lines.push(format!("Mistake {id} ({}): {what}", images.join(", ")));
    }
    if let Some(build) = run.and_then(|r| r.record.build.as_ref())
        && !build.outcome.as_ref().is_some_and(|o| o.succeeded())
    {
        lines.push("Your program did not build: see the tests for the compiler's messages.".to_owned());
    }
    let lost = student.images.iter().filter(|i| i.points < i.max_points).count();
    if lost == 0 {
        lines.push("Every image is within the limits.".to_owned());
    } else {
        lines.push(format!("{lost} image(s) lost points: each test below says why."));
    }
    lines.join("\n")
}

/// Writes `results` to `path` (replaced whole: Gradescope never reads half a file).
pub fn write_results(path: &Path, results: &Results) -> Result<(), AtomicWriteError> {
    let mut json = serde_json::to_vec_pretty(results).unwrap_or_default();
    json.push(b'\n');
    write_file_atomic(path, &json)
}

/// The feedback's indented lines, without their indent.
fn dedent(text: &str) -> String {
    text.lines()
        .map(|line| line.strip_prefix("  ").unwrap_or(line))
        .collect::<Vec<_>>()
        .join("\n")
}
