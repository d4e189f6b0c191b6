//! Sets of pixels as bits: where two pictures differ by more than a threshold. The beam search
//! ([`super::grow`]) asks, for every set it grows and every fault it might add, how many pixels
//! the fault changes where the student's image still fails; as bits that is a few thousand
//! words ANDed and counted, where masks of one byte a pixel cost a fresh 640 KB allocation (and
//! its page faults) for every question at 800×800.

use super::residual::code_limit;
use crate::rgb_image::RgbImage;

/// A set of pixels of one picture size, one bit each in row-major order.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Mask {
    words: Vec<u64>,
}

impl Mask {
    /// The pixels where `a` and `b` differ by more than `threshold` codes in some channel (the
    /// pictures have the same size), by the residual's rule ([`code_limit`]).
    pub fn differing(a: &RgbImage, b: &RgbImage, threshold: f64) -> Mask {
        let limit = code_limit(threshold);
        let words = a
            .as_raw()
            .chunks(64 * 3)
            .zip(b.as_raw().chunks(64 * 3))
            .map(|(x, y)| {
                x.chunks_exact(3)
                    .zip(y.chunks_exact(3))
                    .enumerate()
                    .fold(0u64, |word, (bit, (p, q))| {
                        let over = (0..3).any(|c| i32::from(p[c].abs_diff(q[c])) > limit);
                        word | (u64::from(over) << bit)
                    })
            })
            .collect();
        Mask { words }
    }

    /// How many pixels are in the set.
    pub fn count(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// How many pixels are in both sets.
    pub fn count_both(&self, other: &Mask) -> usize {
        self.words
            .iter()
            .zip(&other.words)
            .map(|(a, b)| (a & b).count_ones() as usize)
            .sum()
    }

    /// How many pixels are in this set and in neither of the others.
    pub fn count_outside(&self, first: &Mask, second: &Mask) -> usize {
        self.words
            .iter()
            .zip(&first.words)
            .zip(&second.words)
            .map(|((a, b), c)| (a & !b & !c).count_ones() as usize)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rgb_image::Rgb;

    #[test]
    fn counts_follow_the_pixels() {
        // 131 pixels: two full words and a partial one.
        let grey = RgbImage::from_pixel(131, 1, Rgb([100; 3]));
        let some = RgbImage::from_fn(131, 1, |x, _| Rgb([100, if x % 3 == 0 { 120 } else { 100 }, 100]));
        let others = RgbImage::from_fn(131, 1, |x, _| Rgb([if x % 2 == 0 { 91 } else { 100 }, 100, 100]));
        let every_third = Mask::differing(&grey, &some, 8.0);
        let even = Mask::differing(&grey, &others, 8.0);
        assert_eq!(every_third.count(), 44);
        assert_eq!(even.count(), 66);
        assert_eq!(
            Mask::differing(&grey, &others, 9.0).count(),
            0,
            "9 codes are not over 9"
        );
        assert_eq!(Mask::differing(&grey, &others, 8.5).count(), 66);
        assert_eq!(every_third.count_both(&even), 22, "multiples of 6");
        let none = Mask::differing(&grey, &grey, 8.0);
        assert_eq!(every_third.count_outside(&even, &none), 22, "odd multiples of 3");
        assert_eq!(Mask::differing(&grey, &grey, -1.0).count(), 131);
    }
}
