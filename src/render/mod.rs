//! Turning a scene into a film: camera, lights, materials, sampling, the Whitted integrator and
//! the supersampling filter.

pub mod camera;
pub mod counter;
pub mod integrator;
pub mod light;
pub mod material;
pub mod progress;
pub mod renderer;
pub mod sampler;

pub use progress::Progress;
pub use counter::RayCounts;
pub use renderer::{RenderOptions, render, render_counting_rays};

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
