//! One comparison from start to finish, and the report a person reads (or a script parses).

use std::fmt;
use std::path::PathBuf;
use std::time::Duration;

use serde::Serialize;

use super::image::{COLOR_CHANNELS, Encoding, Image};
use super::metrics::{ColourRule, Metrics, measure, same_layout};
use super::noise::{self, Noise};
use super::tolerance::Tolerance;
use super::verdict::{Layout, Verdict, judge, percent};

/// The outcome of comparing `actual` against `expected`. `metrics` is `None` only for a
/// [`Verdict::Mismatch`].
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    pub expected: PathBuf,
    pub actual: PathBuf,
    pub tolerance: Tolerance,
    pub metrics: Option<Metrics>,
    /// The statistical test, when both images carry the variance of their mean colour.
    pub noise: Option<Noise>,
    pub verdict: Verdict,
    /// Where the caller wrote the diff heatmap, for the report to point at.
    pub diff_image: Option<PathBuf>,
}

/// Compares `actual` against `expected` under `tolerance`, in the images' own units. When both
/// are EXRs with variance channels (sampled renders), colour values with variance are judged by
/// the statistical test of [`noise`](super::noise) and the rest by `tolerance`.
///
/// A NaN limit counts as 0, the strictest: every comparison with NaN is false, so taken as given
/// it would let any difference through.
pub fn compare(expected: &Image, actual: &Image, tolerance: &Tolerance) -> Comparison {
    compare_timed(expected, actual, tolerance, None).0
}

/// [`compare`] of two images without variance (a student's 8-bit picture against the golden's),
/// each colour value's `pixel` threshold widened by its `allowance` (see
/// [`noise::png_allowance`]): the statistical verdict where only the golden knows its noise.
pub fn compare_widened(expected: &Image, actual: &Image, tolerance: &Tolerance, allowance: &[[f32; 3]]) -> Comparison {
    compare_timed(expected, actual, tolerance, Some(allowance)).0
}

/// [`compare`], or [`compare_widened`] with an `allowance`, and how long its FLIP measurement took
/// (zero when nothing was measured), for callers that report where their time goes.
pub fn compare_timed(
    expected: &Image,
    actual: &Image,
    tolerance: &Tolerance,
    allowance: Option<&[[f32; 3]]>,
) -> (Comparison, Duration) {
    let strict = |limit: f64| if limit.is_nan() { 0.0 } else { limit };
    let tolerance = &Tolerance {
        pixel: strict(tolerance.pixel),
        fail_fraction: strict(tolerance.fail_fraction),
        rmse: strict(tolerance.rmse),
        max: tolerance.max.map(strict),
    };
    let widened = allowance.filter(|a| a.len() == expected.pixels());
    let (metrics, noise, verdict, flip) = if same_layout(expected, actual) {
        let sigmas = noise::sigmas(expected, actual).filter(|_| widened.is_none());
        let colour = match (&sigmas, widened) {
            (_, Some(allowance)) => ColourRule::Widened(allowance),
            (Some(sigmas), None) => ColourRule::Tested(sigmas),
            (None, None) => ColourRule::Threshold,
        };
        let (metrics, flip) = measure(expected, actual, tolerance.pixel, colour);
        let noise = sigmas.map(|sigmas| noise::test(expected, actual, &sigmas, tolerance));
        let verdict = judge(&metrics, tolerance, noise.as_ref());
        (Some(metrics), noise, verdict, flip)
    } else {
        let verdict = Verdict::Mismatch {
            expected: Layout::of(expected),
            actual: Layout::of(actual),
        };
        (None, None, verdict, Duration::ZERO)
    };
    let comparison = Comparison {
        expected: expected.source.clone(),
        actual: actual.source.clone(),
        tolerance: tolerance.clone(),
        metrics,
        noise,
        verdict,
        diff_image: None,
    };
    (comparison, flip)
}

#[derive(Serialize)]
struct JsonTolerance {
    pixel: f64,
    fail_fraction: f64,
    rmse: f64,
    max: Option<f64>,
}

#[derive(Serialize)]
struct JsonReport<'a> {
    #[serde(flatten)]
    verdict: &'a Verdict,
    exit_code: u8,
    expected: &'a PathBuf,
    actual: &'a PathBuf,
    tolerance: JsonTolerance,
    metrics: &'a Option<Metrics>,
    noise: &'a Option<Noise>,
    diff_image: &'a Option<PathBuf>,
}

impl Comparison {
    /// The report as pretty-printed JSON, the verdict first. Infinite and NaN numbers (the PSNR
    /// of identical images, a NaN pixel value) become `null`, as JSON has no such numbers.
    pub fn to_json(&self) -> String {
        let t = &self.tolerance;
        let report = JsonReport {
            expected: &self.expected,
            actual: &self.actual,
            verdict: &self.verdict,
            exit_code: self.verdict.exit_code(),
            tolerance: JsonTolerance {
                pixel: t.pixel,
                fail_fraction: t.fail_fraction,
                rmse: t.rmse,
                max: t.max,
            },
            metrics: &self.metrics,
            noise: &self.noise,
            diff_image: &self.diff_image,
        };
        serde_json::to_string_pretty(&report)
            .unwrap_or_else(|e| serde_json::json!({ "error": e.to_string() }).to_string())
    }
}

impl fmt::Display for Comparison {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{}: {} against {}",
            self.verdict.word(),
            self.actual.display(),
            self.expected.display()
        )?;
        match &self.verdict {
            Verdict::Mismatch { expected, actual } => {
                writeln!(f, "  cannot compare: {}", mismatch(expected, actual))?;
            }
            Verdict::Fail { breaches } => {
                for breach in breaches {
                    writeln!(f, "  broke {breach}")?;
                }
            }
            Verdict::Pass | Verdict::Warn => {}
        }
        if let Some(noise) = &self.noise {
            write_noise(f, noise)?;
        }
        if let Some(metrics) = &self.metrics {
            write_metrics(f, metrics, self.noise.is_some())?;
        }
        if let Some(path) = &self.diff_image {
            let legend = if self.noise.is_some() {
                "|z| from 1 (dark red) to the threshold (yellow); magenta = significant or failing, cyan = NaN/inf"
            } else {
                "magenta = failing pixel, cyan = NaN/inf"
            };
            writeln!(f, "  diff heatmap: {} ({legend})", path.display())?;
        }
        Ok(())
    }
}

/// The statistical test's lines: what was tested, what it found, and what it could have found.
fn write_noise(f: &mut fmt::Formatter<'_>, noise: &Noise) -> fmt::Result {
    writeln!(
        f,
        "  statistical test: {} colour values with variance, Šidák-corrected Z test at α = {} \
         (|z| over {:.2}); {} significant",
        noise.tests, noise.alpha, noise.z_critical, noise.significant
    )?;
    if let Some(strongest) = &noise.strongest {
        writeln!(
            f,
            "  strongest evidence: z = {:.2} at {} (σ {:.3e})",
            strongest.z, strongest.at, strongest.sigma
        )?;
    }
    let p = &noise.power;
    let shift = |s: Option<f64>| s.map_or_else(|| "none".to_owned(), |s| format!("{s:.2e}"));
    writeln!(
        f,
        "  power: detects with {:.0}% probability a shift of {} on every colour value, or of {} over a {}×{} \
         area ({} where it sees least)",
        p.probability * 100.0,
        shift(p.uniform_shift),
        shift(p.local_shift_median),
        p.window,
        p.window,
        shift(p.local_shift_worst),
    )
}

fn write_metrics(f: &mut fmt::Formatter<'_>, m: &Metrics, statistical: bool) -> fmt::Result {
    let units = match m.encoding {
        Encoding::Linear => "linear",
        Encoding::Code8 => "8-bit codes",
    };
    let which = if statistical {
        " (depth, normals and colour values without variance)"
    } else {
        ""
    };
    writeln!(
        f,
        "  failing pixels{which}: {} of {} ({}) differ by more than {} ({units})",
        m.failing_pixels,
        m.pixels,
        percent(m.failing_fraction),
        m.pixel_threshold
    )?;
    match &m.worst {
        Some(worst) => writeln!(f, "  worst colour: {worst} (|diff| {:.6})", worst.error())?,
        None => writeln!(f, "  worst colour: none, colour is identical")?,
    }
    for channel in m
        .channels
        .iter()
        .filter(|c| c.failing > 0 && !COLOR_CHANNELS.contains(&c.name))
    {
        if let Some(worst) = &channel.worst {
            writeln!(
                f,
                "  {} fails on {} pixels, worst {worst}",
                channel.name, channel.failing
            )?;
        }
    }
    writeln!(
        f,
        "  colour: MAE {:.6}  RMSE {:.6}  PSNR {}  FLIP {:.5}",
        m.mae,
        m.rmse,
        if m.psnr.is_finite() {
            format!("{:.2} dB", m.psnr)
        } else {
            "inf".to_owned()
        },
        m.flip
    )
}

fn mismatch(expected: &Layout, actual: &Layout) -> String {
    let describe = |l: &Layout| {
        let kind = match l.encoding {
            Encoding::Linear => "EXR",
            Encoding::Code8 => "8-bit",
        };
        format!("{}x{} {kind} with channels {}", l.width, l.height, l.channels.join(" "))
    };
    let mut differences = Vec::new();
    if (expected.width, expected.height) != (actual.width, actual.height) {
        differences.push("size");
    }
    if expected.encoding != actual.encoding {
        differences.push("encoding");
    }
    if expected.channels != actual.channels {
        differences.push("channels");
    }
    if differences.is_empty() {
        differences.push("buffer lengths");
    }
    format!(
        "{} differ: expected {}, actual {}",
        differences.join(" and "),
        describe(expected),
        describe(actual)
    )
}
