//! A picture of where two images differ, for the person who has to decide whether a failing
//! golden is a bug or an improvement.
//!
//! The expected image shows through as a dim grey backdrop so that errors can be placed in the
//! scene. On top, each pixel's largest channel difference is magnified on a log scale: from a
//! thousandth of the pixel threshold (barely tinted red) up to the threshold itself (bright
//! yellow). A pixel beyond the threshold (or whose depth changed between hit and miss) is solid
//! magenta, and one holding NaN or infinity in only one image is solid cyan: neither colour
//! occurs on the red–yellow scale.
//!
//! A statistical comparison (both images carry variance) draws the evidence instead
//! ([`evidence_heatmap`]): each pixel's largest |z| on the same red–yellow scale, linear from
//! |z| = 1 (what noise gives most of the time) to the Šidák threshold, magenta beyond it.

use crate::rgb_image::{Rgb, RgbImage};

use super::comparison::Comparison;
use super::image::{COLOR_CHANNELS, Encoding, Image};
use super::metrics::{ColourRule, Difference, difference};
use super::noise::{self, Noise};

pub const FAILING: [u8; 3] = [255, 0, 255];
pub const NON_FINITE: [u8; 3] = [0, 255, 255];

/// Decades below the threshold that still show: 3 makes a 1e-5 error visible at a 0.01 threshold.
const DECADES: f64 = 3.0;
/// How much of the expected image shows through, so the errors stand out against it.
const BACKDROP: f32 = 0.3;

/// `None` when the images cannot be laid over each other (different sizes or channels).
pub fn diff_heatmap(expected: &Image, actual: &Image, pixel_threshold: f64) -> Option<RgbImage> {
    heatmap_with(expected, actual, pixel_threshold, ColourRule::Threshold)
}

/// [`diff_heatmap`] of a [`super::compare_widened`] comparison: a colour value is magenta when it
/// differs by more than the threshold plus its allowance.
pub fn diff_heatmap_widened(
    expected: &Image,
    actual: &Image,
    pixel_threshold: f64,
    allowance: &[[f32; 3]],
) -> Option<RgbImage> {
    if allowance.len() != expected.pixels() {
        return None;
    }
    heatmap_with(expected, actual, pixel_threshold, ColourRule::Widened(allowance))
}

fn heatmap_with(expected: &Image, actual: &Image, pixel_threshold: f64, colour: ColourRule) -> Option<RgbImage> {
    if !super::metrics::same_layout(expected, actual) {
        return None;
    }
    let width = expected.width as usize;
    let colour_indices: Vec<Option<usize>> = expected
        .channels
        .iter()
        .map(|e| COLOR_CHANNELS.iter().position(|&c| c == e.name))
        .collect();
    let mut heatmap = RgbImage::from_fn(expected.width, expected.height, |x, y| backdrop(expected, x, y));
    let equal_rows = super::metrics::equal_rows(expected, actual);
    // A pixel equal in every channel is backdrop (a zero difference fails no threshold that is
    // not negative): whole rows of it are most rows of a graded picture, and most pixels of the
    // others. 8-bit pictures hold their values as the preview's bytes.
    let skip_equal = pixel_threshold >= 0.0;
    let bytes = (expected.encoding == Encoding::Code8 && actual.encoding == Encoding::Code8)
        .then(|| (expected.preview.as_raw(), actual.preview.as_raw()));
    let equal_pixel = |i: usize| match bytes {
        Some((e, a)) => e[3 * i..3 * i + 3] == a[3 * i..3 * i + 3],
        None => expected
            .channels
            .iter()
            .zip(&actual.channels)
            .all(|(e, a)| e.values[i] == a.values[i]),
    };
    for y in 0..expected.height {
        if skip_equal && equal_rows[y as usize] {
            continue;
        }
        for x in 0..expected.width {
            let i = y as usize * width + x as usize;
            if skip_equal && equal_pixel(i) {
                continue;
            }
            let mut largest = 0.0_f64;
            let mut failing = false;
            let mut broken = false;
            for ((e, a), colour_index) in expected.channels.iter().zip(&actual.channels).zip(&colour_indices) {
                match difference(e.values[i], a.values[i], e.infinity_is_a_value()) {
                    Difference::Broken => broken = true,
                    diff @ (Difference::Finite(_) | Difference::Coverage) => {
                        failing |= match colour_index {
                            Some(c) => colour.fails(diff, pixel_threshold, i, *c),
                            None => diff.exceeds(pixel_threshold),
                        };
                        if let Difference::Finite(d) = diff {
                            largest = largest.max(d);
                        }
                    }
                }
            }
            let pixel = if broken {
                Rgb(NON_FINITE)
            } else if failing {
                Rgb(FAILING)
            } else if largest == 0.0 {
                continue;
            } else {
                let t = ((largest / pixel_threshold).log10() / DECADES + 1.0).clamp(0.0, 1.0) as f32;
                hot(expected, x, y, t)
            };
            heatmap.put_pixel(x, y, pixel);
        }
    }
    Some(heatmap)
}

/// The heatmap that fits `comparison`: the evidence of a statistical one, the differences of any
/// other. `None` when the images cannot be laid over each other.
pub fn comparison_heatmap(expected: &Image, actual: &Image, comparison: &Comparison) -> Option<RgbImage> {
    match &comparison.noise {
        Some(noise) => evidence_heatmap(expected, actual, noise, comparison.tolerance.pixel),
        None => diff_heatmap(expected, actual, comparison.tolerance.pixel),
    }
}

/// Where a statistical comparison's evidence lies: each pixel's largest |z| over its tested colour
/// values, from 1 (dark red) to `noise.z_critical` (yellow); magenta for a pixel over the
/// threshold or failing the `pixel` rule in a channel judged by it (depth, normals, colour
/// without variance); cyan for NaN/infinity in one image only. Pixels at |z| ≤ 1 show the
/// backdrop. `None` when the images cannot be laid over each other or carry no variance.
pub fn evidence_heatmap(expected: &Image, actual: &Image, noise: &Noise, pixel_threshold: f64) -> Option<RgbImage> {
    if !super::metrics::same_layout(expected, actual) {
        return None;
    }
    let sigmas = noise::sigmas(expected, actual)?;
    let z = noise::z_scores(expected, actual, &sigmas);
    let width = expected.width as usize;
    Some(RgbImage::from_fn(expected.width, expected.height, |x, y| {
        let i = y as usize * width + x as usize;
        let mut failing = false;
        for (e, a) in expected.channels.iter().zip(&actual.channels) {
            let colour = ["R", "G", "B"].iter().position(|&c| c == e.name);
            match difference(e.values[i], a.values[i], e.infinity_is_a_value()) {
                Difference::Broken => return Rgb(NON_FINITE),
                diff => failing |= diff.exceeds(pixel_threshold) && colour.is_none_or(|c| sigmas[i][c].is_none()),
            }
        }
        let largest = z[i].iter().flatten().fold(0.0_f64, |m, z| m.max(z.abs()));
        if failing || largest > noise.z_critical {
            return Rgb(FAILING);
        }
        if largest <= 1.0 {
            return backdrop(expected, x, y);
        }
        let t = ((largest - 1.0) / (noise.z_critical - 1.0)).clamp(0.0, 1.0) as f32;
        hot(expected, x, y, t)
    }))
}

/// The expected image as dim grey.
fn backdrop(expected: &Image, x: u32, y: u32) -> Rgb {
    Rgb([grey(expected, x, y) as u8; 3])
}

fn grey(expected: &Image, x: u32, y: u32) -> f32 {
    let [r, g, b] = expected.preview.get_pixel(x, y).0.map(f32::from);
    (0.2126 * r + 0.7152 * g + 0.0722 * b) * BACKDROP
}

/// The red–yellow scale at `t` in [0, 1], over the backdrop.
fn hot(expected: &Image, x: u32, y: u32, t: f32) -> Rgb {
    let grey = grey(expected, x, y);
    let hot = [255.0, 40.0 + 215.0 * t, 0.0];
    let weight = 0.4 + 0.6 * t;
    Rgb(hot.map(|h| (grey + (h - grey) * weight).round() as u8))
}
