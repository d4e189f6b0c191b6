//! A picture of where two images differ, for the person who has to decide whether a failing
//! golden is a bug or an improvement.
//!
//! The expected image shows through as a dim grey backdrop so that errors can be placed in the
//! scene. On top, each pixel's largest channel difference is magnified on a log scale: from a
//! thousandth of the pixel threshold (barely tinted red) up to the threshold itself (bright
//! yellow). A pixel beyond the threshold (or whose depth changed between hit and miss) is solid
//! magenta, and one holding NaN or infinity in only one image is solid cyan: neither colour
//! occurs on the red–yellow scale.

use image::{Rgb, RgbImage};

use super::image::Image;
use super::metrics::{Difference, difference};

pub const FAILING: [u8; 3] = [255, 0, 255];
pub const NON_FINITE: [u8; 3] = [0, 255, 255];

/// Decades below the threshold that still show: 3 makes a 1e-5 error visible at a 0.01 threshold.
const DECADES: f64 = 3.0;
/// How much of the expected image shows through, so the errors stand out against it.
const BACKDROP: f32 = 0.3;

/// `None` when the images cannot be laid over each other (different sizes or channels).
pub fn diff_heatmap(expected: &Image, actual: &Image, pixel_threshold: f64) -> Option<RgbImage> {
    if !super::metrics::same_layout(expected, actual) {
        return None;
    }
    let width = expected.width as usize;
    Some(RgbImage::from_fn(expected.width, expected.height, |x, y| {
        let i = y as usize * width + x as usize;
        let mut largest = 0.0_f64;
        let mut failing = false;
        for (e, a) in expected.channels.iter().zip(&actual.channels) {
            match difference(e.values[i], a.values[i], e.infinity_is_a_value()) {
                Difference::Broken => return Rgb(NON_FINITE),
                diff @ (Difference::Finite(_) | Difference::Coverage) => {
                    failing |= diff.exceeds(pixel_threshold);
                    if let Difference::Finite(d) = diff {
                        largest = largest.max(d);
                    }
                }
            }
        }
        if failing {
            return Rgb(FAILING);
        }
        let [r, g, b] = expected.preview.get_pixel(x, y).0.map(f32::from);
        let grey = (0.2126 * r + 0.7152 * g + 0.0722 * b) * BACKDROP;
        if largest == 0.0 {
            return Rgb([grey as u8; 3]);
        }
        let t = ((largest / pixel_threshold).log10() / DECADES + 1.0).clamp(0.0, 1.0) as f32;
        let hot = [255.0, 40.0 + 215.0 * t, 0.0];
        let weight = 0.4 + 0.6 * t;
        Rgb(hot.map(|h| (grey + (h - grey) * weight).round() as u8))
    }))
}
