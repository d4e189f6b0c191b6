//! What a comparison reads: an EXR film or an 8-bit PNG, as named channel planes plus the 8-bit
//! sRGB picture that FLIP and the diff heatmap need.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use ::exr::meta::MetaData;
use serde::{Deserialize, Serialize};

use super::error::CompareError;
use super::flip::Reference;
use crate::film::{Film, Tonemap, color_image, decode_exr};
use crate::rgb_image::{DEFAULT_MAX_BYTES, RgbImage, decode_png};

/// The EXR channels goldray writes and reads, in the contract's order. Other channels in a file
/// are not compared, because the film reader does not decode them.
pub(super) const FILM_CHANNELS: [&str; 7] = ["R", "G", "B", "Z", "N.X", "N.Y", "N.Z"];

/// The colour channels: the ones MAE, RMSE, PSNR and the worst pixel are measured on.
pub const COLOR_CHANNELS: [&str; 3] = ["R", "G", "B"];

const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];
const PNG_MAGIC: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];

/// How the values of an image are encoded, which sets the units of every threshold and metric.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Encoding {
    /// Scene-referred linear floats (EXR); PSNR is measured against a peak of 1.
    Linear,
    /// Display-referred 8-bit code values 0–255 (PNG); PSNR is measured against a peak of 255.
    Code8,
}

impl Encoding {
    pub fn peak(self) -> f64 {
        match self {
            Encoding::Linear => 1.0,
            Encoding::Code8 => 255.0,
        }
    }
}

/// One channel's values, row-major with row 0 at the top.
#[derive(Clone, Debug)]
pub struct Channel {
    pub name: &'static str,
    pub values: Plane,
}

/// A channel's values as stored: floats, or an 8-bit picture's code values as bytes. A class's
/// golden pictures are kept all through grading and every student's picture is read into one,
/// so bytes are a quarter of the pages to fill (121 MB less for the course's 21 goldens); a byte
/// reads as the float of its code value, so what is measured does not change.
#[derive(Clone, Debug, PartialEq)]
pub enum Plane {
    Linear(Vec<f32>),
    Code8(Vec<u8>),
}

/// Each code value as a float, so that a byte plane can be indexed like a float one.
static CODE_VALUES: [f32; 256] = {
    let mut values = [0.0; 256];
    let mut code = 0;
    while code < 256 {
        values[code] = code as f32;
        code += 1;
    }
    values
};

impl Plane {
    pub fn len(&self) -> usize {
        match self {
            Plane::Linear(values) => values.len(),
            Plane::Code8(codes) => codes.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn iter(&self) -> impl Iterator<Item = f32> + '_ {
        (0..self.len()).map(|i| self[i])
    }

    /// Whether both planes hold `range` and equal values there (`==`, so never a NaN).
    pub fn equal_in(&self, other: &Plane, range: std::ops::Range<usize>) -> bool {
        match (self, other) {
            (Plane::Linear(a), Plane::Linear(b)) => a.get(range.clone()).is_some_and(|a| Some(a) == b.get(range)),
            (Plane::Code8(a), Plane::Code8(b)) => a.get(range.clone()).is_some_and(|a| Some(a) == b.get(range)),
            _ => range.end <= self.len().min(other.len()) && range.clone().all(|i| self[i] == other[i]),
        }
    }
}

impl std::ops::Index<usize> for Plane {
    type Output = f32;

    #[inline]
    fn index(&self, i: usize) -> &f32 {
        match self {
            Plane::Linear(values) => &values[i],
            Plane::Code8(codes) => &CODE_VALUES[usize::from(codes[i])],
        }
    }
}

impl Channel {
    /// Depth stores a miss as `+inf`, so there `+inf` against a finite depth is a silhouette that
    /// moved (a failing pixel), not a broken value.
    pub fn infinity_is_a_value(&self) -> bool {
        self.name == "Z"
    }
}

#[derive(Clone, Debug)]
pub struct Image {
    /// The file (or snapshot) the image came from, for messages.
    pub source: PathBuf,
    pub encoding: Encoding,
    pub width: u32,
    pub height: u32,
    pub channels: Vec<Channel>,
    /// The variance of each pixel's mean colour (R, G, B), when the image is an EXR of a render
    /// with several samples per pixel: what the statistical verdict weighs differences by.
    pub variance: Option<Vec<[f32; 3]>>,
    /// The colour as a person sees it: FLIP's input and the heatmap's backdrop.
    pub preview: RgbImage,
    /// What FLIP keeps of `preview` as a reference, made the first time a differing picture is
    /// compared against this one and kept for the next: a golden image is the reference of a
    /// whole class.
    pub(super) flip: OnceLock<Reference>,
}

impl Image {
    /// All seven film channels; colour is previewed with the sRGB tone map whatever the case's
    /// own tone map, because FLIP models a viewer looking at an sRGB display.
    pub fn from_film(film: &Film, source: impl Into<PathBuf>) -> Image {
        Image::from_film_channels(film, source.into(), |_| true)
    }

    /// Code values as stored: a PNG is compared as the bytes a viewer shows.
    pub fn from_rgb8(picture: RgbImage, source: impl Into<PathBuf>) -> Image {
        let planes: [Vec<u8>; 3] = std::array::from_fn(|c| picture.as_raw().chunks_exact(3).map(|p| p[c]).collect());
        Image {
            source: source.into(),
            encoding: Encoding::Code8,
            width: picture.width(),
            height: picture.height(),
            channels: COLOR_CHANNELS
                .iter()
                .zip(planes)
                .map(|(&name, codes)| Channel {
                    name,
                    values: Plane::Code8(codes),
                })
                .collect(),
            variance: None,
            preview: picture,
            flip: OnceLock::new(),
        }
    }

    /// Keeps only the film channels the file really has: the film reader fills absent AOVs with
    /// "miss" values, and comparing those invented values would hide a channel-set mismatch.
    pub fn from_exr_bytes(bytes: &[u8], source: impl Into<PathBuf>) -> Result<Image, CompareError> {
        let source = source.into();
        let meta = MetaData::read_from_buffered(bytes, false).map_err(|e| CompareError::ExrHeader {
            path: source.clone(),
            source: e,
        })?;
        let film = decode_exr(bytes).map_err(|e| CompareError::Exr {
            path: source.clone(),
            source: e,
        })?;
        let present = |name: &str| {
            meta.headers
                .first()
                .is_some_and(|header| header.channels.list.iter().any(|c| c.name == *name))
        };
        Ok(Image::from_film_channels(&film, source, present))
    }

    pub fn from_png_bytes(bytes: &[u8], source: impl Into<PathBuf>) -> Result<Image, CompareError> {
        let source = source.into();
        let decoded = decode_png(bytes, DEFAULT_MAX_BYTES).map_err(|e| CompareError::Png {
            path: source.clone(),
            source: e,
        })?;
        Ok(Image::from_rgb8(decoded.image, source))
    }

    /// Decides EXR or PNG by the file's signature, not its name, so that a misnamed file is read
    /// for what it is.
    pub fn read(path: &Path) -> Result<Image, CompareError> {
        let bytes = std::fs::read(path).map_err(|e| CompareError::Read {
            path: path.to_path_buf(),
            source: e,
        })?;
        if bytes.starts_with(&EXR_MAGIC) {
            Image::from_exr_bytes(&bytes, path)
        } else if bytes.starts_with(&PNG_MAGIC) {
            Image::from_png_bytes(&bytes, path)
        } else {
            Err(CompareError::UnknownFormat {
                path: path.to_path_buf(),
            })
        }
    }

    pub fn channel_names(&self) -> Vec<&'static str> {
        self.channels.iter().map(|c| c.name).collect()
    }

    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    fn from_film_channels(film: &Film, source: PathBuf, keep: impl Fn(&str) -> bool) -> Image {
        let pick = |values: &[[f32; 3]], c: usize| values.iter().map(|v| v[c]).collect();
        let planes: [Vec<f32>; 7] = [
            pick(&film.color, 0),
            pick(&film.color, 1),
            pick(&film.color, 2),
            film.depth.clone(),
            pick(&film.normal, 0),
            pick(&film.normal, 1),
            pick(&film.normal, 2),
        ];
        let channels = FILM_CHANNELS
            .into_iter()
            .zip(planes)
            .filter(|(name, _)| keep(name))
            .map(|(name, values)| Channel {
                name,
                values: Plane::Linear(values),
            })
            .collect();
        Image {
            source,
            encoding: Encoding::Linear,
            width: film.width,
            height: film.height,
            channels,
            variance: film.variance.clone(),
            preview: color_image(film, Tonemap::Srgb),
            flip: OnceLock::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rgb_image::Rgb;

    #[test]
    fn an_8_bit_picture_reads_as_the_floats_of_its_code_values() {
        let picture = RgbImage::from_fn(3, 2, |x, y| Rgb([(x * 100) as u8, (y * 255) as u8, 7]));
        let image = Image::from_rgb8(picture.clone(), "p.png");
        assert_eq!(image.channel_names(), COLOR_CHANNELS);
        for (c, channel) in image.channels.iter().enumerate() {
            assert!(
                matches!(channel.values, Plane::Code8(_)),
                "{} is kept as bytes",
                channel.name
            );
            let expected: Vec<f32> = picture.as_raw().chunks_exact(3).map(|p| f32::from(p[c])).collect();
            assert_eq!(channel.values.iter().collect::<Vec<_>>(), expected, "{}", channel.name);
        }
    }

    #[test]
    fn planes_are_equal_where_their_values_are_whatever_they_hold() {
        let codes = Plane::Code8(vec![0, 1, 255, 9]);
        let floats = Plane::Linear(vec![0.0, 1.0, 255.0, 9.5]);
        assert!(codes.equal_in(&floats, 0..3));
        assert!(!codes.equal_in(&floats, 0..4), "9 against 9.5");
        assert!(!codes.equal_in(&codes, 2..5), "past the end is not equal");
        assert!(codes.equal_in(&Plane::Code8(vec![5, 1, 255, 9]), 1..4));
        let nan = Plane::Linear(vec![f32::NAN]);
        assert!(!nan.equal_in(&nan, 0..1), "a NaN equals nothing, itself included");
    }
}
