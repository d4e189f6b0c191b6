//! The default precision: what golden images are rendered with, and the fastest.

instantiate!(f32, glam::Vec2, glam::Vec3, glam::Mat3, glam::Mat4);
