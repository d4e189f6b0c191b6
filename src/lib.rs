//! goldray: a deterministic Whitted-style ray tracer and a scene-to-image regression harness.
//!
//! Data flows one way: case → scene → render → film → outputs → compare → grade.
//!
//! Geometry, scenes and shading are compiled in both precisions (see [`precision`]); the
//! single-precision ones, the default, are also reachable at the crate root.

pub mod assignment_outputs;
pub mod atomic_write;
pub mod autograde;
pub mod build_error;
pub mod case;
pub mod compare;
pub mod error;
pub mod fault;
pub mod film;
pub mod grade;
pub mod html_escape;
pub mod image_size;
pub mod located_toml;
pub mod named_enum;
pub mod options;
pub mod pipeline;
pub mod precision;
pub mod progress;
pub mod provenance;
pub mod review;
pub mod rgb_image;
pub mod run;
pub mod sandbox;
pub mod simd;
pub mod stats;
pub mod texel_cache;
pub mod tradeoff;

pub use error::Error;
pub use precision::single::{geometry, real, render, scene};
