//! 8-bit PNG previews of the film, and their encoding. Colour goes through the case's tone map; depth and normals are data,
//! so they skip the sRGB curve but keep the tone map's rounding rule, which lets the `clamp`
//! (assignment) profile reproduce the reference renderer's depth and normal PNGs value for value.

use std::path::Path;

use image::error::{EncodingError, ImageFormatHint};
use image::{ImageError, ImageFormat, RgbImage};
use rayon::prelude::*;

use super::error::OutputError;
use super::{Film, Tonemap};
use crate::atomic_write::write_file_atomic;

/// Colour as the case asks: `Srgb` for viewing, `Clamp` for the assignment's `trunc(c·255)`.
pub fn color_image(film: &Film, tonemap: Tonemap) -> RgbImage {
    quantised_image(film, tonemap, |i| {
        let color = film.color.get(i).copied().unwrap_or_default();
        color.map(|c| match tonemap {
            Tonemap::Srgb => srgb_encode(c.clamp(0.0, 1.0)),
            Tonemap::Clamp => c,
        })
    })
}

/// Grey `(t − min)/(max − min)`: near is dark, far is white, and a miss is black (as in the
/// assignment) so that background never reads as "very far geometry".
pub fn depth_image(film: &Film, min: f32, max: f32, tonemap: Tonemap) -> RgbImage {
    quantised_image(film, tonemap, |i| {
        let t = film.depth.get(i).copied().unwrap_or(f32::INFINITY);
        let grey = if t == f32::INFINITY {
            0.0
        } else {
            (t - min) / (max - min)
        };
        [grey; 3]
    })
}

/// `(n + 1)/2` per axis; a miss has normal 0 and so shows mid-grey (127 with `Clamp`, 128 with
/// `Srgb`).
pub fn normals_image(film: &Film, tonemap: Tonemap) -> RgbImage {
    quantised_image(film, tonemap, |i| {
        let normal = film.normal.get(i).copied().unwrap_or_default();
        normal.map(|n| (n + 1.0) / 2.0)
    })
}

/// The one loop behind every preview: `value` gives pixel `i`'s three channels in [0, 1] (anything
/// outside, NaN included, is tolerated) and each is quantised by the tone map's rule. A film whose
/// buffers are shorter than its size shows the missing pixels as misses rather than panicking;
/// the EXR encoder is what rejects such a film.
///
/// Rows are quantised in parallel, straight into the image's bytes (pixel `i` is row-major, as
/// [`Film::index`] numbers it).
pub(super) fn quantised_image(film: &Film, tonemap: Tonemap, value: impl Fn(usize) -> [f32; 3] + Sync) -> RgbImage {
    /// Rows per parallel work item.
    const BAND_ROWS: usize = 16;
    /// Pixels whose values are gathered, then quantised together.
    const RUN: usize = 64;
    let width = film.width as usize;
    let mut bytes = vec![0; width * film.height as usize * 3];
    if width > 0 {
        bytes
            .par_chunks_mut(width * 3 * BAND_ROWS)
            .enumerate()
            .for_each(|(band, out)| {
                let first = band * width * BAND_ROWS;
                let mut values = [0.0; 3 * RUN];
                for (run, out) in out.chunks_mut(3 * RUN).enumerate() {
                    let values = &mut values[..out.len()];
                    for (k, pixel) in values.chunks_exact_mut(3).enumerate() {
                        pixel.copy_from_slice(&value(first + run * RUN + k));
                    }
                    quantise_run(values, tonemap, out);
                }
            });
    }
    RgbImage::from_raw(film.width, film.height, bytes).expect("three bytes per pixel")
}

/// [`quantise`] of each value into `out`. With `Clamp`, a run whose values all lie in [0, 1]
/// (where `quantise` is plain `trunc(v·255)`) is converted in one loop the compiler vectorises;
/// any other run, value by value.
fn quantise_run(values: &[f32], tonemap: Tonemap, out: &mut [u8]) {
    let in_unit_range = values.iter().fold(true, |all, &v| all & (0.0..=1.0).contains(&v));
    if tonemap == Tonemap::Clamp && in_unit_range {
        for (byte, &v) in out.iter_mut().zip(values) {
            *byte = (v * 255.0) as i32 as u8;
        }
    } else {
        for (byte, &v) in out.iter_mut().zip(values) {
            *byte = quantise(v, tonemap);
        }
    }
}

/// `Clamp` is the assignment's `clampColorComponent`: `int(c·255)`, then clamped to [0, 255].
/// Where `c·255` does not fit an `int` (from about 8.4 million, infinity and NaN) x86's
/// conversion yields `INT_MIN`, so the course's images show 0 there, not 255: an exploding
/// highlight is black in the reference, and here too. `Srgb` rounds to nearest, NaN is 0 and
/// ±inf saturate. No render value can make a preview fail.
fn quantise(v: f32, tonemap: Tonemap) -> u8 {
    if v.is_nan() {
        return 0;
    }
    match tonemap {
        // 2³¹: the first value x86's float-to-int conversion cannot represent.
        Tonemap::Clamp if v * 255.0 >= 2_147_483_648.0 => 0,
        // `as` truncates towards zero, which is `trunc` for this non-negative value, in one
        // instruction; `trunc` itself is a library call on x86-64 without SSE4.1.
        Tonemap::Clamp => (v.clamp(0.0, 1.0) * 255.0) as u8,
        Tonemap::Srgb => (v.clamp(0.0, 1.0) * 255.0).round() as u8,
    }
}

/// The tone map before its rounding rule: the 8-bit code a linear value maps to, as a real
/// number (0 to 255). What a statistical comparison of PNGs converts a linear noise level with.
pub fn tone_curve(linear: f32, tonemap: Tonemap) -> f32 {
    let v = if linear.is_nan() { 0.0 } else { linear.clamp(0.0, 1.0) };
    255.0
        * match tonemap {
            Tonemap::Srgb => srgb_encode(v),
            Tonemap::Clamp => v,
        }
}

/// The piecewise sRGB transfer curve of IEC 61966-2-1 (not a pure 2.2 gamma, which would darken
/// the shadows by several codes).
fn srgb_encode(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// Lossless 8-bit RGB PNG bytes.
pub fn encode_png(image: &RgbImage) -> Result<Vec<u8>, OutputError> {
    encode_png_named(image, "PNG data")
}

/// [`encode_png`] written with [`write_file_atomic`].
pub fn write_png(path: &Path, image: &RgbImage) -> Result<(), OutputError> {
    let bytes = encode_png_named(image, &path.display().to_string())?;
    Ok(write_file_atomic(path, &bytes)?)
}

/// Encodes with the `png` crate's `Fast` setting (fdeflate, adaptive row filters): previews are
/// read back by programs, not archived, and it is several times faster than the default level
/// at a similar size for rendered images.
pub(super) fn encode_png_named(image: &RgbImage, file: &str) -> Result<Vec<u8>, OutputError> {
    let fail = |error: png::EncodingError| OutputError::EncodePng {
        file: file.to_owned(),
        source: ImageError::Encoding(EncodingError::new(ImageFormatHint::Exact(ImageFormat::Png), error)),
    };
    let mut bytes = Vec::with_capacity(image.as_raw().len() / 4 + 1024);
    let mut encoder = png::Encoder::new(&mut bytes, image.width(), image.height());
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    let mut writer = encoder.write_header().map_err(fail)?;
    writer.write_image_data(image.as_raw()).map_err(fail)?;
    writer.finish().map_err(fail)?;
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn film_with(color: [f32; 3], depth: f32, normal: [f32; 3]) -> Film {
        let mut film = Film::new(1, 1);
        film.color[0] = color;
        film.depth[0] = depth;
        film.normal[0] = normal;
        film
    }

    fn colour(c: f32, tonemap: Tonemap) -> u8 {
        color_image(&film_with([c; 3], 1.0, [0.0; 3]), tonemap)
            .get_pixel(0, 0)
            .0[0]
    }

    fn depth(t: f32, tonemap: Tonemap) -> u8 {
        depth_image(&film_with([0.0; 3], t, [0.0; 3]), 8.0, 18.0, tonemap)
            .get_pixel(0, 0)
            .0[0]
    }

    #[test]
    fn srgb_matches_the_standard_at_known_points() {
        assert_eq!(colour(0.0, Tonemap::Srgb), 0);
        assert_eq!(colour(0.5, Tonemap::Srgb), 188);
        assert_eq!(colour(0.18, Tonemap::Srgb), 118);
        assert_eq!(colour(0.002, Tonemap::Srgb), 7); // linear segment: 12.92 · 0.002 · 255 = 6.6
        assert_eq!(colour(1.0, Tonemap::Srgb), 255);
        assert_eq!(colour(7.0, Tonemap::Srgb), 255);
        assert_eq!(colour(-1.0, Tonemap::Srgb), 0);
    }

    #[test]
    fn srgb_pieces_meet_at_the_boundary() {
        let boundary = 0.003_130_8_f32;
        let above = 1.055 * boundary.powf(1.0 / 2.4) - 0.055;
        assert!((srgb_encode(boundary) - above).abs() < 1e-5);
        assert_eq!(colour(boundary, Tonemap::Srgb), 10); // 0.04045 · 255 = 10.3
        assert_eq!(colour(f32::from_bits(boundary.to_bits() + 1), Tonemap::Srgb), 10);
    }

    #[test]
    fn clamp_truncates_like_the_assignment() {
        assert_eq!(colour(0.999, Tonemap::Clamp), 254);
        assert_eq!(colour(1.0, Tonemap::Clamp), 255);
        assert_eq!(colour(1.5, Tonemap::Clamp), 255);
        assert_eq!(colour(0.5, Tonemap::Clamp), 127);
        assert_eq!(colour(-0.1, Tonemap::Clamp), 0);
    }

    #[test]
    fn non_finite_values_never_escape_the_byte_range() {
        for tonemap in [Tonemap::Srgb, Tonemap::Clamp] {
            assert_eq!(colour(f32::NAN, tonemap), 0);
            assert_eq!(colour(f32::NEG_INFINITY, tonemap), 0);
        }
        assert_eq!(colour(f32::INFINITY, Tonemap::Srgb), 255);
    }

    /// The course's `int(c·255)` overflows to `INT_MIN` from 2³¹/255 on, which it clamps to 0.
    #[test]
    fn clamp_shows_what_overflows_an_int_as_black_like_the_assignment() {
        let limit = 2_147_483_648.0 / 255.0;
        assert_eq!(colour(limit * 0.999, Tonemap::Clamp), 255);
        assert_eq!(colour(limit * 1.001, Tonemap::Clamp), 0);
        assert_eq!(colour(f32::MAX, Tonemap::Clamp), 0);
        assert_eq!(colour(f32::INFINITY, Tonemap::Clamp), 0);
        assert_eq!(colour(f32::MAX, Tonemap::Srgb), 255);
    }

    #[test]
    fn depth_is_dark_near_white_far_and_black_on_a_miss() {
        assert_eq!(depth(f32::INFINITY, Tonemap::Clamp), 0);
        assert_eq!(depth(f32::INFINITY, Tonemap::Srgb), 0);
        assert_eq!(depth(8.0, Tonemap::Clamp), 0);
        assert_eq!(depth(2.0, Tonemap::Clamp), 0);
        assert_eq!(depth(18.0, Tonemap::Clamp), 255);
        assert_eq!(depth(1e6, Tonemap::Clamp), 255);
        // The course's `int(c·255)` overflows far beyond `max`, as for colours.
        assert_eq!(depth(1e30, Tonemap::Clamp), 0);
        assert_eq!(depth(1e30, Tonemap::Srgb), 255);
        assert!(depth(10.0, Tonemap::Clamp) < depth(16.0, Tonemap::Clamp));
    }

    #[test]
    fn depth_uses_the_quantiser_without_the_srgb_curve() {
        // (13 − 8)/10 = 0.5: truncated 127, rounded 128; the sRGB curve would give 188.
        assert_eq!(depth(13.0, Tonemap::Clamp), 127);
        assert_eq!(depth(13.0, Tonemap::Srgb), 128);
    }

    #[test]
    fn normals_map_minus_one_to_one_onto_the_byte_range() {
        let film = film_with([0.0; 3], 3.0, [-1.0, 1.0, 0.0]);
        assert_eq!(normals_image(&film, Tonemap::Clamp).get_pixel(0, 0).0, [0, 255, 127]);
        assert_eq!(normals_image(&film, Tonemap::Srgb).get_pixel(0, 0).0, [0, 255, 128]);
    }

    #[test]
    fn a_missed_pixel_has_grey_127_normals_with_clamp() {
        let film = Film::new(2, 1);
        assert_eq!(normals_image(&film, Tonemap::Clamp).get_pixel(1, 0).0, [127; 3]);
    }

    #[test]
    fn images_keep_row_zero_at_the_top() {
        let mut film = Film::new(1, 2);
        film.color[0] = [1.0; 3];
        let image = color_image(&film, Tonemap::Clamp);
        assert_eq!((image.get_pixel(0, 0).0, image.get_pixel(0, 1).0), ([255; 3], [0; 3]));
    }

    #[test]
    fn a_film_with_short_buffers_renders_as_misses() {
        let mut film = Film::new(2, 2);
        film.color.clear();
        film.depth.clear();
        film.normal.clear();
        assert_eq!(color_image(&film, Tonemap::Clamp).get_pixel(1, 1).0, [0; 3]);
        assert_eq!(depth_image(&film, 0.0, 1.0, Tonemap::Clamp).get_pixel(1, 1).0, [0; 3]);
        assert_eq!(normals_image(&film, Tonemap::Clamp).get_pixel(1, 1).0, [127; 3]);
    }
}
