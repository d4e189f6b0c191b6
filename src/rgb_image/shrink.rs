//! Shrinking a picture by area averaging, for the thumbnails of a grading report.
//!
//! Each pixel of the result is the mean of the part of the picture it covers, partly covered
//! pixels weighted by how much of them it covers: a box filter, exact in integers. Rows are
//! combined first, at full width, which is one multiply-add over contiguous bytes that the
//! compiler vectorises; only the few rows left are then combined along their length. An 800×800
//! picture shrinks to 300×300 in about a millisecond. (goldray used `fast_image_resize` for
//! this: its SIMD resizer was an eighth of the crate's compiled code, for one filter on one pixel
//! type; see docs/speed.md, "Build time".)

use super::RgbImage;

/// Where one pixel of the result reads: `weights[k]` parts of source pixel `first + k`, the
/// weights summing to the source's length (a source pixel counts `result_len` parts in all).
struct Span {
    first: usize,
    weights: Vec<u32>,
}

/// The spans of a `source_len` axis shrunk to `result_len` pixels. In units where a source pixel
/// is `result_len` long and a result pixel `source_len` long, result pixel `t` covers
/// `[t·source_len, (t + 1)·source_len)` and the overlaps are whole numbers.
fn spans(source_len: u32, result_len: u32) -> Vec<Span> {
    let (source, result) = (u64::from(source_len), u64::from(result_len));
    (0..result)
        .map(|t| {
            let (start, end) = (t * source, (t + 1) * source);
            let first = start / result;
            let last = end.div_ceil(result);
            let weights = (first..last)
                .map(|i| (end.min((i + 1) * result) - start.max(i * result)) as u32)
                .collect();
            Span {
                first: first as usize,
                weights,
            }
        })
        .collect()
}

impl RgbImage {
    /// The picture shrunk to `width × height` by area averaging; a size that is not smaller on
    /// both sides (or is empty) gives the picture unchanged.
    pub fn shrunk(&self, width: u32, height: u32) -> RgbImage {
        if width == 0
            || height == 0
            || width > self.width
            || height > self.height
            || (width, height) == self.dimensions()
        {
            return self.clone();
        }
        let row_len = 3 * self.width as usize;
        let mut combined_row = vec![0u32; row_len];
        let mut bytes = Vec::with_capacity(3 * width as usize * height as usize);
        let columns = spans(self.width, width);
        let area = u64::from(self.width) * u64::from(self.height);
        for row_span in spans(self.height, height) {
            combined_row.fill(0);
            for (k, &weight) in row_span.weights.iter().enumerate() {
                let start = (row_span.first + k) * row_len;
                for (sum, &value) in combined_row.iter_mut().zip(&self.bytes[start..start + row_len]) {
                    *sum += weight * u32::from(value);
                }
            }
            // Each sum (rounding included) is under 256 × the source's area: 32 bits hold it up to
            // 16 million pixels, more than any picture a student hands in; 64 bits beyond.
            if area <= u64::from(u32::MAX / 256) {
                let area = area as u32;
                for column in &columns {
                    let sums = column_sums::<u32>(&combined_row, column, u32::from);
                    bytes.extend(sums.map(|sum| ((sum + area / 2) / area) as u8));
                }
            } else {
                for column in &columns {
                    let sums = column_sums::<u64>(&combined_row, column, u64::from);
                    bytes.extend(sums.map(|sum| ((sum + area / 2) / area) as u8));
                }
            }
        }
        RgbImage { width, height, bytes }
    }
}

/// The weighted sums of `column`'s pixels in a row of combined values.
fn column_sums<T>(row: &[u32], column: &Span, widen: impl Fn(u32) -> T) -> [T; 3]
where
    T: Copy + Default + std::ops::Add<Output = T> + std::ops::Mul<Output = T>,
{
    let mut sums = [T::default(); 3];
    let pixels = row[3 * column.first..].chunks_exact(3);
    for (pixel, &weight) in pixels.zip(&column.weights) {
        for (sum, &value) in sums.iter_mut().zip(pixel) {
            *sum = *sum + widen(weight) * widen(value);
        }
    }
    sums
}

#[cfg(test)]
mod tests {
    use super::super::Rgb;
    use super::*;

    #[test]
    fn each_span_covers_its_share_of_the_source() {
        for (source, result) in [(800, 300), (7, 3), (5, 5), (1000, 1)] {
            let spans = spans(source, result);
            assert_eq!(spans.len(), result as usize);
            for span in &spans {
                assert_eq!(span.weights.iter().sum::<u32>(), source);
                assert!(span.weights.iter().all(|&w| w > 0 && w <= result));
            }
            let covered: u64 = spans.iter().flat_map(|s| s.weights.iter()).map(|&w| u64::from(w)).sum();
            assert_eq!(covered, u64::from(source) * u64::from(result));
        }
    }

    #[test]
    fn a_flat_picture_stays_flat_and_halving_averages_pairs() {
        let flat = RgbImage::from_pixel(800, 600, Rgb([10, 200, 255]));
        let small = flat.shrunk(300, 225);
        assert_eq!(small.dimensions(), (300, 225));
        assert!(small.pixels().all(|p| p.0 == [10, 200, 255]));
        let stripes = RgbImage::from_fn(4, 2, |x, _| Rgb([if x % 2 == 0 { 0 } else { 100 }, 7, 8]));
        assert!(stripes.shrunk(2, 1).pixels().all(|p| p.0 == [50, 7, 8]));
    }

    #[test]
    fn a_partly_covered_pixel_counts_by_its_share() {
        // Three pixels into two: the middle one is half in each.
        let picture = RgbImage::from_fn(3, 1, |x, _| Rgb([[0, 90, 180][x as usize]; 3]));
        let small = picture.shrunk(2, 1);
        assert_eq!(small.get_pixel(0, 0).0[0], 30); // (0·2 + 90·1) / 3
        assert_eq!(small.get_pixel(1, 0).0[0], 150); // (90·1 + 180·2) / 3
    }

    #[test]
    fn sizes_that_do_not_shrink_give_the_picture_back() {
        let picture = RgbImage::from_pixel(4, 3, Rgb([1, 2, 3]));
        for (w, h) in [(4, 3), (5, 2), (0, 1), (2, 4)] {
            assert_eq!(picture.shrunk(w, h), picture);
        }
    }
}
