//! Turning a scene into a film: sampling, the Whitted integrator and the supersampling filter.
//! What is drawn (camera, lights, materials) belongs to the scene; this module only reads it.

mod faults;
mod moments;
mod packet;
pub mod integrator;
pub mod renderer;
pub mod sampler;

pub use renderer::{render, render_counting_rays, render_with_faults};

use super::{geometry, real, scene};
