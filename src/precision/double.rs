//! `precision = "f64"`: every position, direction, error bound and colour in double precision.

pub type Real = f64;
pub type Vec2 = glam::DVec2;
pub type Vec3 = glam::DVec3;
pub type Mat3 = glam::DMat3;
pub type Mat4 = glam::DMat4;

#[path = "../real.rs"]
pub mod real;
#[path = "../geometry/mod.rs"]
pub mod geometry;
#[path = "../scene/mod.rs"]
pub mod scene;
#[path = "../render/mod.rs"]
pub mod render;
