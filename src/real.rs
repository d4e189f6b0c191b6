//! The scalar of geometry and shading, and the conversions into and out of it.
//!
//! This file is compiled once per precision (see `crate::precision`): `Real` and the glam
//! types are whatever the enclosing instantiation names, and everything here is written against
//! those names only. Film storage stays `f32` because that is what the EXR and PNG outputs hold.

pub use super::{Mat3, Mat4, R4, R8, Real, Vec2, Vec3, edge4, edge8, join4, lane_pair, lane_splat, transpose_rays};

/// Linear RGB radiance, in the same precision as shading.
pub type Color = Vec3;

/// Half the distance between 1 and the next representable `Real`: the unit round-off.
pub const MACHINE_EPSILON: Real = Real::EPSILON * 0.5;

/// Higham's bound on the relative error of `n` chained floating-point operations,
/// `n·ε / (1 − n·ε)`, as used by pbrt for conservative error intervals.
#[inline]
pub fn gamma(n: u32) -> Real {
    let n_eps = n as Real * MACHINE_EPSILON;
    n_eps / (1.0 - n_eps)
}

/// Converts a value read from a case file (always parsed as `f64`) to the shading precision.
#[inline]
pub fn real(x: f64) -> Real {
    x as Real
}

/// Converts a case-file triple to a vector in the shading precision.
#[inline]
pub fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(real(v[0]), real(v[1]), real(v[2]))
}

/// Converts a transform composed in `f64` (as the case loader does) to the shading precision.
#[inline]
pub fn mat4(m: glam::DMat4) -> Mat4 {
    Mat4::from_cols_array(&m.to_cols_array().map(real))
}

/// Narrows a shading value to the film's `f32`; a no-op in single precision.
#[inline]
pub fn to_f32(x: Real) -> f32 {
    x as f32
}
