//! The default precision: what golden images are rendered with, and the fastest.

pub type Real = f32;
pub type Vec2 = glam::Vec2;
pub type Vec3 = glam::Vec3;
pub type Mat3 = glam::Mat3;
pub type Mat4 = glam::Mat4;

#[path = "../real.rs"]
pub mod real;
#[path = "../geometry/mod.rs"]
pub mod geometry;
#[path = "../scene/mod.rs"]
pub mod scene;
#[path = "../render/mod.rs"]
pub mod render;
