//! How to render, independent of the precision the renderer is compiled in.

use serde::Deserialize;

/// Which camera and image conventions to follow.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Profile {
    /// Pixel centres, vertical fov with aspect correction, orthonormal camera basis.
    #[default]
    Native,
    /// The course's reference renderer, quirks included (DESIGN.md, "The assignment profile").
    Mit6837,
}

/// How each output pixel is reconstructed from samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Filter {
    /// Each pixel is the mean of its own samples.
    #[default]
    None,
    /// Render at 3× width and height, then weight each 3×3 block by [1 2 1]⊗[1 2 1]/16.
    Gaussian,
}

impl Filter {
    /// The name a case file uses.
    pub fn name(self) -> &'static str {
        match self {
            Filter::None => "none",
            Filter::Gaussian => "gaussian",
        }
    }
}

/// The floating-point type of all geometry and shading. The film is `f32` either way, because
/// that is what the EXR holds; `F64` buys accuracy far from the origin or across extreme scales
/// with speed (see README, "Numerical stability").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    #[default]
    F32,
    F64,
}

impl Precision {
    pub const ALL: [Precision; 2] = [Precision::F32, Precision::F64];

    /// The name a case file uses.
    pub fn name(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        }
    }
}

/// Where secondary (shadow and reflection) rays start.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Spawn {
    /// Off the surface by exactly the hit point's rounding-error bound, which is right at every
    /// scale (pbrt-v4). What every native-profile case renders with; a case file cannot choose
    /// otherwise.
    #[default]
    ErrorBounds,
    /// On the surface, ignoring whatever lies closer than this distance: the classic assignment's
    /// `tmin = 1e-4`. Offered to library users to show (as tests/scale_invariance.rs does) or
    /// reproduce what a fixed epsilon does to a scene.
    FixedEpsilon(f64),
    /// The course's reference renderer, which `profile = "mit6837"` renders with (read from its
    /// binary): every secondary ray starts 0.01 along its direction as computed, unnormalised
    /// (`p + 0.01·R`); a reflected direction is `d − 2(d·N)N` of the unnormalised incoming `d`,
    /// which is also the view direction of the next hit's highlight; and only a material whose
    /// specular colour is longer than 0.1 reflects at all.
    Course,
}

impl Spawn {
    /// The course's reflected-ray offset, and the length a specular colour must exceed there.
    pub const COURSE_OFFSET: f64 = 0.01;
    pub const COURSE_MIRROR_THRESHOLD: f64 = 0.1;
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    pub bounces: u32,
    pub shadows: bool,
    pub samples: u32,
    pub seed: u64,
    pub filter: Filter,
    pub spawn: Spawn,
    /// Whether anything reads the depth and normal AOVs. Without them no ray is traced for
    /// them and the film's `depth` and `normal` stay as [`crate::film::Film::new`] made them:
    /// all misses.
    pub aovs: bool,
}
