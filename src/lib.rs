//! goldray: a deterministic Whitted-style ray tracer and a scene-to-image regression harness.
//!
//! Data flows one way: case → scene → render → film → outputs → compare.

pub mod case;
pub mod film;
pub mod geometry;
pub mod real;
pub mod render;
