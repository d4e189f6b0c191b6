//! Rays, shapes, transforms and the acceleration structures that find what a ray hits.

pub mod aabb;
pub mod bvh;
pub mod generate;
pub mod mesh;
pub mod obj;
pub mod ray;
pub mod triangle;

pub use ray::{Ray, SurfaceHit};
