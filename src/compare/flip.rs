//! FLIP (Andersson et al. 2020, NVIDIA): a perceptual difference that weighs what a viewer would
//! notice at a normal viewing distance, so a reviewer can tell "numerically off" from "visibly
//! off". It is reported, not judged: the case tolerances stay in linear values.

use image::RgbImage;

/// The mean of FLIP's per-pixel error map, in [0, 1], at FLIP's default viewing setup (0.7 m from
/// a 24-inch 4K monitor). The images must have the same size, which `compare` checks before
/// measuring anything.
pub(super) fn flip_mean(expected: &RgbImage, actual: &RgbImage) -> f64 {
    let (width, height) = expected.dimensions();
    let reference = nv_flip::FlipImageRgb8::with_data(width, height, expected.as_raw());
    let test = nv_flip::FlipImageRgb8::with_data(width, height, actual.as_raw());
    let map = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE).to_vec();
    if map.is_empty() {
        return 0.0;
    }
    map.iter().map(|&v| f64::from(v)).sum::<f64>() / map.len() as f64
}
