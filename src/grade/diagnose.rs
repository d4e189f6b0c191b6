//! Diagnosis: which classic mistake explains an image that lost points.
//!
//! For every render of the rubric that a student image lost points on, the render's pictures are
//! drawn again under each fault of the catalogue (`crate::fault`) that the scene can show in
//! them, once per rubric (and cached beside the golden renders, see [`pictures`]). Each image
//! that lost points is then compared with every such picture, and a fault **explains** it when
//! the image is much closer to the fault's picture than to the golden one:
//!
//! 1. the failing fraction against the fault's picture is at most 1/[`FAILING_REDUCTION`] of the
//!    failing fraction against the golden picture, and the RMSE at most 1/[`RMSE_REDUCTION`] of
//!    the golden's, or at most [`RMSE_FLOOR`] codes (an image that lost points on FLIP alone,
//!    with hardly any failing pixel, needs its RMSE divided by [`FAILING_REDUCTION`] instead,
//!    and no more failing pixels);
//! 2. and the student's image would pass or nearly pass against the fault's picture: within the
//!    rubric's partial-credit limits (failing fraction, and FLIP when the rubric judges it).
//!
//! Among the faults that explain an image the closest wins (fewest failing pixels, then RMSE),
//! a single fault before a pair unless the pair is [`FAILING_REDUCTION`] times closer. When no
//! single fault explains an image, the rest of each promising family is tried (every member of
//! `wrong-bounces`, the unnormalised reflection's lengths, a gamma fitted by golden-section
//! search) and then pairs of the faults that explained part of it. What nothing explains is
//! `unexplained`. Speckled mistakes (acne) are compared over blocks, where an independent
//! program's speckles, drawn elsewhere, have the same density.

mod batch;
mod candidates;
mod pictures;
mod residual;

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use image::RgbImage;
use serde::{Deserialize, Serialize};

use super::outcome::Outcome;
use super::rubric::{ImageSpec, Output, Rubric, Rule};
use super::score::{ImageResult, StudentResult, judge};
use crate::atomic_write::replace_file;
use crate::compare::{Image, Metrics, Tolerance, compare, diff_heatmap};
use crate::fault::{Fault, FaultSet, Gamma, Parameter};
use crate::film::{Picture, encode_png, picture_with_faults};
pub(super) use batch::{Diagnoser, prepare_mistakes};
pub use residual::Residual;

/// A fault explains an image only if the image fails at most this many times fewer pixels
/// against the fault's picture than against the golden one.
pub const FAILING_REDUCTION: f64 = 4.0;
/// …and its RMSE against the fault's picture is this many times smaller, or at most
/// [`RMSE_FLOOR`] (and smaller than the golden's).
pub const RMSE_REDUCTION: f64 = 2.0;
/// An RMSE an independent program's rounding and sampling can reach by themselves, in 8-bit
/// codes (±3 codes of uniform noise on every channel is an RMSE of 2).
pub const RMSE_FLOOR: f64 = 3.0;
/// A fault that brings the failing fraction below this share of the golden's explains part of
/// the image: its family is searched further and it is paired with the others.
const PROMISING: f64 = 0.7;
/// How many of the partly explaining faults are paired, each with how many partners, and how
/// much of the pixels it leaves failing a partner must change to be one.
const PAIRED: usize = 3;
const PARTNERS: usize = 3;
/// A partner must bring A's RMSE down to this share of it (in the prediction).
const PARTNER_GAIN: f64 = 0.8;
/// Where the pictures of the faults go in the report.
pub const MISTAKES_DIR: &str = "mistakes";

/// What explains an image that lost points. `grades.json` holds it per image, only for images
/// that did not get full points.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Diagnosis {
    /// A catalogue id, two joined by `+`, or `unexplained`.
    pub id: String,
    /// The fault set with its family members: `gamma-applied=2.35`, `wrong-bounces=3`.
    pub faults: Option<String>,
    /// For the student: what the program does.
    pub explanation: String,
    /// Where in the assignment's code each mistake usually lives.
    pub hints: Vec<String>,
    pub confidence: Confidence,
    /// The share of the pixels failing against the golden picture that the mistake accounts for.
    pub explained: f64,
    /// Failing fraction and RMSE against the golden picture, measured as against the mistake's.
    pub golden: Residual,
    /// The student's image against the mistake's picture: failing fraction and RMSE as the
    /// decision measured them.
    pub residual: Option<Residual>,
    /// The full comparison with the mistake's picture (FLIP included), as the report shows it.
    pub residual_metrics: Option<Metrics>,
    /// `pixels`, or `blocks of N×N pixels` for speckled mistakes.
    pub compared_by: String,
    /// Other mistakes that explain the image nearly as well.
    pub alternatives: Vec<String>,
    /// For an unexplained image: the mistake that came closest, and how much it explained.
    pub closest: Option<Closest>,
    /// The mistake's picture, relative to the report directory.
    pub mistake_image: Option<String>,
    /// The difference between the student's picture and the mistake's.
    pub residual_image: Option<String>,
    /// The share of the points granted for this mistake by the rubric (`[mistake."ID"] credit`).
    pub credit: Option<f64>,
    /// Other fault sets that explain the image exactly as well (drawing the same picture here),
    /// for choosing among them by the student's other images.
    #[serde(skip)]
    pub ties: Vec<FaultSet>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Confidence {
    /// The image passes against the mistake's picture and no other mistake comes close.
    High,
    /// It only nearly passes, or another mistake explains it about as well.
    Medium,
    /// Unexplained.
    None,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Closest {
    pub id: String,
    pub faults: String,
    pub explained: f64,
}

/// What diagnosing a class cost, render by render, for `grades.json` and the summary.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct DiagnosisRun {
    pub seconds: f64,
    /// Images that lost points, and how many of them a mistake explains.
    pub images: usize,
    pub explained: usize,
    pub renders: Vec<RenderDiagnosis>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RenderDiagnosis {
    pub render: String,
    pub images: usize,
    /// Fault sets compared with the images; those rendered now and those read from the cache.
    pub fault_sets: usize,
    pub rendered: usize,
    pub cached: usize,
    pub seconds: f64,
    /// Fault sets that could not be rendered, with the reason; left out of the comparison.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub failed: Vec<String>,
}

/// Whether an image lost points on a comparison (a missing or unreadable file has nothing to
/// diagnose).
pub fn loses_points(result: &ImageResult) -> bool {
    matches!(result.outcome, Outcome::Partial | Outcome::Fail)
}

/// A fault set with its pictures, in the store's picture order.
struct Candidate {
    set: FaultSet,
    pictures: Arc<Vec<RgbImage>>,
}

/// One candidate measured against one student image.
#[derive(Clone, Copy, Debug)]
struct Scored {
    set: FaultSet,
    residual: Residual,
    /// What the golden scored by the same measure (blocks for speckles).
    golden: Residual,
    speckle: bool,
}

impl Scored {
    fn explains(&self, rule: &Rule) -> bool {
        explains(&self.golden, &self.residual, rule)
    }

    fn share_explained(&self) -> f64 {
        if self.golden.failing_fraction > 0.0 {
            (1.0 - self.residual.failing_fraction / self.golden.failing_fraction).max(0.0)
        } else {
            (1.0 - self.residual.rmse / self.golden.rmse.max(1e-9)).max(0.0)
        }
    }

    /// Whether the fault explains part of the image: fewer failing pixels or a smaller RMSE.
    fn promising(&self) -> bool {
        self.residual.rmse < self.golden.rmse
            && (self.residual.failing_fraction <= self.golden.failing_fraction * PROMISING
                || self.residual.rmse <= self.golden.rmse * PROMISING)
    }

    /// How much of the golden's error is left, by the better of the two measures (smaller is
    /// closer).
    fn left(&self) -> f64 {
        let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 1.0 };
        ratio(self.residual.failing_fraction, self.golden.failing_fraction)
            .min(ratio(self.residual.rmse, self.golden.rmse))
    }

    fn key(&self) -> (f64, f64) {
        (self.residual.failing_fraction, self.residual.rmse)
    }
}

/// The decision rule's measurements (the module documentation says it in words).
pub fn explains(golden: &Residual, residual: &Residual, rule: &Rule) -> bool {
    let flip_only = golden.failing_fraction <= rule.pass_fraction;
    let (failing_ok, rmse_limit) = if flip_only {
        (
            residual.failing_fraction <= golden.failing_fraction,
            golden.rmse / FAILING_REDUCTION,
        )
    } else {
        (
            residual.failing_fraction <= golden.failing_fraction / FAILING_REDUCTION,
            golden.rmse / RMSE_REDUCTION,
        )
    };
    let rmse_ok = residual.rmse < golden.rmse && residual.rmse <= rmse_limit.max(RMSE_FLOOR);
    failing_ok && rmse_ok && residual.failing_fraction <= rule.partial_fraction
}

/// One student image being diagnosed.
struct Subject<'a> {
    spec: &'a ImageSpec,
    /// Index into the store's pictures.
    picture: usize,
    student: RgbImage,
    golden: &'a RgbImage,
    by_pixel: Residual,
    by_block: Residual,
    block: u32,
}

impl Subject<'_> {
    fn score(&self, candidate: &Candidate) -> Option<Scored> {
        let picture = &candidate.pictures[self.picture];
        if picture == self.golden {
            // The fault does not change this picture: it cannot explain anything here.
            return None;
        }
        Some(self.score_picture(candidate.set, picture))
    }

    fn score_picture(&self, set: FaultSet, picture: &RgbImage) -> Scored {
        let threshold = self.spec.rule.threshold;
        let speckle = set.faults().any(Fault::is_speckle);
        let (residual, golden) = if speckle {
            (
                residual::block_residual(picture, &self.student, threshold, self.block),
                self.by_block,
            )
        } else {
            (residual::residual(picture, &self.student, threshold), self.by_pixel)
        };
        Scored {
            set,
            residual,
            golden,
            speckle,
        }
    }
}

/// The id of an image no mistake explains.
pub const UNEXPLAINED: &str = "unexplained";

fn film_picture(output: Output) -> Picture {
    match output {
        Output::Color => Picture::Color,
        Output::Normals => Picture::Normals,
        Output::Depth { min, max } => Picture::Depth {
            min: min as f32,
            max: max as f32,
        },
    }
}

fn student_dir(student: &StudentResult) -> String {
    student.page.strip_suffix(".html").unwrap_or(&student.page).to_owned()
}

/// What to render next for an image no single fault explains cleanly: the other members of the
/// promising families, and pairs: each of the closest promising faults with the faults that
/// change most of the pixels it leaves failing.
/// `cubemap-ignored` with the flat colour the student's picture shows where the golden rays
/// miss, when it shows one there (the course's scenes give a colour beside the cube map, which
/// the import drops): the median of those pixels, if most of them are within the rubric's
/// threshold of it.
fn fit_background(subject: &Subject, misses: &[bool], singles: &[Candidate]) -> Option<FaultSet> {
    let tried = singles.iter().any(|c| c.set.contains(Fault::CubemapIgnored));
    if !tried || subject.golden.len() != misses.len() * 3 {
        return None;
    }
    let seen: Vec<[u8; 3]> = subject
        .student
        .pixels()
        .zip(misses)
        .filter(|(_, miss)| **miss)
        .map(|(p, _)| p.0)
        .collect();
    if seen.len() * 100 < misses.len() {
        return None;
    }
    let median = [0, 1, 2].map(|c| {
        let mut values: Vec<u8> = seen.iter().map(|p| p[c]).collect();
        values.sort_unstable();
        values[values.len() / 2]
    });
    let threshold = subject.spec.rule.threshold;
    let close = seen
        .iter()
        .filter(|p| p.iter().zip(median).all(|(v, m)| f64::from(v.abs_diff(m)) <= threshold))
        .count();
    (close * 5 >= seen.len() * 4 && median != [0; 3])
        .then(|| FaultSet::NONE.with(crate::fault::Parameter::Background(median)))
}

fn expansions(case: &crate::case::Case, subject: &Subject, scores: &[Scored], singles: &[Candidate]) -> Vec<FaultSet> {
    let rule = &subject.spec.rule;
    let mut promising: Vec<&Scored> = scores.iter().filter(|s| s.promising()).collect();
    promising.sort_by(|a, b| a.left().partial_cmp(&b.left()).unwrap_or(std::cmp::Ordering::Equal));
    let mut wanted = Vec::new();
    for scored in &promising {
        for fault in scored
            .set
            .faults()
            .filter(|f| f.is_family() && *f != Fault::GammaApplied)
        {
            wanted.extend(candidates::members(case, fault));
        }
    }
    let passes = |s: &Scored| s.explains(rule) && s.residual.failing_fraction <= rule.pass_fraction;
    if scores.iter().any(|s| s.set.len() == 1 && passes(s)) {
        return wanted;
    }
    let picture = |set: &FaultSet| {
        singles
            .iter()
            .find(|c| c.set == *set)
            .map(|c| &c.pictures[subject.picture])
    };
    let threshold = rule.threshold;
    for a in promising.iter().take(PAIRED) {
        let Some(a_picture) = picture(&a.set) else { continue };
        // Each partner B predicted without a render: A's picture plus what B changes in the
        // golden one (flipped to A's orientation, or A flipped when B is a flip). Additive
        // changes (a light, a shadow, a highlight) compose exactly, the others roughly; the
        // prediction only chooses which pairs to render.
        let mut partners: Vec<(f64, FaultSet)> = singles
            .iter()
            .filter(|b| b.set != a.set && b.pictures[subject.picture] != *subject.golden)
            .filter_map(|b| {
                let set = candidates::pair(&a.set, &b.set)?;
                let predicted = predict(a_picture, &a.set, &b.pictures[subject.picture], &b.set, subject.golden);
                let r = residual::residual(&predicted, &subject.student, threshold);
                (r.rmse <= a.residual.rmse * PARTNER_GAIN && r.failing_fraction <= a.residual.failing_fraction)
                    .then_some((r.rmse, set))
            })
            .collect();
        partners.sort_by(|x, y| x.0.partial_cmp(&y.0).unwrap_or(std::cmp::Ordering::Equal));
        wanted.extend(partners.into_iter().take(PARTNERS).map(|(_, set)| set));
    }
    wanted
}

/// The picture of A and B together, predicted from their pictures alone (see [`expansions`]).
fn predict(a: &RgbImage, a_set: &FaultSet, b: &RgbImage, b_set: &FaultSet, golden: &RgbImage) -> RgbImage {
    use crate::fault::Mapping;
    let flip = |image: &RgbImage, mapping: Option<Mapping>| match mapping {
        Some(Mapping::UpsideDown) => image::imageops::flip_vertical(image),
        Some(Mapping::Mirrored) => image::imageops::flip_horizontal(image),
        _ => image.clone(),
    };
    let b_flip = b_set.mapping().filter(|m| *m != Mapping::Centres);
    if b_flip.is_some() {
        return flip(a, b_flip);
    }
    let a_flip = a_set.mapping().filter(|m| *m != Mapping::Centres);
    let (b, golden) = (flip(b, a_flip), flip(golden, a_flip));
    let mut out = a.clone();
    for ((o, b), g) in out.pixels_mut().zip(b.pixels()).zip(golden.pixels()) {
        for c in 0..3 {
            o.0[c] = (i32::from(o.0[c]) + i32::from(b.0[c]) - i32::from(g.0[c])).clamp(0, 255) as u8;
        }
    }
    out
}

/// `gamma-applied` with the γ that fits the image best (golden-section search on the RMSE),
/// when a gamma member looked promising; quantised from the golden film, so nothing renders.
fn fit_gamma(subject: &Subject, store: &pictures::FaultPictures, scores: &[Scored]) -> Option<Scored> {
    let promising = scores
        .iter()
        .any(|s| s.set.contains(Fault::GammaApplied) && s.set.len() == 1 && s.promising());
    if !promising || store.pictures()[subject.picture] != Picture::Color {
        return None;
    }
    let picture = |gamma: f64| {
        let set = FaultSet::NONE.with(Parameter::Gamma(Gamma::Power(gamma)));
        (
            set,
            picture_with_faults(store.golden_film(), Picture::Color, store.tonemap(), &set),
        )
    };
    let cost = |gamma: f64| {
        let (set, image) = picture(gamma);
        subject.score_picture(set, &image).residual.rmse
    };
    let (mut lo, mut hi) = (1.0f64, 3.4f64);
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
    let (mut fa, mut fb) = (cost(a), cost(b));
    for _ in 0..16 {
        if fa <= fb {
            hi = b;
            (b, fb) = (a, fa);
            a = hi - ratio * (hi - lo);
            fa = cost(a);
        } else {
            lo = a;
            (a, fa) = (b, fb);
            b = lo + ratio * (hi - lo);
            fb = cost(b);
        }
    }
    let gamma = ((lo + hi) / 2.0 * 100.0).round() / 100.0;
    let (set, image) = picture(gamma);
    Some(subject.score_picture(set, &image))
}

/// The decision for one image (the module documentation's rule), with its pictures written.
#[allow(clippy::too_many_arguments)]
fn decide(
    subject: &Subject,
    scores: &[Scored],
    store: &pictures::FaultPictures,
    expanded: &[&Candidate],
    singles: &[Candidate],
    out: &Path,
    student_dir: &str,
    written: &Mutex<HashSet<PathBuf>>,
) -> Diagnosis {
    let rule = &subject.spec.rule;
    let mut explaining: Vec<&Scored> = scores.iter().filter(|s| s.explains(rule)).collect();
    explaining.sort_by(|a, b| a.key().partial_cmp(&b.key()).unwrap_or(std::cmp::Ordering::Equal));
    // Parsimony: the closest single fault, unless a pair is far closer.
    let best_single = explaining.iter().find(|s| s.set.len() == 1).copied();
    let best_pair = explaining.iter().find(|s| s.set.len() > 1).copied();
    let mut order: Vec<&Scored> = match (best_single, best_pair) {
        (Some(single), Some(pair)) if pair.left() * FAILING_REDUCTION < single.left() => {
            vec![pair, single]
        }
        (Some(single), _) => vec![single],
        (None, Some(pair)) => vec![pair],
        (None, None) => Vec::new(),
    };
    let rest: Vec<&Scored> = explaining
        .iter()
        .filter(|s| !order.iter().any(|o| o.set == s.set))
        .take(3)
        .copied()
        .collect();
    order.extend(rest);
    let picture_of = |set: &FaultSet| -> Option<RgbImage> {
        let index = subject.picture;
        if let Some(candidate) = singles.iter().chain(expanded.iter().copied()).find(|c| c.set == *set) {
            return Some(candidate.pictures[index].clone());
        }
        if let Some(known) = store.get_if_known(set) {
            return Some(known[index].clone());
        }
        // A fitted gamma: quantised from the golden film.
        let picture = store.pictures()[index];
        (set.render_part().is_empty()).then(|| picture_with_faults(store.golden_film(), picture, store.tonemap(), set))
    };
    let tolerance = Tolerance {
        pixel: rule.threshold,
        fail_fraction: rule.pass_fraction,
        rmse: f64::INFINITY,
        max: None,
    };
    let file = &subject.spec.file;
    let student = Image::from_rgb8(subject.student.clone(), file.clone());
    for scored in order {
        let Some(mistake) = picture_of(&scored.set) else {
            continue;
        };
        let expected = Image::from_rgb8(mistake.clone(), scored.set.to_string());
        let Some(metrics) = compare(&expected, &student, &tolerance).metrics else {
            continue;
        };
        // Within the partial limits, FLIP included; speckles are judged by their blocks.
        if !scored.speckle && judge(rule, &metrics).0 == Outcome::Fail {
            continue;
        }
        let passes = if scored.speckle {
            scored.residual.failing_fraction <= rule.pass_fraction
        } else {
            judge(rule, &metrics).0 == Outcome::Pass
        };
        let alternatives: Vec<String> = explaining
            .iter()
            .filter(|s| s.set.id() != scored.set.id() && s.set.len() <= scored.set.len())
            .filter(|s| {
                s.residual.failing_fraction
                    <= (2.0 * scored.residual.failing_fraction).max(scored.residual.failing_fraction + 0.001)
                    && s.residual.rmse <= 1.5 * scored.residual.rmse + 0.5
            })
            .map(|s| s.set.id())
            .fold(Vec::new(), |mut ids, id| {
                if !ids.contains(&id) {
                    ids.push(id);
                }
                ids
            });
        let (mistake_image, residual_image) = write_pictures(
            &scored.set,
            &mistake,
            &expected,
            &student,
            subject,
            out,
            student_dir,
            written,
        );
        return Diagnosis {
            id: scored.set.id(),
            faults: Some(scored.set.to_string()),
            explanation: scored.set.explain(),
            hints: scored.set.faults().map(|f| f.hint().to_owned()).collect(),
            confidence: if passes && alternatives.is_empty() {
                Confidence::High
            } else {
                Confidence::Medium
            },
            explained: scored.share_explained(),
            golden: scored.golden,
            residual: Some(scored.residual),
            residual_metrics: Some(metrics),
            compared_by: compared_by(scored, subject.block),
            alternatives,
            closest: None,
            mistake_image,
            residual_image,
            credit: None,
            ties: explaining
                .iter()
                .filter(|s| s.set.id() != scored.set.id() && s.set.len() == scored.set.len())
                .filter(|s| s.residual == scored.residual && s.golden == scored.golden)
                .map(|s| s.set)
                .collect(),
        };
    }
    // Unexplained: name the closest mistake, if any came closer than the golden picture.
    let closest = scores.iter().filter(|s| s.share_explained() > 0.0).max_by(|a, b| {
        a.share_explained()
            .partial_cmp(&b.share_explained())
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let (mut mistake_image, mut residual_image) = (None, None);
    if let Some(closest) = closest
        && let Some(mistake) = picture_of(&closest.set)
    {
        let expected = Image::from_rgb8(mistake.clone(), closest.set.to_string());
        (mistake_image, residual_image) = write_pictures(
            &closest.set,
            &mistake,
            &expected,
            &student,
            subject,
            out,
            student_dir,
            written,
        );
    }
    Diagnosis {
        id: UNEXPLAINED.to_owned(),
        faults: None,
        explanation: "no mistake of the catalogue, alone or with another, explains this image".to_owned(),
        hints: Vec::new(),
        confidence: Confidence::None,
        explained: 0.0,
        golden: subject.by_pixel,
        residual: None,
        residual_metrics: None,
        compared_by: "pixels".to_owned(),
        alternatives: Vec::new(),
        closest: closest.map(|c| Closest {
            id: c.set.id(),
            faults: c.set.to_string(),
            explained: c.share_explained(),
        }),
        mistake_image,
        residual_image,
        credit: None,
        ties: Vec::new(),
    }
}

fn compared_by(scored: &Scored, block: u32) -> String {
    if scored.speckle {
        format!("blocks of {block}×{block} pixels")
    } else {
        "pixels".to_owned()
    }
}

/// The mistake's picture (`mistakes/SET/FILE`, once per run) and the student's difference from
/// it (`students/NAME/STEM.mistake.png`), relative to the report directory. Pictures that cannot
/// be written are left out of the report rather than failing it.
#[allow(clippy::too_many_arguments)]
fn write_pictures(
    set: &FaultSet,
    mistake: &RgbImage,
    expected: &Image,
    student: &Image,
    subject: &Subject,
    out: &Path,
    student_dir: &str,
    written: &Mutex<HashSet<PathBuf>>,
) -> (Option<String>, Option<String>) {
    let file = &subject.spec.file;
    let mistake_path = format!("{MISTAKES_DIR}/{set}/{file}");
    let absolute = out.join(&mistake_path);
    let first = written
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .insert(absolute.clone());
    let mistake_ok = !first || encode_png(mistake).is_ok_and(|bytes| replace_file(&absolute, &bytes).is_ok());
    let stem = file.strip_suffix(".png").unwrap_or(file);
    let residual_path = format!("{student_dir}/{stem}.mistake.png");
    let residual_ok = diff_heatmap(expected, student, subject.spec.rule.threshold).is_some_and(|heatmap| {
        encode_png(&heatmap).is_ok_and(|bytes| replace_file(&out.join(&residual_path), &bytes).is_ok())
    });
    (mistake_ok.then_some(mistake_path), residual_ok.then_some(residual_path))
}

/// The rubric's credit for diagnosed mistakes (`[mistake."ID"] credit`): an image whose diagnosis
/// names only credited mistakes gets at least the product of their credits times its points.
/// Without credits nothing changes.
pub(super) fn apply_credit(rubric: &Rubric, students: &mut [StudentResult]) {
    if rubric.mistake_credit.is_empty() {
        return;
    }
    let credit_of = |id: &str| {
        rubric
            .mistake_credit
            .iter()
            .find(|(f, _)| f.name() == id)
            .map(|(_, c)| *c)
    };
    for student in students.iter_mut() {
        for image in &mut student.images {
            let Some(diagnosis) = &mut image.diagnosis else {
                continue;
            };
            if diagnosis.id == UNEXPLAINED {
                continue;
            }
            let credits: Option<Vec<f64>> = diagnosis.id.split('+').map(credit_of).collect();
            let Some(credit) = credits.map(|c| c.iter().product::<f64>()) else {
                continue;
            };
            let points = image.max_points * credit;
            if points > image.points {
                image.points = points;
                diagnosis.credit = Some(credit);
                image.explanation.push_str(&format!(
                    "; the rubric grants {} of the points for the diagnosed mistake {}",
                    super::score::percent(credit),
                    diagnosis.id
                ));
            }
        }
        student.recount();
    }
}

/// Where mistakes tie on an image (they draw the same picture there), the one the student's other
/// images are diagnosed with, unambiguously, is named: a depth image that an inverted depth and a
/// missing object both turn black is blamed on the inverted depth of a student whose other depth
/// images are inverted.
pub(super) fn prefer_consistent(students: &mut [StudentResult]) {
    for student in students.iter_mut() {
        let clear: Vec<String> = student
            .images
            .iter()
            .filter_map(|i| i.diagnosis.as_ref())
            .filter(|d| d.ties.is_empty() && d.id != UNEXPLAINED)
            .flat_map(|d| d.id.split('+').map(str::to_owned).collect::<Vec<_>>())
            .collect();
        let made = |set: &FaultSet| set.faults().all(|f| clear.iter().any(|id| id == f.name()));
        for image in &mut student.images {
            let Some(diagnosis) = &mut image.diagnosis else {
                continue;
            };
            let current = diagnosis.id.parse::<FaultSet>().ok();
            if current.as_ref().is_some_and(made) {
                continue;
            }
            let Some(better) = diagnosis.ties.iter().find(|t| made(t)).copied() else {
                continue;
            };
            let previous = std::mem::replace(&mut diagnosis.id, better.id());
            diagnosis.alternatives.retain(|a| *a != diagnosis.id);
            diagnosis.alternatives.insert(0, previous);
            diagnosis.faults = Some(better.to_string());
            diagnosis.explanation = better.explain();
            diagnosis.hints = better.faults().map(|f| f.hint().to_owned()).collect();
        }
    }
}
