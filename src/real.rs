//! The one place that names the scalar type of geometry and shading.
//!
//! Everything that intersects or shades uses these aliases, so that a double-precision mode can
//! swap them (or make them generic) without touching the algorithms. Film storage stays `f32`
//! because that is what the EXR and PNG outputs hold.

pub type Real = f32;
pub type Vec3 = glam::Vec3;
pub type Vec2 = glam::Vec2;
pub type Mat3 = glam::Mat3;
pub type Mat4 = glam::Mat4;

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
    m.as_mat4()
}

/// Narrows a shading value to the film's `f32`; a no-op in the default precision.
#[inline]
#[allow(clippy::unnecessary_cast)]
pub fn to_f32(x: Real) -> f32 {
    x as f32
}
