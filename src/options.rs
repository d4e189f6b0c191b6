//! How to render, independent of the precision the renderer is compiled in.

use crate::named_enum::named_enum;

named_enum! {
    /// Which camera and image conventions to follow.
    #[derive(Default)]
    pub enum Profile: "profile" {
        /// Pixel centres, vertical fov with aspect correction, orthonormal camera basis.
        #[default]
        Native = "native",
        /// The course's reference renderer, quirks included (docs/ARCHITECTURE.md,
        /// "The assignment profile").
        Mit6837 = "mit6837",
    }
}

named_enum! {
    /// How each output pixel is reconstructed from samples.
    #[derive(Default)]
    pub enum Filter: "filter" {
        /// Each pixel is the mean of its own samples.
        #[default]
        None = "none",
        /// Render at 3× width and height, then weight each 3×3 block by [1 2 1]⊗[1 2 1]/16.
        Gaussian = "gaussian",
    }
}

named_enum! {
    /// The floating-point type of all geometry and shading. The film is `f32` either way, because
    /// that is what the EXR holds; `F64` buys accuracy far from the origin or across extreme scales
    /// with speed (see docs/extremes.md).
    #[derive(Default)]
    pub enum Precision: "precision" {
        #[default]
        F32 = "f32",
        F64 = "f64",
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

/// Where the jitter's random numbers come from.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Seeding {
    /// A hash of (seed, pixel, sample index): what every case renders with.
    #[default]
    Seeded,
    /// A hash of the pixel alone, the same for every sample and every seed: a program that calls
    /// `srand(pixel index)` before drawing each sample's position with `rand()`. Every sample of
    /// a pixel lands on one random point, so the picture is as aliased as one sample per pixel.
    /// A case file cannot choose it; it is offered to library users to measure what the
    /// statistical verdict detects (examples/calibrate_noise.rs, tests/noise.rs).
    PixelIndex,
}

/// What a render traces: the part a case's `[render]` table and the renderer's options share,
/// defined once so that the two cannot drift apart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trace {
    pub width: u32,
    pub height: u32,
    pub bounces: u32,
    pub shadows: bool,
    /// Per pixel (per sub-pixel with the Gaussian filter); a perfect square, so that stratified
    /// jitter can use an n×n grid.
    pub samples: u32,
    pub seed: u64,
    pub filter: Filter,
}

/// What the renderer is asked to do: the trace, plus what a case file cannot choose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    pub trace: Trace,
    pub spawn: Spawn,
    pub seeding: Seeding,
    /// Whether anything reads the depth and normal AOVs. Without them no ray is traced for
    /// them and the film's `depth` and `normal` stay as [`crate::film::Film::new`] made them:
    /// all misses.
    pub aovs: bool,
}
