//! The class report and its machine-readable forms: `grades.csv` for the spreadsheet the grades
//! end up in, `grades.json` with everything for scripts.

use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize, Serializer};

use super::diagnosis::DiagnosisRun;
use super::feedback::student_feedback;
use super::golden::GoldenRender;
use super::judge::format_points;
use super::lms::{Layout, Refusal, canvas, moodle};
use super::rubric::{ImageSpec, Rubric};
use super::score::StudentResult;
use super::similarity::SimilarPair;
use super::timing::RunCost;
use crate::atomic_write::write_file_atomic;
use crate::film::OutputError;

/// Everything one grading run found; `grades.json` is this, serialised.
#[derive(Clone, Debug, Serialize)]
pub struct ClassReport {
    /// goldray's version, which (with the build) the golden images depend on.
    pub goldray: &'static str,
    pub rubric: RubricSummary,
    pub submissions: PathBuf,
    /// How the submissions were laid out: plain folders, or a Canvas or Moodle download.
    pub layout: Layout,
    /// Where the golden renders were cached.
    pub cache: PathBuf,
    /// Each render's name and cache key (what it cost goes to `run.json`).
    #[serde(serialize_with = "renders_and_keys")]
    pub goldens: Vec<GoldenRender>,
    /// What diagnosing the images that lost points cost; `None` when grading did not diagnose.
    /// In `run.json`, not `grades.json`, which holds only what the same inputs always give.
    #[serde(skip)]
    pub diagnosis: Option<DiagnosisRun>,
    /// Entries of the submissions folder that are not student folders (loose files), by name.
    pub ignored: Vec<String>,
    /// Entries of a download that were refused and belong to no student, each with why.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub refused: Vec<Refusal>,
    /// By folder name.
    pub students: Vec<StudentResult>,
    /// Pairs of students who handed in the same picture, or nearly the same failing one.
    pub similar: Vec<SimilarPair>,
    /// What this run cost and where the time went (`run.json`).
    #[serde(skip)]
    pub cost: RunCost,
}

/// `grades.json`'s `goldens`: which render, under which cache key; whether it was cached and how
/// long it took belong to one run, not to the grades.
fn renders_and_keys<S: Serializer>(goldens: &[GoldenRender], serializer: S) -> Result<S::Ok, S::Error> {
    #[derive(Serialize)]
    struct Render<'a> {
        render: &'a str,
        key: &'a str,
    }
    serializer.collect_seq(goldens.iter().map(|g| Render {
        render: &g.render,
        key: &g.key,
    }))
}

/// `run.json`: what one grading run (or the shards a merge combined) cost. Unlike `grades.json`,
/// it differs from run to run.
#[derive(Serialize)]
struct RunFile<'a> {
    #[serde(flatten)]
    cost: &'a RunCost,
    goldens: &'a [GoldenRender],
    diagnosis: &'a Option<DiagnosisRun>,
}

/// Writes `run.json` into `out`.
pub fn write_run(report: &ClassReport, out: &Path) -> Result<(), OutputError> {
    let file = RunFile {
        cost: &report.cost,
        goldens: &report.goldens,
        diagnosis: &report.diagnosis,
    };
    let json = serde_json::to_string_pretty(&file).unwrap_or_default();
    write_file_atomic(&out.join("run.json"), (json + "\n").as_bytes())?;
    Ok(())
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RubricSummary {
    pub path: PathBuf,
    pub title: String,
    pub max_points: f64,
    pub images: Vec<ImageSpec>,
    /// The rubric's credit per diagnosed mistake, by catalogue id (absent: none).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub mistake_credit: BTreeMap<String, f64>,
    /// The assignment's column in Canvas's gradebook (`[lms] assignment`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lms_assignment: Option<String>,
}

impl RubricSummary {
    pub fn of(rubric: &Rubric) -> RubricSummary {
        RubricSummary {
            path: rubric.path.clone(),
            title: rubric.title.clone(),
            max_points: rubric.images.iter().map(|i| i.points).sum(),
            images: rubric.images.clone(),
            mistake_credit: rubric
                .mistake_credit
                .iter()
                .map(|(f, c)| (f.name().to_owned(), *c))
                .collect(),
            lms_assignment: rubric.lms_assignment.clone(),
        }
    }
}

/// Writes `grades.csv` and `grades.json` into `out`, and for a download whose students carry
/// their platform's ids, the grades in the form that platform imports.
pub fn write_data(report: &ClassReport, out: &Path) -> Result<(), OutputError> {
    write_file_atomic(&out.join("grades.csv"), grades_csv(report).as_bytes())?;
    for (platform, file) in [(Layout::Moodle, MOODLE_CSV), (Layout::Canvas, CANVAS_CSV)] {
        match lms_csv(report, platform) {
            Some(csv) => write_file_atomic(&out.join(file), csv.as_bytes())?,
            // One left by an earlier run over another class is not this class's.
            None => {
                let _ = std::fs::remove_file(out.join(file));
            }
        }
    }
    // Serialising plain data to a string cannot fail; infinite numbers (the PSNR of identical
    // pictures) become null.
    let json = serde_json::to_string_pretty(report).unwrap_or_else(|e| format!("{{\"error\": {:?}}}", e.to_string()));
    write_file_atomic(&out.join("grades.json"), (json + "\n").as_bytes())?;
    Ok(())
}

/// One row per student: the folder name, the points of each image in rubric order, the total,
/// and the flags on the student's images (`a01.png: identical to the published reference; …`).
pub fn grades_csv(report: &ClassReport) -> String {
    let mut csv = String::new();
    let header = std::iter::once("student")
        .chain(report.rubric.images.iter().map(|i| i.file.as_str()))
        .chain(["total", "flags", "diagnoses"])
        .map(csv_field)
        .collect::<Vec<_>>();
    csv.push_str(&header.join(","));
    csv.push_str("\r\n");
    for student in &report.students {
        let row = std::iter::once(csv_field(&student.name))
            .chain(student.images.iter().map(|i| format_points(i.points)))
            .chain([
                format_points(student.total),
                csv_field(&flags(student).join("; ")),
                csv_field(&diagnoses_of(student).join("; ")),
            ])
            .collect::<Vec<_>>();
        csv.push_str(&row.join(","));
        csv.push_str("\r\n");
    }
    csv
}

/// Moodle's offline grading worksheet, filled.
pub const MOODLE_CSV: &str = "grades-moodle.csv";
/// Canvas's gradebook import, filled.
pub const CANVAS_CSV: &str = "grades-canvas.csv";

/// The grades as `platform` imports them, when the class's students carry its ids: Moodle's
/// worksheet with the per-image verdicts and the diagnoses as feedback, or Canvas's gradebook
/// columns with the rubric's `[lms] assignment` (else its title) as the assignment's.
pub fn lms_csv(report: &ClassReport, platform: Layout) -> Option<String> {
    let students: Vec<(&StudentResult, &str)> = report
        .students
        .iter()
        .filter_map(|s| {
            s.lms
                .as_ref()
                .filter(|l| l.platform == platform)
                .map(|l| (s, l.id.as_str()))
        })
        .collect();
    if students.is_empty() {
        return None;
    }
    let maximum = format_points(report.rubric.max_points);
    let mut rows = match platform {
        Layout::Canvas => {
            let assignment = report.rubric.lms_assignment.as_deref().unwrap_or(&report.rubric.title);
            vec![canvas::header(assignment), canvas::points_possible(&maximum)]
        }
        _ => vec![moodle::HEADER.map(str::to_owned).to_vec()],
    };
    for (student, id) in students {
        let total = format_points(student.total);
        rows.push(match platform {
            Layout::Canvas => canvas::row(&student.name, id, &total),
            _ => moodle::row(
                id,
                &student.name,
                &total,
                &maximum,
                &moodle::feedback_comments(&student_feedback(student)),
            ),
        });
    }
    let mut csv = String::new();
    for row in rows {
        csv.push_str(&row.iter().map(|cell| csv_field(cell)).collect::<Vec<_>>().join(","));
        csv.push_str("\r\n");
    }
    Some(csv)
}

/// Each flag of a student's images, as `FILE: flag`.
/// The diagnoses of a student's images, each id once, in rubric order: `no-shadows`,
/// `no-shadows+gamma-applied`, `unexplained`.
pub fn diagnoses_of(student: &StudentResult) -> Vec<String> {
    let mut ids: Vec<String> = Vec::new();
    for diagnosis in student.images.iter().filter_map(|i| i.diagnosis.as_ref()) {
        if !ids.contains(&diagnosis.id) {
            ids.push(diagnosis.id.clone());
        }
    }
    ids
}

/// The mistakes a student made, each catalogue id once (a pair's two apart), and `unexplained`
/// if some image is: what the class histogram counts.
pub fn mistakes_of(student: &StudentResult) -> Vec<String> {
    let mut ids: Vec<String> = Vec::new();
    for id in diagnoses_of(student).iter().flat_map(|id| id.split('+')) {
        if !ids.iter().any(|known| known == id) {
            ids.push(id.to_owned());
        }
    }
    ids
}

pub fn flags(student: &StudentResult) -> Vec<String> {
    student
        .images
        .iter()
        .flat_map(|image| image.flags.iter().map(move |flag| format!("{}: {flag}", image.file)))
        .collect()
}

/// RFC 4180 quoting, and a leading `'` on anything a spreadsheet would run as a formula: folder
/// names are chosen by students, and `=HYPERLINK(…)` in a gradebook is an attack.
fn csv_field(text: &str) -> String {
    let guarded = if text.starts_with(['=', '+', '-', '@', '\t', '\r']) {
        format!("'{text}")
    } else {
        text.to_owned()
    };
    if guarded.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", guarded.replace('"', "\"\""))
    } else {
        guarded
    }
}

/// A distinct file-system and URL-safe name per student folder: ASCII letters, digits, `-` and
/// `_` kept, anything else `_`, and `-2`, `-3`… on a clash. Clashes are found ignoring case, for
/// case-insensitive file systems.
pub fn slugs(names: &[String]) -> Vec<String> {
    let mut taken = HashSet::new();
    names
        .iter()
        .map(|name| {
            let mut base: String = name
                .chars()
                .take(60)
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                        c
                    } else {
                        '_'
                    }
                })
                .collect();
            if base.is_empty() {
                base = "student".to_owned();
            }
            let mut slug = base.clone();
            let mut n = 1;
            while !taken.insert(slug.to_ascii_lowercase()) {
                n += 1;
                slug = format!("{base}-{n}");
            }
            slug
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_fields_are_quoted_and_formulas_defused() {
        assert_eq!(csv_field("alice"), "alice");
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
        assert_eq!(csv_field("=1+1"), "'=1+1");
        assert_eq!(csv_field("-x,y"), "\"'-x,y\"");
    }

    #[test]
    fn points_drop_needless_decimals() {
        assert_eq!(format_points(2.0), "2");
        assert_eq!(format_points(0.5), "0.5");
        assert_eq!(format_points(4.0 / 3.0), "1.33");
        assert_eq!(format_points(0.0), "0");
    }

    #[test]
    fn slugs_are_safe_and_distinct() {
        let names = ["alice", "Alice", "<b>bob</b>", "", "..", "alice"].map(String::from);
        assert_eq!(
            slugs(&names),
            ["alice", "Alice-2", "_b_bob__b_", "student", "__", "alice-3"]
        );
    }
}
