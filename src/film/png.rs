//! 8-bit PNG previews of the film, and their encoding. Colour goes through the case's tone map; depth and normals are data,
//! so they skip the sRGB curve but keep the tone map's rounding rule, which lets the `clamp`
//! (assignment) profile reproduce the reference renderer's depth and normal PNGs value for value.

use std::path::Path;

use rayon::prelude::*;

use super::error::OutputError;
use super::{Film, Tonemap};
use crate::atomic_write::write_file_atomic;
use crate::rgb_image::RgbImage;

/// Colour as the case asks: `Srgb` for viewing, `Clamp` for the assignment's `trunc(c·255)`.
pub fn color_image(film: &Film, tonemap: Tonemap) -> RgbImage {
    quantised_runs(film, tonemap, |first, values| {
        match film.color.get(first..first + values.len() / 3) {
            Some(colors) => values.copy_from_slice(colors.as_flattened()),
            None => fill_by_pixel(first, values, |i| film.color.get(i).copied().unwrap_or_default()),
        }
        if tonemap == Tonemap::Srgb {
            for v in values.iter_mut() {
                *v = srgb_encode(v.clamp(0.0, 1.0));
            }
        }
    })
}

/// Grey `(t − min)/(max − min)`: near is dark, far is white, and a miss is black (as in the
/// assignment) so that background never reads as "very far geometry".
pub fn depth_image(film: &Film, min: f32, max: f32, tonemap: Tonemap) -> RgbImage {
    let grey = |t: f32| {
        if t == f32::INFINITY {
            0.0
        } else {
            (t - min) / (max - min)
        }
    };
    quantised_runs(film, tonemap, |first, values| {
        match film.depth.get(first..first + values.len() / 3) {
            Some(depths) => {
                for (pixel, &t) in values.chunks_exact_mut(3).zip(depths) {
                    pixel.fill(grey(t));
                }
            }
            None => fill_by_pixel(first, values, |i| {
                [grey(film.depth.get(i).copied().unwrap_or(f32::INFINITY)); 3]
            }),
        }
    })
}

/// `(n + 1)/2` per axis; a miss has normal 0 and so shows mid-grey (127 with `Clamp`, 128 with
/// `Srgb`).
pub fn normals_image(film: &Film, tonemap: Tonemap) -> RgbImage {
    quantised_runs(film, tonemap, |first, values| {
        match film.normal.get(first..first + values.len() / 3) {
            Some(normals) => {
                for (v, &n) in values.iter_mut().zip(normals.as_flattened()) {
                    *v = (n + 1.0) / 2.0;
                }
            }
            None => fill_by_pixel(first, values, |i| {
                film.normal.get(i).copied().unwrap_or_default().map(|n| (n + 1.0) / 2.0)
            }),
        }
    })
}

/// The one loop behind every preview: `value` gives pixel `i`'s three channels in [0, 1] (anything
/// outside, NaN included, is tolerated) and each is quantised by the tone map's rule. A film whose
/// buffers are shorter than its size shows the missing pixels as misses rather than panicking;
/// the EXR encoder is what rejects such a film.
pub(super) fn quantised_image(film: &Film, tonemap: Tonemap, value: impl Fn(usize) -> [f32; 3] + Sync) -> RgbImage {
    quantised_runs(film, tonemap, |first, values| fill_by_pixel(first, values, &value))
}

/// Sets `values` (three per pixel) to `value` of the pixels from `first` on.
fn fill_by_pixel(first: usize, values: &mut [f32], value: impl Fn(usize) -> [f32; 3]) {
    for (k, pixel) in values.chunks_exact_mut(3).enumerate() {
        pixel.copy_from_slice(&value(first + k));
    }
}

/// [`quantised_image`] a run of pixels at a time: `fill(first, values)` sets `values` to the three
/// channels of each pixel from `first` on (a run never crosses a row band), so that the pictures
/// the course writes can copy and remap whole slices of the film, which the compiler vectorises,
/// instead of calling a closure per pixel.
///
/// Rows are quantised in parallel, straight into the image's bytes (pixel `i` is row-major, as
/// [`Film::index`] numbers it).
fn quantised_runs(film: &Film, tonemap: Tonemap, fill: impl Fn(usize, &mut [f32]) + Sync) -> RgbImage {
    /// Rows per parallel work item.
    const BAND_ROWS: usize = 16;
    /// Pixels whose values are gathered, then quantised together.
    const RUN: usize = 256;
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
                    fill(first + run * RUN, values);
                    quantise_run(values, tonemap, out);
                }
            });
    }
    RgbImage::from_raw(film.width, film.height, bytes).expect("three bytes per pixel")
}

/// [`quantise`] of each value into `out`.
fn quantise_run(values: &[f32], tonemap: Tonemap, out: &mut [u8]) {
    match tonemap {
        Tonemap::Clamp => quantise_clamp_run(values, out),
        Tonemap::Srgb => {
            for (byte, &v) in out.iter_mut().zip(values) {
                *byte = quantise(v, tonemap);
            }
        }
    }
}

/// [`quantise_clamp`] of each value into `out`, sixteen at a time with SSE2: `cvttps2dq` is the
/// course's `int(c·255)` itself (truncation, and `INT_MIN` for NaN and whatever does not fit),
/// and the two saturating packs are its clamp to [0, 255]. LLVM does not vectorise the scalar
/// form (Rust's saturating `as` has no SSE2 instruction), which costs ten instructions a value.
#[cfg(target_arch = "x86_64")]
fn quantise_clamp_run(values: &[f32], out: &mut [u8]) {
    // SAFETY: SSE2 is part of the x86-64 baseline: every processor this code runs on has it.
    unsafe { quantise_clamp_run_sse2(values, out) }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse2")]
fn quantise_clamp_run_sse2(values: &[f32], out: &mut [u8]) {
    use std::arch::x86_64::*;
    let scale = _mm_set1_ps(255.0);
    let mut values = values.chunks_exact(16);
    let mut outs = out.chunks_exact_mut(16);
    for (v, out) in (&mut values).zip(&mut outs) {
        let int = |i: usize| _mm_cvttps_epi32(_mm_mul_ps(_mm_setr_ps(v[i], v[i + 1], v[i + 2], v[i + 3]), scale));
        let bytes = _mm_packus_epi16(_mm_packs_epi32(int(0), int(4)), _mm_packs_epi32(int(8), int(12)));
        out[..8].copy_from_slice(&_mm_cvtsi128_si64(bytes).to_le_bytes());
        out[8..].copy_from_slice(&_mm_cvtsi128_si64(_mm_unpackhi_epi64(bytes, bytes)).to_le_bytes());
    }
    for (byte, &v) in outs.into_remainder().iter_mut().zip(values.remainder()) {
        *byte = quantise_clamp(v);
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn quantise_clamp_run(values: &[f32], out: &mut [u8]) {
    for (byte, &v) in out.iter_mut().zip(values) {
        *byte = quantise_clamp(v);
    }
}

/// [`quantise`] with `Clamp`: `as u8` truncates towards zero (`trunc` itself is a library call
/// on x86-64 without SSE4.1) and saturates (below 0 gives 0, above 255 gives 255, NaN gives 0),
/// which is the clamp to [0, 1] and the truncation at once; only what overflows an `int` in the
/// course's conversion needs its own test.
#[inline]
fn quantise_clamp(v: f32) -> u8 {
    let scaled = v * 255.0;
    // 2³¹: the first value x86's float-to-int conversion cannot represent.
    if scaled >= 2_147_483_648.0 { 0 } else { scaled as u8 }
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
        Tonemap::Clamp => quantise_clamp(v),
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

/// Encodes with fdeflate's fast mode (the `png` crate's `Fast`) over rows filtered with `Sub`:
/// previews are read back by programs, not archived. Against `Fast`'s own filtering (each row's
/// filter chosen among all five by trying them), `Sub` halves the instructions of encoding the
/// course's 21 pictures at 800×800 for files 18% larger; `Up` is as fast and larger still,
/// `Paeth` as small as trying all five and 40% slower than `Sub`.
pub(super) fn encode_png_named(image: &RgbImage, file: &str) -> Result<Vec<u8>, OutputError> {
    let fail = |error: png::EncodingError| OutputError::EncodePng {
        file: file.to_owned(),
        source: error,
    };
    let mut bytes = Vec::with_capacity(image.as_raw().len() / 4 + 1024);
    let mut encoder = png::Encoder::new(&mut bytes, image.width(), image.height());
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    encoder.set_filter(png::Filter::Sub);
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

    /// The SIMD runs and the value-by-value rule agree on every kind of value, in a run long
    /// enough for both the vector loop and its remainder.
    #[test]
    fn clamp_runs_quantise_like_each_value() {
        let limit = 2_147_483_648.0_f32 / 255.0;
        let specials = [
            0.0,
            -0.0,
            1e-10,
            f32::MIN_POSITIVE / 2.0,
            0.5,
            0.999,
            1.0 / 255.0,
            1.0,
            1.5,
            -0.1,
            -1e9,
            limit * 0.999,
            limit,
            limit * 1.001,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            254.9 / 255.0,
        ];
        let values: Vec<f32> = specials.iter().cycle().take(53).copied().collect();
        let mut out = vec![7; values.len()];
        quantise_run(&values, Tonemap::Clamp, &mut out);
        let expected: Vec<u8> = values.iter().map(|&v| quantise(v, Tonemap::Clamp)).collect();
        assert_eq!(out, expected);
        assert_eq!(&out[..6], &[0, 0, 0, 0, 127, 254]);
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
