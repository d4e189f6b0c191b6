//! How far a student's picture is from a candidate picture, measured fast enough to try dozens
//! of candidates per image: the failing-pixel fraction at the rubric's threshold and the RMSE in
//! 8-bit codes, pixel by pixel, or over blocks for speckled mistakes (acne), whose speckles an
//! independent program draws in other places.

use super::super::diagnosis::Residual;
use crate::rgb_image::RgbImage;

/// Pixel by pixel. Both pictures have the same size (the caller checks).
pub fn residual(expected: &RgbImage, actual: &RgbImage, threshold: f64) -> Residual {
    let (mut failing, mut sum_sq) = (0usize, 0u64);
    for (e, a) in expected.pixels().zip(actual.pixels()) {
        let mut fails = false;
        for (x, y) in e.0.iter().zip(a.0) {
            let d = i32::from(*x) - i32::from(y);
            sum_sq += (d * d) as u64;
            fails |= f64::from(d.abs()) > threshold;
        }
        failing += usize::from(fails);
    }
    let pixels = (expected.width() as usize * expected.height() as usize).max(1);
    Residual {
        failing_fraction: failing as f64 / pixels as f64,
        rmse: (sum_sq as f64 / (3 * pixels) as f64).sqrt(),
    }
}

/// The side of the blocks speckled pictures are compared over: about a hundredth of the
/// picture, at least 4 pixels.
pub fn block_size(picture: &RgbImage) -> u32 {
    (picture.width().min(picture.height()) / 64).max(4)
}

/// Over the means of `block × block` blocks: the speckles' density, not their places.
pub fn block_residual(expected: &RgbImage, actual: &RgbImage, threshold: f64, block: u32) -> Residual {
    let (e, a) = (block_means(expected, block), block_means(actual, block));
    let (mut failing, mut sum_sq) = (0usize, 0.0f64);
    for (x, y) in e.iter().zip(&a) {
        let mut fails = false;
        for c in 0..3 {
            let d = x[c] - y[c];
            sum_sq += d * d;
            fails |= d.abs() > threshold;
        }
        failing += usize::from(fails);
    }
    let blocks = e.len().max(1);
    Residual {
        failing_fraction: failing as f64 / blocks as f64,
        rmse: (sum_sq / (3 * blocks) as f64).sqrt(),
    }
}

fn block_means(picture: &RgbImage, block: u32) -> Vec<[f64; 3]> {
    let (w, h) = picture.dimensions();
    let (bw, bh) = (w.div_ceil(block), h.div_ceil(block));
    let mut sums = vec![([0.0f64; 3], 0u32); (bw * bh) as usize];
    for (x, y, p) in picture.enumerate_pixels() {
        let cell = &mut sums[((y / block) * bw + x / block) as usize];
        for c in 0..3 {
            cell.0[c] += f64::from(p.0[c]);
        }
        cell.1 += 1;
    }
    sums.into_iter()
        .map(|(s, n)| s.map(|v| v / f64::from(n.max(1))))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rgb_image::Rgb;

    #[test]
    fn pixels_and_blocks() {
        let grey = RgbImage::from_pixel(8, 8, Rgb([100; 3]));
        assert_eq!(
            residual(&grey, &grey, 8.0),
            Residual {
                failing_fraction: 0.0,
                rmse: 0.0
            }
        );
        // A checkerboard of ±20 fails every pixel but averages to the grey over blocks.
        let checker = RgbImage::from_fn(8, 8, |x, y| Rgb([if (x + y) % 2 == 0 { 120 } else { 80 }; 3]));
        let r = residual(&grey, &checker, 8.0);
        assert_eq!((r.failing_fraction, r.rmse), (1.0, 20.0));
        assert_eq!(block_residual(&grey, &checker, 8.0, 4).failing_fraction, 0.0);
        let dark = RgbImage::from_pixel(8, 8, Rgb([50; 3]));
        assert_eq!(block_residual(&grey, &dark, 8.0, 4).failing_fraction, 1.0);
    }
}
