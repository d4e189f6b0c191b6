//! Any PNG as 8-bit RGB, with how it was stored.
//!
//! The `png` crate expands palettes, transparency chunks and bit depths below 8
//! (`Transformations::EXPAND`), which leaves grey, grey+alpha, RGB or RGBA at 8 or 16 bits; this
//! converts those to RGB the way the `image` crate, which goldray used before, did: grey copied to
//! R, G and B, alpha dropped (the colour is kept as stored, not blended), and 16-bit values
//! rounded to the nearest 8-bit value, `(v + 128) / 257`.

use std::fmt;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use super::RgbImage;

/// The channels a PNG holds once expanded, and their bits (8 or 16).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PngLayout {
    pub channels: Channels,
    pub bits: u8,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channels {
    Grey,
    GreyAlpha,
    Rgb,
    Rgba,
}

impl Channels {
    fn count(self) -> usize {
        match self {
            Channels::Grey => 1,
            Channels::GreyAlpha => 2,
            Channels::Rgb => 3,
            Channels::Rgba => 4,
        }
    }
}

impl PngLayout {
    pub fn has_alpha(self) -> bool {
        matches!(self.channels, Channels::GreyAlpha | Channels::Rgba)
    }

    pub fn is_grey(self) -> bool {
        matches!(self.channels, Channels::Grey | Channels::GreyAlpha)
    }

    /// Bytes of the decoded picture in this layout.
    fn decoded_bytes(self, width: u32, height: u32) -> u64 {
        u64::from(width) * u64::from(height) * self.channels.count() as u64 * u64::from(self.bits / 8)
    }
}

/// `Rgb8`, `La16`, … as the `image` crate named them (the words a grading note has used).
impl fmt::Display for PngLayout {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let channels = match self.channels {
            Channels::Grey => "L",
            Channels::GreyAlpha => "La",
            Channels::Rgb => "Rgb",
            Channels::Rgba => "Rgba",
        };
        write!(f, "{channels}{}", self.bits)
    }
}

/// A decoded PNG: its pixels as RGB and what it held.
#[derive(Clone, Debug)]
pub struct DecodedPng {
    pub image: RgbImage,
    pub layout: PngLayout,
    /// Pixels whose alpha (rounded to 8 bits) is not opaque; 0 without alpha.
    pub translucent: usize,
}

#[derive(Debug, thiserror::Error)]
pub enum DecodeError {
    /// The decoded picture would take more than the caller allows.
    #[error("{width}×{height} pixels of {layout} take {bytes} bytes decoded, over the limit of {limit}")]
    TooLarge {
        width: u32,
        height: u32,
        layout: PngLayout,
        bytes: u64,
        limit: u64,
    },
    /// Decoding would allocate more than the limit for something other than the picture (its
    /// text or colour-profile chunks).
    #[error("decoding would exceed the memory limit")]
    OverMemoryLimit,
    /// The file ends before its image data does.
    #[error("the file ends before the image data does")]
    Truncated,
    #[error("{0}")]
    Corrupt(png::DecodingError),
    #[error("cannot read {path}: {source}", path = path.display())]
    Read { path: PathBuf, source: std::io::Error },
}

/// The PNG file at `path` as 8-bit RGB, with no limit on its size: for goldray's own files and
/// the course's (a student's file goes through [`decode_png`] with the grader's limits).
pub fn read_png(path: &Path) -> Result<RgbImage, DecodeError> {
    let bytes = std::fs::read(path).map_err(|source| DecodeError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(decode_png(&bytes, u64::MAX)?.image)
}

/// The decoding limit for files goldray reads on its own behalf (golden and compared pictures,
/// cube map faces): 512 MiB decoded, the limit the `image` crate set by default when it decoded
/// them, far above any picture goldray makes or compares. Students' files get the grader's own.
pub const DEFAULT_MAX_BYTES: u64 = 512 << 20;

/// Decodes `bytes` as a PNG of at most `max_bytes` once decoded (checked from the header, before
/// anything is allocated: a decompression bomb declares its size).
pub fn decode_png(bytes: &[u8], max_bytes: u64) -> Result<DecodedPng, DecodeError> {
    let limit = usize::try_from(max_bytes).unwrap_or(usize::MAX);
    let mut decoder = png::Decoder::new_with_limits(Cursor::new(bytes), png::Limits { bytes: limit });
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(failure)?;
    let (width, height) = (reader.info().width, reader.info().height);
    let layout = layout_of(reader.output_color_type());
    let decoded_bytes = layout.decoded_bytes(width, height);
    if decoded_bytes > max_bytes {
        return Err(DecodeError::TooLarge {
            width,
            height,
            layout,
            bytes: decoded_bytes,
            limit: max_bytes,
        });
    }
    let mut samples = vec![0; decoded_bytes as usize];
    reader.next_frame(&mut samples).map_err(failure)?;
    let (image, translucent) = to_rgb8(width, height, layout, samples);
    Ok(DecodedPng {
        image,
        layout,
        translucent,
    })
}

fn layout_of((color, depth): (png::ColorType, png::BitDepth)) -> PngLayout {
    let channels = match color {
        png::ColorType::Grayscale => Channels::Grey,
        png::ColorType::GrayscaleAlpha => Channels::GreyAlpha,
        png::ColorType::Rgba => Channels::Rgba,
        // EXPAND turns a palette into RGB (or RGBA, with a transparency chunk).
        png::ColorType::Rgb | png::ColorType::Indexed => Channels::Rgb,
    };
    let bits = if depth == png::BitDepth::Sixteen { 16 } else { 8 };
    PngLayout { channels, bits }
}

/// The samples as RGB bytes, and how many pixels are not opaque.
fn to_rgb8(width: u32, height: u32, layout: PngLayout, samples: Vec<u8>) -> (RgbImage, usize) {
    let eight_bit: Vec<u8> = match layout.bits {
        16 => samples
            .chunks_exact(2)
            .map(|pair| ((u32::from(u16::from_be_bytes([pair[0], pair[1]])) + 128) / 257) as u8)
            .collect(),
        _ => samples,
    };
    let count = layout.channels.count();
    let translucent = match layout.has_alpha() {
        true => eight_bit
            .chunks_exact(count)
            .filter(|p| p[count - 1] != u8::MAX)
            .count(),
        false => 0,
    };
    let bytes = match layout.channels {
        Channels::Rgb => eight_bit,
        Channels::Rgba => eight_bit.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect(),
        Channels::Grey | Channels::GreyAlpha => eight_bit.chunks_exact(count).flat_map(|p| [p[0]; 3]).collect(),
    };
    let image = RgbImage::from_raw(width, height, bytes).unwrap_or_else(|| RgbImage::new(width, height));
    (image, translucent)
}

fn failure(error: png::DecodingError) -> DecodeError {
    match error {
        png::DecodingError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => DecodeError::Truncated,
        png::DecodingError::LimitsExceeded => DecodeError::OverMemoryLimit,
        other => DecodeError::Corrupt(other),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn encode(width: u32, height: u32, color: png::ColorType, depth: png::BitDepth, data: &[u8]) -> Vec<u8> {
        let mut bytes = Vec::new();
        let mut encoder = png::Encoder::new(&mut bytes, width, height);
        encoder.set_color(color);
        encoder.set_depth(depth);
        encoder.write_header().unwrap().write_image_data(data).unwrap();
        bytes
    }

    #[test]
    fn grey_is_copied_to_every_channel_and_alpha_is_dropped_but_counted() {
        let grey = encode(
            2,
            1,
            png::ColorType::GrayscaleAlpha,
            png::BitDepth::Eight,
            &[10, 255, 20, 128],
        );
        let decoded = decode_png(&grey, 1 << 20).unwrap();
        assert_eq!(decoded.image.as_raw(), [10, 10, 10, 20, 20, 20]);
        assert_eq!(decoded.translucent, 1);
        assert_eq!(decoded.layout.to_string(), "La8");
    }

    #[test]
    fn sixteen_bits_round_to_the_nearest_eight_bit_value() {
        let values: [u16; 3] = [0x8080, 0x807f, 0xffff];
        let data: Vec<u8> = values.iter().flat_map(|v| v.to_be_bytes()).collect();
        let decoded = decode_png(
            &encode(1, 1, png::ColorType::Rgb, png::BitDepth::Sixteen, &data),
            1 << 20,
        )
        .unwrap();
        assert_eq!(decoded.image.as_raw(), [128, 128, 255]);
        assert_eq!(decoded.layout.to_string(), "Rgb16");
    }

    #[test]
    fn a_declared_size_over_the_limit_is_refused_before_decoding() {
        let small = encode(4, 4, png::ColorType::Rgba, png::BitDepth::Eight, &[0; 64]);
        assert!(matches!(
            decode_png(&small, 63),
            Err(DecodeError::TooLarge { bytes: 64, .. })
        ));
        assert!(decode_png(&small, 64).is_ok());
    }

    #[test]
    fn a_cut_file_is_truncated_not_a_panic() {
        let whole = encode(8, 8, png::ColorType::Rgb, png::BitDepth::Eight, &[7; 192]);
        for cut in [whole.len() / 2, whole.len() - 13] {
            assert!(decode_png(&whole[..cut], 1 << 20).is_err());
        }
    }
}
