//! Comparing two image files, as `goldray diff` does: each limit the user leaves out takes the
//! default for the files' encoding, so that a diff of two EXRs judges like the golden suite.

use std::path::Path;

use super::comparison::{Comparison, compare};
use super::error::CompareError;
use super::heatmap::comparison_heatmap;
use super::image::{Encoding, Image};
use super::tolerance::{EXR_DEFAULTS, PNG_DEFAULTS, Tolerance};
use crate::film::write_png;

/// Limits given by the user; each one left out takes the default for the files' encoding.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ToleranceOverrides {
    pub pixel: Option<f64>,
    pub fail_fraction: Option<f64>,
    pub rmse: Option<f64>,
    pub max: Option<f64>,
}

impl ToleranceOverrides {
    /// The tolerance for images of `encoding`: [`EXR_DEFAULTS`] or [`PNG_DEFAULTS`] with these
    /// overrides.
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

/// Two files compared: `goldray diff` without the printing. Both images are kept so that a
/// heatmap can be drawn afterwards.
#[derive(Debug)]
pub struct FileComparison {
    pub expected: Image,
    pub actual: Image,
    pub tolerance: Tolerance,
    pub comparison: Comparison,
}

/// Reads both files, side by side, and compares them under `overrides` (defaults by the
/// expected file's encoding). When both are unreadable, the expected file's error is reported.
pub fn compare_files(
    expected: &Path,
    actual: &Path,
    overrides: &ToleranceOverrides,
) -> Result<FileComparison, CompareError> {
    // Side by side: a PNG is decoded on one thread, and an EXR's reading is not all parallel
    // (`goldray diff` of two 800×800 PNGs 9.8-15.9 -> 7.4-8.9 ms, of an 800×800 EXR with
    // itself 115-130 -> 103-119 ms).
    let (expected, actual) = rayon::join(|| Image::read(expected), || Image::read(actual));
    let (expected, actual) = (expected?, actual?);
    let tolerance = overrides.tolerance(expected.encoding);
    let comparison = compare(&expected, &actual, &tolerance);
    Ok(FileComparison {
        expected,
        actual,
        tolerance,
        comparison,
    })
}

impl FileComparison {
    /// Writes the heatmap of the differences (of the evidence, for a statistical comparison) to
    /// `path` and records it in the comparison.
    /// Returns `Ok(false)`, writing nothing, when the images cannot be laid over each other
    /// (different sizes or channels).
    pub fn write_heatmap(&mut self, path: &Path) -> Result<bool, CompareError> {
        let Some(heatmap) = comparison_heatmap(&self.expected, &self.actual, &self.comparison) else {
            return Ok(false);
        };
        write_png(path, &heatmap).map_err(|source| CompareError::WriteDiff {
            path: path.to_path_buf(),
            source,
        })?;
        self.comparison.diff_image = Some(path.to_path_buf());
        Ok(true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unreadable_file_is_named_the_expected_first_when_both_are() {
        let dir = tempfile::tempdir().unwrap();
        let [missing_expected, missing_actual] = ["golden.exr", "student.png"].map(|name| dir.path().join(name));
        let overrides = ToleranceOverrides::default();
        let both = compare_files(&missing_expected, &missing_actual, &overrides)
            .unwrap_err()
            .to_string();
        assert!(both.contains("golden.exr") && !both.contains("student.png"), "{both}");

        let readable = dir.path().join("golden.png");
        write_png(&readable, &crate::rgb_image::RgbImage::new(4, 3)).unwrap();
        let one = compare_files(&readable, &missing_actual, &overrides)
            .unwrap_err()
            .to_string();
        assert!(one.contains("student.png"), "{one}");
        let same = compare_files(&readable, &readable, &overrides).unwrap();
        assert_eq!((same.expected.width, same.actual.height), (4, 3));
    }
}
