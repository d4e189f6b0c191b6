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
//! `unexplained`. Speckled mistakes (acne) alone are recognised by their signature
//! ([`signature`]): an independent program's speckles fall elsewhere and come at another
//! density, but darken the same surfaces in scattered pixels; with another mistake they are
//! compared over blocks. Fault sets of any size are grown for images nothing smaller explains
//! ([`grow`]) and, for unfinished work whose parts show only together, shrunk from every part
//! not written ([`shrink`]); a set naming a mistake in written code must be clearly closer than any set of
//! parts not written ([`decide`]).

mod batch;
mod candidates;
mod decide;
mod expand;
mod grow;
mod mask;
mod pictures;
mod residual;
mod shrink;
mod signature;
mod student;

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use crate::rgb_image::RgbImage;

use super::diagnosis::{
    Closest, Confidence, Diagnosis, DiagnosisRun, RenderDiagnosis, Residual, UNEXPLAINED, Unfinished, UnfinishedPart,
};
use super::judge::judge;
use super::outcome::Outcome;
use super::rubric::{ImageSpec, Rubric, Rule};
use super::score::{ImageResult, StudentResult};
use crate::atomic_write::replace_file;
use crate::compare::{Image, Tolerance, compare, diff_heatmap};
use crate::fault::{Fault, FaultSet, Gamma, Parameter};
use crate::film::{Picture, encode_png, picture_with_faults};
pub(super) use batch::{Diagnoser, prepare_mistakes};
use decide::decide;
use expand::{expansions, fit_background, fit_gamma};
pub(super) use student::{apply_credit, gather_unfinished, prefer_consistent};

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

/// Whether an image lost points on a comparison (a missing or unreadable file has nothing to
/// diagnose).
pub fn loses_points(result: &ImageResult) -> bool {
    matches!(result.outcome, Outcome::Partial | Outcome::Fail)
}

/// A fault set with its pictures, in the store's picture order.
struct Candidate {
    set: FaultSet,
    pictures: pictures::SetPictures,
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

    /// How many of the set's faults are mistakes in written code rather than parts not written.
    fn specific(&self) -> usize {
        self.set.faults().filter(|f| f.unfinished_part().is_none()).count()
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
        let picture: &RgbImage = &candidate.pictures[self.picture];
        // Most sets share the golden picture itself; the others are compared byte by byte.
        if std::ptr::eq(picture, self.golden) || picture == self.golden {
            // The fault does not change this picture: it cannot explain anything here.
            return None;
        }
        Some(self.score_picture(candidate.set, picture))
    }

    fn score_picture(&self, set: FaultSet, picture: &RgbImage) -> Scored {
        let threshold = self.spec.rule.threshold;
        let speckle = set.faults().any(Fault::is_speckle);
        // Shadow acne only darkens, which moving the camera by a fraction of a pixel does not do
        // in scattered pixels of lit surfaces alone; reflection acne changes a mirror either way,
        // as such a move does to a reflected texture, so it keeps the comparison over blocks.
        let (residual, golden) = if set == FaultSet::single(Fault::ShadowAcne) {
            (
                signature::acne_residual(self.golden, picture, &self.student, threshold),
                self.by_pixel,
            )
        } else if speckle {
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

fn student_dir(student: &StudentResult) -> String {
    student.page.strip_suffix(".html").unwrap_or(&student.page).to_owned()
}
