//! What a diagnosis found, as `grades.json`, the CSV and the pages report it: the records only.
//! How they are found is `diagnose`'s job; keeping the records apart lets the score and the
//! report carry them without depending on the diagnosis itself.

use serde::{Deserialize, Serialize};

use crate::compare::Metrics;
use crate::fault::FaultSet;

/// The id of an image no known mistake explains.
pub const UNEXPLAINED: &str = "unexplained";

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

/// A student whose diagnoses name several parts of the assignment that were never written (the
/// starter code's `TODO`s as shipped: planes, triangles, transforms, the background…): one
/// finding, "unfinished", with the parts and the images each explains, rather than one mistake
/// per part. `grades.json` holds it per student.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Unfinished {
    /// "unfinished: planes, triangles and the background are not implemented".
    pub summary: String,
    pub parts: Vec<UnfinishedPart>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct UnfinishedPart {
    /// The catalogue id: `plane-missing`.
    pub id: String,
    /// What is not implemented: `planes`.
    pub part: String,
    /// The images whose diagnosis names it, in rubric order.
    pub images: Vec<String>,
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

/// The failing fraction and RMSE of one picture against another.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Residual {
    /// Pixels (or blocks) with a channel more than the rubric's threshold away.
    pub failing_fraction: f64,
    /// Over every channel, in 8-bit codes.
    pub rmse: f64,
}
