//! goldray: a deterministic Whitted-style ray tracer and a scene-to-image regression harness.
//!
//! Data flows one way: case → scene → render → film → outputs → compare → grade.

pub mod assignment_outputs;
pub mod case;
pub mod compare;
pub mod error;
pub mod film;
pub mod geometry;
pub mod grade;
pub mod pipeline;
pub mod real;
pub mod render;
pub mod scene;
pub mod stats;
pub mod tradeoff;

pub use error::Error;
