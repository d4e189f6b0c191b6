//! The rendered image and its outputs: HDR colour plus the depth and normal AOVs, written as one
//! linear EXR and as tone-mapped PNGs.

mod error;
mod exr;
mod faults;
mod output;
mod png;

pub use self::error::OutputError;
pub use self::exr::{VARIANCE_CHANNELS, decode_exr, encode_exr, read_exr, write_exr};
pub use self::faults::{Picture, picture, picture_with_faults};
pub use self::output::{OutputOptions, write_outputs};
pub use self::png::{color_image, depth_image, encode_png, normals_image, tone_curve, write_png};

/// A rendered frame. Pixels are row-major with row 0 at the top of the picture.
///
/// `depth` is the hit distance along the primary ray (`+inf` on a miss) and `normal` the world
/// normal at that hit (zero on a miss); both come from one ray through the pixel centre, so they
/// are never blended across an edge.
///
/// `variance` is the estimated variance of each pixel's mean colour, per channel, present when
/// the render takes more than one sample per pixel (see `render::moments` for how it is
/// estimated, the Gaussian filter included). It is what lets a comparison tell a re-seeded
/// render from a changed one.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    pub color: Vec<[f32; 3]>,
    pub depth: Vec<f32>,
    pub normal: Vec<[f32; 3]>,
    pub variance: Option<Vec<[f32; 3]>>,
}

impl Film {
    /// A black film with every AOV set to "miss".
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Film {
            width,
            height,
            color: vec![[0.0; 3]; n],
            depth: vec![f32::INFINITY; n],
            normal: vec![[0.0; 3]; n],
            variance: None,
        }
    }

    #[inline]
    pub fn index(&self, x: u32, y: u32) -> usize {
        y as usize * self.width as usize + x as usize
    }
}

crate::named_enum::named_enum! {
    /// How linear colour becomes 8-bit PNG values.
    pub enum Tonemap: "tone map" {
        /// Clamp to [0, 1], apply the sRGB transfer curve, round to nearest.
        Srgb = "srgb",
        /// The assignment's quantisation: `trunc(c·255)` clamped to [0, 255], no gamma.
        Clamp = "clamp",
    }
}
