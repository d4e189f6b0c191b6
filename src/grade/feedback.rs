//! What a student reads about their own grade, as plain text: the points per image and, for each
//! image that lost points, why, the mistake named and where to look in the code. The same words
//! serve a terminal (`goldray check`) and a learning platform (`goldray autograde`'s
//! `results.json`), so a student reads the same sentence wherever they are graded.

use super::diagnosis::{Confidence, UNEXPLAINED};
use super::judge::format_points;
use super::score::{ImageResult, StudentResult};

/// How many of the last lines of a failing command's stderr the feedback quotes: enough for a
/// compiler's first errors in a short build log.
const STDERR_LINES: usize = 20;

/// One image's feedback: a first line (`a01.png: pass, 1 / 1`) and, when it lost points, the
/// lines after it.
pub fn image_feedback(result: &ImageResult) -> String {
    let mut text = format!(
        "{}: {}, {} / {}",
        result.file,
        result.outcome.word(),
        format_points(result.points),
        format_points(result.max_points)
    );
    if result.points >= result.max_points {
        return text;
    }
    if !result.explanation.is_empty() {
        text += &format!("\n  {}", result.explanation);
    }
    for note in &result.notes {
        text += &format!("\n  note: {note}");
    }
    if let Some(diagnosis) = &result.diagnosis {
        if diagnosis.id == UNEXPLAINED {
            text += "\n  no known mistake explains this image";
        } else {
            let confidence = match diagnosis.confidence {
                Confidence::High => "",
                Confidence::Medium => " (likely)",
                Confidence::None => " (a guess)",
            };
            text += &format!("\n  mistake{confidence}: {}: {}", diagnosis.id, diagnosis.explanation);
            for hint in &diagnosis.hints {
                text += &format!("\n  where to look: {hint}");
            }
        }
    }
    if let Some(program) = &result.program {
        if result.explanation.starts_with(&program.how) {
            text += &format!("\n  command: {}", program.command);
        } else {
            text += &format!("\n  your program: {} ({})", program.how, program.command);
        }
        let lines: Vec<&str> = program.stderr_tail.lines().collect();
        for line in &lines[lines.len().saturating_sub(STDERR_LINES)..] {
            text += &format!("\n  | {line}");
        }
    }
    text
}

/// The whole grade: the total, then every image, lost points first.
pub fn student_feedback(student: &StudentResult) -> String {
    let mut text = format!(
        "{} / {} points",
        format_points(student.total),
        format_points(student.max_points)
    );
    let mut images: Vec<&ImageResult> = student.images.iter().collect();
    images.sort_by(|a, b| (a.points - a.max_points).total_cmp(&(b.points - b.max_points)));
    for result in images {
        text += "\n";
        text += &image_feedback(result);
    }
    text
}
