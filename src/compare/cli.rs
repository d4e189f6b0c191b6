//! `goldray diff`: the golden comparison from the shell, for any two EXR or PNG files, with
//! idiff's exit codes so that scripts written for OpenImageIO keep working.

use std::io::Write;
use std::path::PathBuf;

use super::comparison::{Comparison, compare};
use super::error::CompareError;
use super::heatmap::diff_heatmap;
use super::image::{Encoding, Image};
use crate::case::Tolerance;
use crate::film::write_png;

/// The exit code for a file that cannot be read or decoded (or a `--diff-image` not written).
pub const UNREADABLE: u8 = 4;

/// The case-file defaults, so that `goldray diff` on two EXRs judges like the golden suite.
pub const EXR_DEFAULTS: Tolerance = Tolerance::DEFAULT;

/// The same limits in 8-bit code values: an off-by-one code (rounding, or an ulp of drift at a
/// quantisation boundary) is within `pixel`; `rmse` is 0.002 × 255 ≈ 0.5 codes, so a uniform
/// one-code shift of the whole picture still fails.
pub const PNG_DEFAULTS: Tolerance = Tolerance {
    pixel: 1.0,
    fail_fraction: 0.001,
    rmse: 0.5,
    max: None,
};

/// `goldray diff`'s command line. A threshold left out takes the default for the files' encoding.
#[derive(Clone, Debug, clap::Args)]
pub struct DiffArgs {
    /// The reference image (e.g. the golden).
    pub expected: PathBuf,
    /// The image under test.
    pub actual: PathBuf,
    /// A pixel fails when any channel differs by more than this (default: 0.01 for EXR, in
    /// linear values; 1 for PNG, in 8-bit codes).
    #[arg(long, value_parser = parse_threshold)]
    pub pixel: Option<f64>,
    /// At most this fraction of the pixels may fail (default 0.001).
    #[arg(long, value_parser = parse_fraction)]
    pub fail_fraction: Option<f64>,
    /// The colour RMSE may be at most this (default: 0.002 for EXR; 0.5 codes for PNG).
    #[arg(long, value_parser = parse_threshold)]
    pub rmse: Option<f64>,
    /// No channel of any pixel may differ by more than this (default: no cap).
    #[arg(long, value_parser = parse_threshold)]
    pub max: Option<f64>,
    /// Write a heatmap of the differences to this PNG.
    #[arg(long, value_name = "OUT.png")]
    pub diff_image: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

impl DiffArgs {
    pub fn tolerance(&self, encoding: Encoding) -> Tolerance {
        let defaults = match encoding {
            Encoding::Linear => EXR_DEFAULTS,
            Encoding::Code8 => PNG_DEFAULTS,
        };
        Tolerance {
            pixel: self.pixel.unwrap_or(defaults.pixel),
            fail_fraction: self.fail_fraction.unwrap_or(defaults.fail_fraction),
            rmse: self.rmse.unwrap_or(defaults.rmse),
            max: self.max.or(defaults.max),
        }
    }
}

/// Runs the comparison, prints the report (text or JSON) on stdout and any error on stderr, and
/// returns the exit code: 0 pass, 1 warn, 2 fail, 3 size or channel mismatch, 4 unreadable file
/// (or an unwritable `--diff-image`).
pub fn run_diff(args: &DiffArgs) -> u8 {
    match diff_files(args) {
        Ok(comparison) => {
            let text = if args.json {
                comparison.to_json() + "\n"
            } else {
                comparison.to_string()
            };
            print_stdout(&text);
            comparison.verdict.exit_code()
        }
        Err(error) => {
            if args.json {
                let report = serde_json::json!({
                    "verdict": "unreadable",
                    "exit_code": UNREADABLE,
                    "error": error.to_string(),
                });
                print_stdout(&format!("{report:#}\n"));
            }
            eprintln!("error: {error}");
            UNREADABLE
        }
    }
}

/// [`run_diff`] without the printing: reads both files, compares them and writes the heatmap
/// when asked (and when the images can be overlaid).
pub fn diff_files(args: &DiffArgs) -> Result<Comparison, CompareError> {
    let expected = Image::read(&args.expected)?;
    let actual = Image::read(&args.actual)?;
    let tolerance = args.tolerance(expected.encoding);
    let mut comparison = compare(&expected, &actual, &tolerance);
    if let Some(path) = &args.diff_image {
        match diff_heatmap(&expected, &actual, tolerance.pixel) {
            Some(heatmap) => {
                write_png(path, &heatmap).map_err(|e| CompareError::WriteDiff {
                    path: path.clone(),
                    source: e,
                })?;
                comparison.diff_image = Some(path.clone());
            }
            None => {
                eprintln!("note: no diff image written: the images cannot be laid over each other")
            }
        }
    }
    Ok(comparison)
}

/// A closed pipe (`goldray diff … | head`) must not turn a verdict into a panic.
fn print_stdout(text: &str) {
    let mut stdout = std::io::stdout().lock();
    let _ = stdout.write_all(text.as_bytes()).and_then(|()| stdout.flush());
}

/// Thresholds: a finite number ≥ 0 (a NaN threshold would pass
/// everything, because every comparison with NaN is false).
fn parse_threshold(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("{text:?} is not a finite number at least 0")),
    }
}

/// `--fail-fraction`: a number in [0, 1].
fn parse_fraction(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if (0.0..=1.0).contains(&v) => Ok(v),
        _ => Err(format!("{text:?} is not a number between 0 and 1")),
    }
}
