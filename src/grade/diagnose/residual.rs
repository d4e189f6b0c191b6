//! How far a student's picture is from a candidate picture, measured fast enough to try dozens
//! of candidates per image: the failing-pixel fraction at the rubric's threshold and the RMSE in
//! 8-bit codes, pixel by pixel, or over blocks for speckled mistakes (acne), whose speckles an
//! independent program draws in other places.

use super::super::diagnosis::Residual;
use crate::rgb_image::RgbImage;

/// Pixel by pixel. Both pictures have the same size (the caller checks). Diagnosis measures
/// every candidate against every image that lost points (tens of 800×800 pictures an image), so
/// this works on the raw bytes in runs of [`RUN`] pixels that the compiler vectorises, with the
/// machine's widest vectors ([`crate::simd::dispatch`]; the sums are integers, the same on every
/// path): the squared differences summed in integers and each byte's verdict kept, then the
/// verdicts of a pixel's three channels joined ([`code_limit`]).
pub fn residual(expected: &RgbImage, actual: &RgbImage, threshold: f64) -> Residual {
    let (failing, sum_sq) = crate::simd::dispatch(Runs {
        expected: expected.as_raw(),
        actual: actual.as_raw(),
        limit: code_limit(threshold),
    });
    let pixels = (expected.width() as usize * expected.height() as usize).max(1);
    Residual {
        failing_fraction: failing as f64 / pixels as f64,
        rmse: (sum_sq as f64 / (3 * pixels) as f64).sqrt(),
    }
}

/// The largest difference in codes that is not over `threshold`: a difference in codes is an
/// integer, so it exceeds the threshold exactly when it exceeds the threshold's integer part
/// (every difference exceeds a negative threshold).
pub fn code_limit(threshold: f64) -> i32 {
    if threshold < 0.0 {
        -1
    } else {
        threshold.min(255.0) as i32
    }
}

/// [`residual`]'s loop over two pictures' bytes: the failing pixels and the sum of squares.
struct Runs<'a> {
    expected: &'a [u8],
    actual: &'a [u8],
    limit: i32,
}

impl crate::simd::Kernel for Runs<'_> {
    type Output = (usize, u64);

    #[inline(always)]
    fn run<I: crate::simd::Isa>(self) -> (usize, u64) {
        let (mut failing, mut sum_sq) = (0usize, 0u64);
        let mut over = [false; 3 * RUN];
        for (e, a) in self.expected.chunks(3 * RUN).zip(self.actual.chunks(3 * RUN)) {
            let mut run_sq = 0u32;
            for ((x, y), over) in e.iter().zip(a).zip(over.iter_mut()) {
                let d = u32::from(x.abs_diff(*y));
                run_sq += d * d;
                *over = d as i32 > self.limit;
            }
            sum_sq += u64::from(run_sq);
            failing += over[..e.len()]
                .chunks_exact(3)
                .filter(|channels| channels[0] | channels[1] | channels[2])
                .count();
        }
        (failing, sum_sq)
    }
}

/// Pixels a run of [`residual`] holds: its squared differences (at most 3 × 255² a pixel) stay
/// within a `u32`.
const RUN: usize = 64;

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

/// Each block's mean per channel. Sums are kept in integers row by row (exact, as the f64 sums
/// of the codes were: far below 2⁵³), so the means are the same to the bit.
fn block_means(picture: &RgbImage, block: u32) -> Vec<[f64; 3]> {
    let (w, h) = picture.dimensions();
    let (bw, bh) = (w.div_ceil(block) as usize, h.div_ceil(block) as usize);
    let mut sums = vec![[0u64; 3]; bw * bh];
    let row_bytes = 3 * w as usize;
    for (y, row) in picture.as_raw().chunks_exact(row_bytes.max(1)).enumerate() {
        let cells = &mut sums[(y / block as usize) * bw..][..bw];
        for (cell, pixels) in cells.iter_mut().zip(row.chunks(3 * block as usize)) {
            let mut run = [0u32; 3];
            for pixel in pixels.chunks_exact(3) {
                for c in 0..3 {
                    run[c] += u32::from(pixel[c]);
                }
            }
            for c in 0..3 {
                cell[c] += u64::from(run[c]);
            }
        }
    }
    let counts = |i: usize| {
        let (bx, by) = ((i % bw) as u32, (i / bw) as u32);
        let across = block.min(w - bx * block);
        let down = block.min(h - by * block);
        f64::from(across * down)
    };
    sums.into_iter()
        .enumerate()
        .map(|(i, s)| s.map(|v| v as f64 / counts(i).max(1.0)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rgb_image::Rgb;

    /// What [`residual`] computes, written plainly.
    fn plain(expected: &RgbImage, actual: &RgbImage, threshold: f64) -> Residual {
        let (mut failing, mut sum_sq) = (0usize, 0u64);
        for (e, a) in expected.pixels().zip(actual.pixels()) {
            let mut fails = false;
            for (x, y) in e.0.iter().zip(a.0) {
                let d = i64::from(*x) - i64::from(y);
                sum_sq += (d * d) as u64;
                fails |= d.abs() as f64 > threshold;
            }
            failing += usize::from(fails);
        }
        let pixels = expected.width() as usize * expected.height() as usize;
        Residual {
            failing_fraction: failing as f64 / pixels as f64,
            rmse: (sum_sq as f64 / (3 * pixels) as f64).sqrt(),
        }
    }

    #[test]
    fn block_means_are_the_plain_means() {
        let picture = RgbImage::from_fn(37, 11, |x, y| Rgb([(x * 7 + y) as u8, (x * y) as u8, 255 - x as u8]));
        for block in [4, 5, 16, 64] {
            let (bw, bh) = (37u32.div_ceil(block), 11u32.div_ceil(block));
            let mut plain = vec![([0.0f64; 3], 0u32); (bw * bh) as usize];
            for (x, y, p) in picture.enumerate_pixels() {
                let cell = &mut plain[((y / block) * bw + x / block) as usize];
                for c in 0..3 {
                    cell.0[c] += f64::from(p.0[c]);
                }
                cell.1 += 1;
            }
            let plain: Vec<[f64; 3]> = plain.into_iter().map(|(s, n)| s.map(|v| v / f64::from(n))).collect();
            assert_eq!(block_means(&picture, block), plain, "{block}");
        }
    }

    #[test]
    fn the_vectorised_residual_is_the_plain_one() {
        // A stateless hash for the pictures' codes.
        let code =
            |x: u32, y: u32, salt: u32| (x.wrapping_mul(2654435761) ^ y.wrapping_mul(40503) ^ salt).to_le_bytes();
        let expected = RgbImage::from_fn(131, 7, |x, y| {
            let b = code(x, y, 1);
            Rgb([b[0], b[1], b[2]])
        });
        let actual = RgbImage::from_fn(131, 7, |x, y| {
            let (e, b) = (expected.get_pixel(x, y).0, code(x, y, 7));
            Rgb([0, 1, 2].map(|c| e[c].saturating_add(b[c] % 24).saturating_sub(b[3] % 24)))
        });
        for threshold in [0.0, 0.5, 3.0, 8.0, 8.99, 12.0, 300.0] {
            assert_eq!(
                residual(&expected, &actual, threshold),
                plain(&expected, &actual, threshold),
                "{threshold}"
            );
        }
    }

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
        // A run's worst case (every byte 255 apart) and a picture that ends mid-run.
        let black = RgbImage::from_pixel(RUN as u32 + 5, 3, Rgb([0; 3]));
        let white = RgbImage::from_pixel(RUN as u32 + 5, 3, Rgb([255; 3]));
        assert_eq!(
            residual(&black, &white, 254.5),
            Residual {
                failing_fraction: 1.0,
                rmse: 255.0
            }
        );
        assert_eq!(residual(&black, &white, 255.0).failing_fraction, 0.0);
        assert_eq!(residual(&black, &black, -1.0).failing_fraction, 1.0);
        let dark = RgbImage::from_pixel(8, 8, Rgb([50; 3]));
        assert_eq!(block_residual(&grey, &dark, 8.0, 4).failing_fraction, 1.0);
    }
}
