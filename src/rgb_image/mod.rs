//! 8-bit RGB pictures: the PNG previews goldray writes, and the students' and golden PNGs it
//! reads and compares.
//!
//! A width, a height and the bytes row by row, three per pixel, which is what the `png` crate
//! encodes and decodes. goldray used the `image` crate for this buffer and its PNG decoding; with
//! its colour-management crates it was about 40 s of a fresh build's processor time for a type
//! of a few dozen lines and a conversion of the `png` crate's output ([`decode_png`]).

mod decode;
mod shrink;

use std::iter::FusedIterator;

use bytemuck::{Pod, Zeroable};

pub use decode::{Channels, DEFAULT_MAX_BYTES, DecodeError, DecodedPng, PngLayout, decode_png, read_png};

/// One pixel: red, green and blue.
#[repr(transparent)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Pod, Zeroable)]
pub struct Rgb(pub [u8; 3]);

/// A picture of `width × height` [`Rgb`] pixels, stored row by row from the top.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct RgbImage {
    width: u32,
    height: u32,
    bytes: Vec<u8>,
}

impl RgbImage {
    /// A black picture.
    pub fn new(width: u32, height: u32) -> RgbImage {
        RgbImage {
            width,
            height,
            bytes: vec![0; byte_len(width, height)],
        }
    }

    /// A picture of one colour.
    pub fn from_pixel(width: u32, height: u32, pixel: Rgb) -> RgbImage {
        RgbImage {
            width,
            height,
            bytes: pixel.0.repeat(pixel_count(width, height)),
        }
    }

    /// The picture whose pixel `(x, y)` is `pixel(x, y)`.
    pub fn from_fn(width: u32, height: u32, mut pixel: impl FnMut(u32, u32) -> Rgb) -> RgbImage {
        let mut bytes = Vec::with_capacity(byte_len(width, height));
        for y in 0..height {
            for x in 0..width {
                bytes.extend_from_slice(&pixel(x, y).0);
            }
        }
        RgbImage { width, height, bytes }
    }

    /// `bytes` as a picture, when they are exactly three per pixel.
    pub fn from_raw(width: u32, height: u32, bytes: Vec<u8>) -> Option<RgbImage> {
        (u64::try_from(bytes.len()).ok()? == 3 * u64::from(width) * u64::from(height)).then_some(RgbImage {
            width,
            height,
            bytes,
        })
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    pub fn dimensions(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The bytes, row by row, three per pixel.
    pub fn as_raw(&self) -> &[u8] {
        &self.bytes
    }

    pub fn into_raw(self) -> Vec<u8> {
        self.bytes
    }

    /// Pixel `(x, y)`; panics outside the picture, like indexing a slice.
    pub fn get_pixel(&self, x: u32, y: u32) -> &Rgb {
        let at = self.index(x, y);
        &self.pixel_slice()[at]
    }

    pub fn get_pixel_mut(&mut self, x: u32, y: u32) -> &mut Rgb {
        let at = self.index(x, y);
        &mut self.pixel_slice_mut()[at]
    }

    pub fn put_pixel(&mut self, x: u32, y: u32, pixel: Rgb) {
        *self.get_pixel_mut(x, y) = pixel;
    }

    /// Every pixel, row by row from the top.
    pub fn pixels(&self) -> std::slice::Iter<'_, Rgb> {
        self.pixel_slice().iter()
    }

    pub fn pixels_mut(&mut self) -> std::slice::IterMut<'_, Rgb> {
        self.pixel_slice_mut().iter_mut()
    }

    /// Every pixel with its position, row by row from the top.
    pub fn enumerate_pixels(&self) -> impl DoubleEndedIterator<Item = (u32, u32, &Rgb)> + FusedIterator {
        let width = self.width.max(1);
        self.pixels().enumerate().map(move |(i, pixel)| {
            let i = i as u64;
            ((i % u64::from(width)) as u32, (i / u64::from(width)) as u32, pixel)
        })
    }

    /// The rows, from the top.
    pub fn rows(&self) -> impl DoubleEndedIterator<Item = &[Rgb]> + ExactSizeIterator {
        self.pixel_slice().chunks_exact(self.width.max(1) as usize)
    }

    /// The picture upside down.
    pub fn flipped_vertically(&self) -> RgbImage {
        let row = 3 * self.width as usize;
        let bytes = match row {
            0 => Vec::new(),
            _ => self.bytes.chunks_exact(row).rev().flatten().copied().collect(),
        };
        RgbImage { bytes, ..*self }
    }

    /// The picture mirrored left to right.
    pub fn flipped_horizontally(&self) -> RgbImage {
        let mut flipped = self.clone();
        flipped.flip_horizontally();
        flipped
    }

    pub fn flip_vertically(&mut self) {
        *self = self.flipped_vertically();
    }

    pub fn flip_horizontally(&mut self) {
        let width = self.width.max(1) as usize;
        for row in self.pixel_slice_mut().chunks_exact_mut(width) {
            row.reverse();
        }
    }

    fn pixel_slice(&self) -> &[Rgb] {
        bytemuck::cast_slice(&self.bytes)
    }

    fn pixel_slice_mut(&mut self) -> &mut [Rgb] {
        bytemuck::cast_slice_mut(&mut self.bytes)
    }

    fn index(&self, x: u32, y: u32) -> usize {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) is outside a {}×{} picture",
            self.width,
            self.height
        );
        y as usize * self.width as usize + x as usize
    }
}

fn pixel_count(width: u32, height: u32) -> usize {
    width as usize * height as usize
}

fn byte_len(width: u32, height: u32) -> usize {
    3 * pixel_count(width, height)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn numbered(width: u32, height: u32) -> RgbImage {
        RgbImage::from_fn(width, height, |x, y| Rgb([x as u8, y as u8, (10 * y + x) as u8]))
    }

    #[test]
    fn pixels_are_stored_row_by_row_from_the_top() {
        let picture = numbered(3, 2);
        assert_eq!(picture.as_raw()[..6], [0, 0, 0, 1, 0, 1]);
        assert_eq!(*picture.get_pixel(2, 1), Rgb([2, 1, 12]));
        let positions: Vec<_> = picture.enumerate_pixels().map(|(x, y, p)| (x, y, p.0[2])).collect();
        assert_eq!(positions[4], (1, 1, 11));
        assert_eq!(picture.rows().len(), 2);
    }

    #[test]
    fn flips_move_pixels_to_the_mirrored_place() {
        let picture = numbered(3, 2);
        assert_eq!(*picture.flipped_vertically().get_pixel(2, 0), *picture.get_pixel(2, 1));
        assert_eq!(
            *picture.flipped_horizontally().get_pixel(0, 1),
            *picture.get_pixel(2, 1)
        );
        assert_eq!(picture.flipped_vertically().flipped_vertically(), picture);
    }

    #[test]
    fn raw_bytes_must_be_three_per_pixel() {
        assert!(RgbImage::from_raw(2, 2, vec![0; 12]).is_some());
        assert!(RgbImage::from_raw(2, 2, vec![0; 11]).is_none());
        assert!(RgbImage::from_raw(2, 2, vec![0; 13]).is_none());
    }

    #[test]
    fn empty_pictures_have_no_pixels_and_do_not_panic() {
        for picture in [RgbImage::new(0, 5), RgbImage::new(5, 0)] {
            assert_eq!(picture.pixels().count(), 0);
            assert_eq!(picture.flipped_vertically(), picture);
            assert_eq!(picture.flipped_horizontally(), picture);
        }
    }
}
