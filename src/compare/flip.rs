//! FLIP (Andersson et al. 2020, NVIDIA): a perceptual difference that weighs what a viewer would
//! notice at a normal viewing distance, so a reviewer can tell "numerically off" from "visibly
//! off". It is reported, not judged: the case tolerances stay in linear values.
//!
//! FLIP is local: at the default viewing setup its per-pixel error is zero wherever the two
//! images agree within [`SUPPORT`] pixels, and a pixel's error reads the images at most
//! [`SUPPORT`] pixels further out. So only the regions that differ are measured, each cropped
//! with a margin of twice the support; the sum of their error maps is the whole map's sum,
//! exactly. Most pictures a grader sees are identical to the golden one or differ in a few places,
//! and FLIP over a whole 800×800 picture costs about 0.3 s.

use image::RgbImage;

/// How far (in pixels) a difference spreads into FLIP's error map at
/// `nv_flip::DEFAULT_PIXELS_PER_DEGREE`: the colour filters' radius (the feature filters' is 9).
/// A test checks it against the crate.
const SUPPORT: u32 = 10;
/// Each measured region extends this far past its differences, so that every pixel the
/// differences can reach is measured with all the data its filters read.
const MARGIN: u32 = 2 * SUPPORT + 4;

/// The mean of FLIP's per-pixel error map, in [0, 1], at FLIP's default viewing setup (0.7 m from
/// a 24-inch 4K monitor). The images must have the same size, which `compare` checks before
/// measuring anything.
pub(super) fn flip_mean(expected: &RgbImage, actual: &RgbImage) -> f64 {
    let (width, height) = expected.dimensions();
    let pixels = f64::from(width) * f64::from(height);
    if pixels == 0.0 {
        return 0.0;
    }
    differing_regions(expected, actual)
        .into_iter()
        .map(|region| flip_sum(expected, actual, region))
        .sum::<f64>()
        / pixels
}

/// A rectangle of the picture: columns `x0..x1`, rows `y0..y1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Region {
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
}

/// Bands of rows holding differences, split where two differing rows are more than `2·MARGIN`
/// apart (so that no pixel is in reach of two bands), each cropped to the columns its
/// differences span, all widened by `MARGIN` and clamped to the picture.
fn differing_regions(expected: &RgbImage, actual: &RgbImage) -> Vec<Region> {
    let (width, height) = expected.dimensions();
    let row_bytes = width as usize * 3;
    let columns = |y: u32| -> Option<(u32, u32)> {
        let start = y as usize * row_bytes;
        let a = &expected.as_raw()[start..start + row_bytes];
        let b = &actual.as_raw()[start..start + row_bytes];
        if a == b {
            return None;
        }
        let first = a.chunks_exact(3).zip(b.chunks_exact(3)).position(|(p, q)| p != q)?;
        let last = a.chunks_exact(3).zip(b.chunks_exact(3)).rposition(|(p, q)| p != q)?;
        Some((first as u32, last as u32))
    };
    let mut bands: Vec<(u32, u32, u32, u32)> = Vec::new();
    for y in 0..height {
        let Some((first, last)) = columns(y) else { continue };
        match bands.last_mut() {
            Some(band) if y - band.3 <= 2 * MARGIN => {
                band.0 = band.0.min(first);
                band.2 = band.2.max(last);
                band.3 = y;
            }
            _ => bands.push((first, y, last, y)),
        }
    }
    bands
        .into_iter()
        .map(|(x_first, y_first, x_last, y_last)| Region {
            x0: x_first.saturating_sub(MARGIN),
            y0: y_first.saturating_sub(MARGIN),
            x1: (x_last + MARGIN + 1).min(width),
            y1: (y_last + MARGIN + 1).min(height),
        })
        .collect()
}

/// The sum of FLIP's error map over `region`, measured on the region alone.
fn flip_sum(expected: &RgbImage, actual: &RgbImage, region: Region) -> f64 {
    let crop = |picture: &RgbImage| -> Vec<u8> {
        let row_bytes = picture.width() as usize * 3;
        (region.y0..region.y1)
            .flat_map(|y| {
                let start = y as usize * row_bytes + region.x0 as usize * 3;
                picture.as_raw()[start..start + (region.x1 - region.x0) as usize * 3]
                    .iter()
                    .copied()
            })
            .collect()
    };
    let (width, height) = (region.x1 - region.x0, region.y1 - region.y0);
    let (reference, test) = (crop(expected), crop(actual));
    let map = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(width, height, &reference),
        nv_flip::FlipImageRgb8::with_data(width, height, &test),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    )
    .to_vec();
    map.iter().map(|&v| f64::from(v)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgb;

    fn noise(width: u32, height: u32, seed: u64) -> RgbImage {
        let mut state = seed;
        RgbImage::from_fn(width, height, |_, _| {
            let mut byte = || {
                state = state
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                (state >> 56) as u8
            };
            Rgb([byte(), byte(), byte()])
        })
    }

    /// FLIP over the whole picture, as the crate computes it.
    fn whole(expected: &RgbImage, actual: &RgbImage) -> f64 {
        let (width, height) = expected.dimensions();
        flip_sum(
            expected,
            actual,
            Region {
                x0: 0,
                y0: 0,
                x1: width,
                y1: height,
            },
        ) / f64::from(width * height)
    }

    #[test]
    fn a_difference_reaches_no_further_than_the_support() {
        let expected = noise(120, 100, 1);
        let mut actual = expected.clone();
        actual.get_pixel_mut(60, 50).0[1] ^= 0x40;
        let map = nv_flip::flip(
            nv_flip::FlipImageRgb8::with_data(120, 100, expected.as_raw()),
            nv_flip::FlipImageRgb8::with_data(120, 100, actual.as_raw()),
            nv_flip::DEFAULT_PIXELS_PER_DEGREE,
        )
        .to_vec();
        let reach = (0..100u32)
            .flat_map(|y| (0..120u32).map(move |x| (x, y)))
            .filter(|&(x, y)| map[(y * 120 + x) as usize] != 0.0)
            .map(|(x, y)| x.abs_diff(60).max(y.abs_diff(50)))
            .max()
            .unwrap();
        assert!(reach <= SUPPORT, "FLIP reaches {reach} pixels; SUPPORT is {SUPPORT}");
    }

    #[test]
    fn measuring_the_differing_regions_gives_the_whole_picture_s_mean() {
        let expected = noise(300, 260, 2);
        for changes in [
            vec![(5, 5)],
            vec![(150, 130), (152, 133)],
            vec![(10, 10), (290, 250)],
            vec![(0, 0), (299, 0), (0, 259), (299, 259), (150, 20), (150, 200)],
        ] {
            let mut actual = expected.clone();
            for &(x, y) in &changes {
                actual.get_pixel_mut(x, y).0 = [255, 0, 255];
            }
            let (fast, full) = (flip_mean(&expected, &actual), whole(&expected, &actual));
            assert!(
                (fast - full).abs() <= 1e-9 * full.max(1e-9),
                "{changes:?}: {fast} vs {full}"
            );
            assert!(fast > 0.0);
        }
        assert_eq!(flip_mean(&expected, &expected), 0.0);
    }
}
