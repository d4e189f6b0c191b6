//! Turning a scene into a film: camera, lights, materials, sampling, the Whitted integrator and
//! the supersampling filter.

pub mod camera;
pub mod integrator;
pub mod light;
pub mod material;
pub mod renderer;
pub mod sampler;

pub use renderer::{render, render_counting_rays};

use super::{geometry, real, scene};
