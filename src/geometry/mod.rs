//! Rays, shapes, transforms and the acceleration structures that find what a ray hits.

pub mod aabb;
pub mod bvh;
pub mod generate;
pub mod mesh;
pub mod obj;
pub mod plane;
pub mod ray;
pub mod spawn;
pub mod sphere;
pub mod transform;
pub mod triangle;

pub use ray::{Ray, SurfaceHit};

use super::real;
