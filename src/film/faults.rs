//! The catalogue's output mistakes (`crate::fault`, [`Injection::Output`]): the PNGs a student's
//! program writes when it quantises, remaps or orients them wrongly. Without such a fault each
//! picture is exactly [`color_image`], [`normals_image`] or [`depth_image`].
//!
//! [`Injection::Output`]: crate::fault::Injection::Output

use crate::rgb_image::{Rgb, RgbImage};
use serde::Serialize;

use super::png::{color_image, depth_image, normals_image, quantised_image};
use super::{Film, Tonemap};
use crate::fault::{Fault, FaultSet, Gamma, Mapping, Pictures};

/// Which of the course binary's pictures.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Picture {
    Color,
    Normals,
    /// Distances from `min` (black) to `max` (white); a miss is black.
    Depth {
        min: f32,
        max: f32,
    },
}

impl Picture {
    /// Whether a fault that can change `pictures` can change this one.
    pub fn among(self, pictures: Pictures) -> bool {
        match self {
            Picture::Color => pictures.color,
            Picture::Normals => pictures.normals,
            Picture::Depth { .. } => pictures.depth,
        }
    }
}

/// `picture` of `film` as a program with the output faults of `faults` writes it (the other
/// faults of the set are the renderer's business and are ignored here).
pub fn picture_with_faults(film: &Film, picture: Picture, tonemap: Tonemap, faults: &FaultSet) -> RgbImage {
    let image = match picture {
        Picture::Color => color(film, tonemap, faults),
        Picture::Normals if faults.contains(Fault::NormalsNotRemapped) => {
            quantised_image(film, tonemap, |i| film.normal.get(i).copied().unwrap_or_default())
        }
        Picture::Normals => normals_image(film, tonemap),
        Picture::Depth { min, max } => depth(film, min, max, tonemap, faults),
    };
    orient(image, faults)
}

/// The picture `picture` of a film, without faults.
pub fn picture(film: &Film, picture: Picture, tonemap: Tonemap) -> RgbImage {
    picture_with_faults(film, picture, tonemap, &FaultSet::NONE)
}

fn color(film: &Film, tonemap: Tonemap, faults: &FaultSet) -> RgbImage {
    let gamma = faults.contains(Fault::GammaApplied).then(|| faults.gamma());
    let wrap = faults.contains(Fault::ColorNotClamped);
    match (gamma, wrap) {
        (None, false) => return color_image(film, tonemap),
        (Some(Gamma::Srgb), false) => return color_image(film, Tonemap::Srgb),
        _ => {}
    }
    let value = |i: usize| {
        let c = film.color.get(i).copied().unwrap_or_default();
        match gamma {
            None => c,
            Some(Gamma::Srgb) => c.map(|v| srgb_encode(v.max(0.0))),
            Some(Gamma::Power(g)) => c.map(|v| v.max(0.0).powf((1.0 / g) as f32)),
        }
    };
    if wrap {
        wrapped_image(film, value)
    } else {
        quantised_image(film, tonemap, value)
    }
}

/// The sRGB transfer curve (as `Tonemap::Srgb` applies it), here without the clamp to 1.
fn srgb_encode(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

fn depth(film: &Film, min: f32, max: f32, tonemap: Tonemap, faults: &FaultSet) -> RgbImage {
    let inverted = faults.contains(Fault::DepthInverted);
    let miss_white = faults.contains(Fault::DepthMissWhite);
    let wrap = faults.contains(Fault::DepthNotClamped);
    if !(inverted || miss_white || wrap) {
        return depth_image(film, min, max, tonemap);
    }
    let value = |i: usize| {
        let t = film.depth.get(i).copied().unwrap_or(f32::INFINITY);
        let grey = if t == f32::INFINITY {
            if miss_white { 1.0 } else { 0.0 }
        } else {
            let grey = (t - min) / (max - min);
            if inverted { 1.0 - grey } else { grey }
        };
        [grey; 3]
    };
    if wrap {
        wrapped_image(film, value)
    } else {
        quantised_image(film, tonemap, value)
    }
}

/// `(unsigned char)(int)(v·255)`: no clamping, so that 1.2 wraps to 50 and −0.1 to 231.
fn wrapped_image(film: &Film, value: impl Fn(usize) -> [f32; 3]) -> RgbImage {
    RgbImage::from_fn(film.width, film.height, |x, y| {
        Rgb(value(film.index(x, y)).map(|v| {
            let scaled = v * 255.0;
            if scaled.is_finite() { scaled as i64 as u8 } else { 0 }
        }))
    })
}

/// `pixel-mapping=upside-down` and `=mirrored`.
fn orient(mut image: RgbImage, faults: &FaultSet) -> RgbImage {
    match faults.mapping() {
        Some(Mapping::UpsideDown) => image.flip_vertically(),
        Some(Mapping::Mirrored) => image.flip_horizontally(),
        Some(Mapping::Centres) | None => {}
    }
    image
}

#[cfg(test)]
mod tests {
    use super::*;

    fn film() -> Film {
        let mut film = Film::new(2, 1);
        film.color = vec![[0.25, 1.2, -0.1], [0.5, 0.0, 1.0]];
        film.depth = vec![10.0, f32::INFINITY];
        film.normal = vec![[-1.0, 0.5, 1.0], [0.0; 3]];
        film
    }

    fn pixel(picture: Picture, faults: &str) -> [[u8; 3]; 2] {
        let image = picture_with_faults(&film(), picture, Tonemap::Clamp, &faults.parse().unwrap());
        [image.get_pixel(0, 0).0, image.get_pixel(1, 0).0]
    }

    const DEPTH: Picture = Picture::Depth { min: 8.0, max: 18.0 };

    #[test]
    fn without_faults_the_pictures_are_the_course_binarys() {
        let film = film();
        assert_eq!(
            picture(&film, Picture::Color, Tonemap::Clamp),
            color_image(&film, Tonemap::Clamp)
        );
        assert_eq!(
            picture(&film, Picture::Normals, Tonemap::Clamp),
            normals_image(&film, Tonemap::Clamp)
        );
        assert_eq!(
            picture(&film, DEPTH, Tonemap::Clamp),
            depth_image(&film, 8.0, 18.0, Tonemap::Clamp)
        );
        assert_eq!(
            pixel(Picture::Color, "no-shadows+depth-inverted"),
            pixel(Picture::Color, "none")
        );
    }

    #[test]
    fn colour_faults() {
        assert_eq!(pixel(Picture::Color, "none"), [[63, 255, 0], [127, 0, 255]]);
        // 0.25^(1/2.2) = 0.5325; 0.5^(1/2.2) = 0.7297.
        assert_eq!(
            pixel(Picture::Color, "gamma-applied=2.2"),
            [[135, 255, 0], [186, 0, 255]]
        );
        assert_eq!(pixel(Picture::Color, "gamma-applied=1"), pixel(Picture::Color, "none"));
        assert_eq!(pixel(Picture::Color, "gamma-applied=srgb")[1][0], 188);
        // 1.2·255 = 306 wraps to 50; −0.1·255 = −25.5 → −25 wraps to 231.
        assert_eq!(
            pixel(Picture::Color, "color-not-clamped"),
            [[63, 50, 231], [127, 0, 255]]
        );
    }

    #[test]
    fn normals_and_depth_faults() {
        assert_eq!(pixel(Picture::Normals, "none"), [[0, 191, 255], [127, 127, 127]]);
        assert_eq!(
            pixel(Picture::Normals, "normals-not-remapped"),
            [[0, 127, 255], [0, 0, 0]]
        );
        // t = 10 in [8, 18]: 0.2 → 51; inverted 0.8 → 204 (trunc of 203.99… is 203).
        assert_eq!(pixel(DEPTH, "none"), [[51; 3], [0; 3]]);
        let inverted = pixel(DEPTH, "depth-inverted");
        assert!(inverted[0][0] == 203 || inverted[0][0] == 204, "{inverted:?}");
        assert_eq!(inverted[1], [0; 3], "a miss stays black");
        assert_eq!(pixel(DEPTH, "depth-miss-white"), [[51; 3], [255; 3]]);
        let far = Picture::Depth { min: 8.0, max: 9.0 };
        assert_eq!(pixel(far, "none")[0], [255; 3]);
        assert_eq!(pixel(far, "depth-not-clamped")[0], [254; 3], "2·255 = 510 wraps to 254");
    }

    #[test]
    fn orientation_faults_flip_the_picture() {
        assert_eq!(
            pixel(Picture::Color, "pixel-mapping=mirrored"),
            [[127, 0, 255], [63, 255, 0]]
        );
        let mut tall = Film::new(1, 2);
        tall.color[0] = [1.0; 3];
        let image = picture_with_faults(
            &tall,
            Picture::Color,
            Tonemap::Clamp,
            &"pixel-mapping=upside-down".parse().unwrap(),
        );
        assert_eq!((image.get_pixel(0, 0).0, image.get_pixel(0, 1).0), ([0; 3], [255; 3]));
    }
}
