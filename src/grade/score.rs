//! Grading one student: every expected file gets an [`Outcome`], points, the sentence that
//! explains them, and the measurements behind them.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::diagnosis::{Diagnosis, Unfinished};
use super::golden::GOLDEN_DIR;
use super::integrity::{Integrity, PUBLISHED_COPY, pixel_hash, refuse_link};
use super::judge::{judge, percent};
use super::lms::{LmsId, Staged};
use super::outcome::Outcome;
use super::program_run::{ProgramRun, absent_verdict, delivered_note, read_run_record};
use super::rubric::ImageSpec;
use super::similarity::Fingerprint;
use super::submission::{Folder, read_png};
use super::timing::{Timings, seconds, timed};
use crate::atomic_write::replace_file;
use crate::compare::{Encoding, Image, Metrics, Tolerance, compare_timed, diff_heatmap, diff_heatmap_widened};
use crate::film::{OutputError, encode_png};
use crate::rgb_image::RgbImage;
use crate::sandbox::RunRecord;

/// One expected file of one student.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ImageResult {
    pub file: String,
    #[serde(flatten)]
    pub outcome: Outcome,
    pub points: f64,
    pub max_points: f64,
    /// Why these points, in one sentence naming the limits that decided.
    pub explanation: String,
    /// Conversions and where the file was found, when not exactly as expected.
    pub notes: Vec<String>,
    /// The student's file that was graded.
    pub graded_file: Option<PathBuf>,
    /// The student's picture as compared (8-bit RGB), relative to the report directory.
    pub student_image: Option<String>,
    /// The diff heatmap, relative to the report directory.
    pub diff_image: Option<String>,
    pub metrics: Option<Metrics>,
    /// Which mistake explains the image, only for an image that lost points on a comparison
    /// (and only when grading diagnoses).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diagnosis: Option<Diagnosis>,
    /// Evidence for the TA about where the picture came from ("identical to the published
    /// reference"); it changes the points only where the rubric says so.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub flags: Vec<String>,
    /// The command behind the image, from `goldray run`'s record, when it did not end well.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub program: Option<ProgramRun>,
    /// What finding copies between students needs; not part of the report.
    #[serde(skip)]
    pub fingerprint: Option<Fingerprint>,
}

/// All of one student's results, in rubric order.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StudentResult {
    /// The folder's name (lossily decoded if it is not UTF-8), or the name the learning platform
    /// gives the student.
    pub name: String,
    /// Who the student is on the learning platform whose download was graded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lms: Option<LmsId>,
    /// Where the student's files are: their folder, or in a download, where their files were.
    pub folder: PathBuf,
    /// The student's files that were refused (hostile archive entries), each with why.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub refused: Vec<String>,
    /// The student's page, relative to the report directory.
    pub page: String,
    pub total: f64,
    pub max_points: f64,
    pub images: Vec<ImageResult>,
    /// Several parts of the assignment never written, named once (see [`Unfinished`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unfinished: Option<Unfinished>,
}

/// One student's folder, listed once, with the file-system and URL-safe name its pictures and
/// page go under (see `report::slugs`).
pub struct Submission {
    pub name: String,
    /// Where the files are read: the student's folder, or their files staged out of a download.
    pub path: PathBuf,
    /// Where the report says the files are (the folder, or where they are in the download).
    pub shown: PathBuf,
    pub slug: String,
    pub lms: Option<LmsId>,
    files: Folder,
    /// Notes on the files that were refused.
    refused: Vec<String>,
    /// What `goldray run` recorded when it made this folder's pictures.
    pub run: Option<RunRecord>,
}

impl Submission {
    pub fn new(name: String, path: PathBuf, slug: String) -> Submission {
        let files = Folder::scan(&path);
        let run = read_run_record(&path);
        Submission {
            name,
            shown: path.clone(),
            path,
            slug,
            lms: None,
            files,
            refused: Vec::new(),
            run,
        }
    }

    /// A download's student whose files were staged at `path`: the report shows `shown`, names
    /// their platform id, and gives the refused files their verdicts.
    pub fn staged(
        name: String,
        path: PathBuf,
        slug: String,
        shown: PathBuf,
        lms: Option<LmsId>,
        staged: &Staged,
    ) -> Submission {
        let mut submission = Submission::new(name, path, slug);
        submission.shown = shown;
        submission.lms = lms;
        submission.files.refused = staged
            .refused
            .iter()
            .map(|(path, refusal)| (path.clone(), refusal.outcome.clone()))
            .collect();
        submission.refused = staged.refused.iter().map(|(_, refusal)| refusal.note()).collect();
        submission
    }

    /// Feeds `hasher` what grading the expected files `names` reads of this submission.
    pub fn hash_inputs<'a>(&self, names: impl Iterator<Item = &'a str>, hasher: &mut impl std::hash::Hasher) {
        use std::hash::Hash;
        self.files.hash_inputs(names, hasher);
        serde_json::to_string(&self.run).unwrap_or_default().hash(hasher);
    }

    /// Where the student's pictures go, relative to the report directory.
    pub fn dir(&self) -> String {
        format!("students/{}", self.slug)
    }
}

impl StudentResult {
    /// `images` in rubric order.
    pub fn new(submission: &Submission, images: Vec<ImageResult>) -> StudentResult {
        StudentResult {
            name: submission.name.clone(),
            lms: submission.lms.clone(),
            folder: submission.shown.clone(),
            refused: submission.refused.clone(),
            page: format!("{}.html", submission.dir()),
            total: images.iter().map(|i| i.points).sum(),
            max_points: images.iter().map(|i| i.max_points).sum(),
            images,
            unfinished: None,
        }
    }

    /// The total again, after points changed (credit for a diagnosed mistake).
    pub fn recount(&mut self) {
        self.total = self.images.iter().map(|i| i.points).sum();
    }
}

/// The golden side of one image: its picture, and with a rubric's `statistical = true` the
/// allowance each colour value's threshold is widened by (the golden's sampling noise, in codes:
/// `compare::noise::png_allowance`).
#[derive(Clone, Copy)]
pub struct Golden<'a> {
    pub picture: &'a Image,
    pub allowance: Option<&'a [[f32; 3]]>,
}

/// Grades one expected file of one student against its golden picture, writing the student's
/// picture and the diff heatmap under `out` when they differ from the golden. `published` is the
/// pixel hash of the published reference image of this file, when the rubric names a published
/// folder that has it. Whatever the file, the result is a verdict; only a failure to write the
/// report is an error. `timings` gets the time each step took.
///
pub fn grade_image(
    spec: &ImageSpec,
    golden: Golden,
    submission: &Submission,
    integrity: &Integrity,
    published: Option<u64>,
    out: &Path,
    timings: &mut Timings,
) -> Result<ImageResult, OutputError> {
    let Golden {
        picture: golden,
        allowance,
    } = golden;
    let (folder, dir) = (&submission.files, submission.dir());
    let mut result = ImageResult {
        file: spec.file.clone(),
        outcome: Outcome::Missing,
        points: 0.0,
        max_points: spec.points,
        explanation: String::new(),
        notes: Vec::new(),
        graded_file: None,
        student_image: None,
        diff_image: None,
        metrics: None,
        diagnosis: None,
        flags: Vec::new(),
        program: None,
        fingerprint: None,
    };
    let located = match (&folder.error, folder.find(&spec.file)) {
        (Some(reason), _) => return Ok(refused(result, Outcome::Unreadable { reason: reason.clone() })),
        (None, None) => {
            if let Some(outcome) = folder.refusal(&spec.file) {
                return Ok(refused(result, outcome.clone()));
            }
            let why = submission.run.as_ref().and_then(|run| absent_verdict(run, &spec.file));
            return Ok(match why {
                Some((outcome, explanation, program)) => {
                    let mut result = refused(result, outcome);
                    result.explanation = explanation;
                    result.program = Some(program);
                    result
                }
                None => refused(result, Outcome::Missing),
            });
        }
        (None, Some(located)) => located,
    };
    result.notes.extend(located.note);
    if let Some((note, program)) = submission.run.as_ref().and_then(|run| delivered_note(run, &spec.file)) {
        result.notes.push(note);
        result.program = Some(program);
    }
    result.graded_file = Some(located.path.clone());
    if let Some(reason) = refuse_link(&located.path, &submission.path, integrity.links) {
        return Ok(refused(result, Outcome::Linked { reason }));
    }
    let submitted = match timed(&mut timings.decode, || read_png(&located.path)) {
        Ok(submitted) => submitted,
        Err(outcome) => return Ok(refused(result, outcome)),
    };
    result.notes.extend(submitted.notes);

    let copy_of_published =
        published.is_some_and(|hash| hash == timed(&mut timings.decode, || pixel_hash(&submitted.picture)));
    if copy_of_published {
        result.flags.push(PUBLISHED_COPY.to_owned());
    }
    let picture = submitted.picture;
    let copy = format!("{dir}/{}", spec.file);
    let tolerance = Tolerance {
        pixel: spec.rule.threshold,
        fail_fraction: spec.rule.pass_fraction,
        rmse: f64::INFINITY,
        max: None,
    };
    let compare_started = Instant::now();
    // A picture identical to the golden one (most of a class's) is measured as the golden against
    // itself: the same measurements, without making the picture's channel planes.
    let submitted_image;
    let actual = if golden.encoding == Encoding::Code8 && golden.preview == picture {
        golden
    } else {
        submitted_image = Image::from_rgb8(picture, located.path);
        &submitted_image
    };
    let (comparison, flip) = compare_timed(golden, actual, &tolerance, allowance);
    timings.compare += seconds(compare_started.elapsed().saturating_sub(flip));
    timings.flip += seconds(flip);
    let Some(metrics) = comparison.metrics else {
        // Both pictures are 8-bit RGB, so only their sizes can keep them from being compared.
        timed(&mut timings.report, || -> Result<(), OutputError> {
            Ok(replace_file(&out.join(&copy), &encode_png(&actual.preview)?)?)
        })?;
        result.student_image = Some(copy);
        let outcome = Outcome::WrongSize {
            expected: [golden.width, golden.height],
            actual: [actual.width, actual.height],
        };
        result.fingerprint =
            (!copy_of_published).then(|| timed(&mut timings.decode, || Fingerprint::of(&actual.preview, true)));
        return Ok(refused(result, outcome));
    };
    let (outcome, mut explanation) = judge(&spec.rule, &metrics);
    let report_started = Instant::now();
    if metrics.worst.is_none() {
        // Identical: the golden picture stands in for the student's, and there is no difference
        // to draw, which keeps the report of a good class small.
        result.student_image = Some(format!("{GOLDEN_DIR}/{}", spec.file));
    } else if outcome == Outcome::Pass {
        // Full points: a thumbnail shows what was handed in; there is nothing for the student to
        // find in a full-size copy or a heatmap. Thumbnails are named by their content and
        // shared, so that a class handing in the same passing pictures (the published reference
        // images) stores each once.
        let bytes = encode_png(&thumbnail(&actual.preview))?;
        let shared = format!("{THUMBNAILS_DIR}/{}.png", &blake3::hash(&bytes).to_hex()[..32]);
        if !out.join(&shared).is_file() {
            replace_file(&out.join(&shared), &bytes)?;
        }
        result.student_image = Some(shared);
    } else {
        replace_file(&out.join(&copy), &encode_png(&actual.preview)?)?;
        result.student_image = Some(copy);
        let heatmap = match allowance {
            Some(allowance) => diff_heatmap_widened(golden, actual, spec.rule.threshold, allowance),
            None => diff_heatmap(golden, actual, spec.rule.threshold),
        };
        if let Some(heatmap) = heatmap {
            let stem = spec.file.strip_suffix(".png").unwrap_or(&spec.file);
            let diff = format!("{dir}/{stem}.diff.png");
            replace_file(&out.join(&diff), &encode_png(&heatmap)?)?;
            result.diff_image = Some(diff);
        }
    }
    timings.report += seconds(report_started.elapsed());
    result.points = match outcome {
        Outcome::Pass => spec.points,
        Outcome::Partial => spec.points * spec.rule.partial_credit,
        _ => 0.0,
    };
    if copy_of_published && integrity.published_copy_credit < 1.0 {
        result.points *= integrity.published_copy_credit;
        explanation.push_str(&format!(
            " The picture is identical to the published reference: the rubric keeps {} of its points.",
            percent(integrity.published_copy_credit)
        ));
    }
    // Matching the golden or the published answer is not copying a classmate.
    if metrics.worst.is_some() && !copy_of_published {
        result.fingerprint = Some(timed(&mut timings.decode, || {
            Fingerprint::of(&actual.preview, outcome != Outcome::Pass)
        }));
    }
    result.outcome = outcome;
    result.explanation = explanation;
    result.metrics = Some(metrics);
    Ok(result)
}

/// The folder of the report holding passing pictures' thumbnails, named by content.
pub const THUMBNAILS_DIR: &str = "thumbnails";

/// The side of the square a passing picture's thumbnail fits in: the report shows pictures 300
/// pixels wide.
const THUMBNAIL: u32 = 300;

/// `picture` shrunk (never enlarged) to fit a [`THUMBNAIL`] square, keeping its aspect.
fn thumbnail(picture: &RgbImage) -> RgbImage {
    let (width, height) = picture.dimensions();
    let longest = width.max(height);
    if longest <= THUMBNAIL {
        return picture.clone();
    }
    let scale = |side: u32| ((u64::from(side) * u64::from(THUMBNAIL)) / u64::from(longest)).max(1) as u32;
    picture.shrunk(scale(width), scale(height))
}

/// A result with nothing compared: no points, and the outcome's reason as the explanation.
fn refused(mut result: ImageResult, outcome: Outcome) -> ImageResult {
    result.explanation = match &outcome {
        Outcome::Missing => format!("no {} in the folder", result.file),
        Outcome::WrongSize { expected, actual } => format!(
            "the picture is {}×{} pixels; the golden image is {}×{}",
            actual[0], actual[1], expected[0], expected[1]
        ),
        Outcome::WrongFormat { found } => format!("the file is {found}, not a PNG"),
        Outcome::TooLarge { reason } | Outcome::Unreadable { reason } | Outcome::Linked { reason } => reason.clone(),
        Outcome::Crashed | Outcome::TimedOut | Outcome::OverLimit | Outcome::ExitError | Outcome::NotRun => {
            format!("no {}: {}", result.file, outcome.word())
        }
        Outcome::Pass | Outcome::Partial | Outcome::Fail => String::new(),
    };
    result.outcome = outcome;
    result.points = 0.0;
    result
}
