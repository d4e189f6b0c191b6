//! FLIP (Andersson et al. 2020, NVIDIA): a perceptual difference that weighs what a viewer would
//! notice at a normal viewing distance, so a reviewer can tell "numerically off" from "visibly
//! off". It is reported, not judged: the case tolerances stay in linear values.
//!
//! This is NVIDIA's reference algorithm for 8-bit pictures at its default viewing setup, written
//! again for how goldray compares: many pictures against one reference (a class's submissions
//! against one golden image), most of them identical to it or different in a few places. The
//! `nv-flip` crate computes the whole error map of both pictures every time (about 0.3 s at
//! 800×800); here the reference's filtered maps are made once per reference picture and kept
//! (`Image` holds them), identical pictures cost a byte comparison, and a picture that differs
//! in a few pixels costs in proportion to those pixels (`sparse`). Filtering and the per-pixel
//! formulas follow the reference implementation operation by operation in single precision,
//! eight pixels at a time in SIMD lanes, with correctly rounded powers where it calls `powf`;
//! tests compare the means with the crate's.

mod color;
mod filter;
mod kernels;
mod maps;
mod reference;
mod sparse;

use std::sync::OnceLock;

use crate::rgb_image::RgbImage;

use maps::Maps;
pub(super) use reference::Reference;
use reference::TestPixels;

/// Below this fraction of differing pixels (1 in `SPARSE_BELOW`) of the rows that differ,
/// spreading each difference through the kernels costs less than filtering those rows of the
/// test picture: a differing pixel costs about 3,200 multiply-adds there, a pixel about 300 here.
const SPARSE_BELOW: usize = 12;

/// The mean of FLIP's per-pixel error map, in [0, 1], at FLIP's default viewing setup (0.7 m from
/// a 24-inch 4K monitor). `reference` holds what FLIP keeps of the expected picture once made;
/// it is made only when the pictures differ. The pictures must have the same size, which
/// `compare` checks before measuring anything.
pub(super) fn flip_mean(expected: &RgbImage, reference: &OnceLock<Reference>, actual: &RgbImage) -> f64 {
    let (width, height) = (expected.width() as usize, expected.height() as usize);
    if width * height == 0 {
        return 0.0;
    }
    let row_bytes = width * 3;
    let differing: Vec<usize> = expected
        .as_raw()
        .chunks_exact(row_bytes)
        .zip(actual.as_raw().chunks_exact(row_bytes))
        .enumerate()
        .filter(|(_, (e, a))| e != a)
        .flat_map(|(y, (e, a))| {
            e.chunks_exact(3)
                .zip(a.chunks_exact(3))
                .enumerate()
                .filter(|(_, (p, q))| p != q)
                .map(move |(x, _)| y * width + x)
        })
        .collect();
    let (Some(&first), Some(&last)) = (differing.first(), differing.last()) else {
        return 0.0;
    };
    let reference = reference.get_or_init(|| Reference::of(expected));
    // The rows whose maps a difference can reach.
    let reach = kernels::KERNELS.spatial_radius().max(kernels::KERNELS.feature_radius());
    let rows = (first / width).saturating_sub(reach)..(last / width + reach + 1).min(height);
    let sum = if differing.len() * SPARSE_BELOW < rows.len() * width {
        sparse::error_sum(expected, reference, actual, &differing)
    } else {
        dense_error_sum(reference, &Maps::of(actual, rows))
    };
    sum / (width * height) as f64
}

/// The sum of FLIP's error map of a test picture whose maps are `test` (over the rows where it
/// differs) against `reference`. Pixels whose maps agree exactly have no error.
fn dense_error_sum(reference: &Reference, test: &Maps) -> f64 {
    let mut differing = TestPixels::with_capacity(test.pixels().len());
    for p in test.pixels() {
        let (color, features) = (test.color(p), test.features(p));
        if color != reference.maps.color(p) || features != reference.maps.features(p) {
            differing.push(p, color, features);
        }
    }
    reference.error_sum(&differing)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rgb_image::Rgb;

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

    /// A smooth picture with an edge, like a render: gradients, a bright disc, a dark floor.
    fn scene(width: u32, height: u32) -> RgbImage {
        RgbImage::from_fn(width, height, |x, y| {
            let (u, v) = (x as f32 / width as f32, y as f32 / height as f32);
            let disc = (u - 0.5).powi(2) + (v - 0.4).powi(2) < 0.06;
            if disc {
                Rgb([230, (120.0 + 100.0 * u) as u8, 40])
            } else if v > 0.7 {
                Rgb([30, 30, (60.0 * v) as u8])
            } else {
                Rgb([(200.0 * v) as u8, (180.0 * u) as u8, 220])
            }
        })
    }

    /// FLIP's mean over the whole picture as the `nv-flip` crate computes it.
    fn crate_mean(expected: &RgbImage, actual: &RgbImage) -> f64 {
        let (width, height) = expected.dimensions();
        let map = nv_flip::flip(
            nv_flip::FlipImageRgb8::with_data(width, height, expected.as_raw()),
            nv_flip::FlipImageRgb8::with_data(width, height, actual.as_raw()),
            nv_flip::DEFAULT_PIXELS_PER_DEGREE,
        )
        .to_vec();
        map.iter().map(|&v| f64::from(v)).sum::<f64>() / f64::from(width * height)
    }

    fn ours(expected: &RgbImage, actual: &RgbImage) -> f64 {
        flip_mean(expected, &OnceLock::new(), actual)
    }

    fn assert_close(what: &str, ours: f64, theirs: f64) {
        assert!(
            (ours - theirs).abs() <= 1e-10 + 1e-5 * theirs,
            "{what}: ours {ours}, nv-flip {theirs}"
        );
    }

    #[test]
    fn the_viewing_setup_is_the_crate_s_default() {
        assert_eq!(kernels::PIXELS_PER_DEGREE, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
        assert_eq!(kernels::KERNELS.spatial_radius(), 10);
        assert_eq!(kernels::KERNELS.feature_radius(), 9);
    }

    #[test]
    fn pictures_that_differ_everywhere_measure_as_the_crate_measures_them() {
        let expected = noise(120, 100, 1);
        assert_close(
            "noise",
            ours(&expected, &noise(120, 100, 2)),
            crate_mean(&expected, &noise(120, 100, 2)),
        );
        let render = scene(160, 120);
        let gamma = RgbImage::from_fn(160, 120, |x, y| {
            Rgb(render
                .get_pixel(x, y)
                .0
                .map(|c| (255.0 * (f32::from(c) / 255.0).powf(1.0 / 2.2)) as u8))
        });
        assert_close("gamma", ours(&render, &gamma), crate_mean(&render, &gamma));
    }

    #[test]
    fn pictures_that_differ_in_a_few_pixels_measure_as_the_crate_measures_them() {
        for expected in [noise(300, 260, 2), scene(300, 260)] {
            for changes in [
                vec![(5, 5)],
                vec![(150, 130), (152, 133)],
                vec![(10, 10), (290, 250)],
                vec![
                    (0, 0),
                    (299, 0),
                    (0, 259),
                    (299, 259),
                    (150, 20),
                    (150, 200),
                    (1, 130),
                    (298, 7),
                ],
            ] {
                let mut actual = expected.clone();
                for &(x, y) in &changes {
                    actual.get_pixel_mut(x, y).0 = [255, 0, 255];
                }
                let mean = ours(&expected, &actual);
                assert!(mean > 0.0);
                assert_close(&format!("{changes:?}"), mean, crate_mean(&expected, &actual));
            }
        }
    }

    #[test]
    fn spreading_the_differences_agrees_with_filtering_the_whole_picture() {
        let expected = scene(200, 150);
        let mut actual = expected.clone();
        // Every 7th pixel of a band darkened by a few codes: neither path is the obvious one.
        for i in (0..200 * 40).step_by(7) {
            let pixel = actual.get_pixel_mut(i % 200, 60 + i / 200);
            pixel.0 = pixel.0.map(|c| c.saturating_sub(6));
        }
        let reference = Reference::of(&expected);
        let differing: Vec<usize> = (0..200 * 150)
            .filter(|&i| expected.as_raw()[3 * i..3 * i + 3] != actual.as_raw()[3 * i..3 * i + 3])
            .collect();
        let sparse = sparse::error_sum(&expected, &reference, &actual, &differing);
        let dense = dense_error_sum(&reference, &Maps::of(&actual, 0..150));
        // Only the rows a difference reaches are filtered, with the same result.
        let band = dense_error_sum(&reference, &Maps::of(&actual, 50..111));
        assert_eq!(band, dense);
        assert!(dense > 0.0);
        assert!((sparse - dense).abs() <= 1e-5 * dense, "sparse {sparse}, dense {dense}");
    }

    #[test]
    fn identical_pictures_have_no_error_and_make_no_maps() {
        let picture = scene(64, 48);
        let reference = OnceLock::new();
        assert_eq!(flip_mean(&picture, &reference, &picture.clone()), 0.0);
        assert!(reference.get().is_none());
        let mut changed = picture.clone();
        changed.get_pixel_mut(3, 3).0[0] ^= 1;
        assert!(flip_mean(&picture, &reference, &changed) > 0.0);
        assert!(reference.get().is_some(), "the maps are kept for the next comparison");
    }
}
