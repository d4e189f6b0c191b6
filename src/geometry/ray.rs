use super::real::{Real, Vec3};

/// A ray `origin + t·direction`. The direction is not required to be unit length: instancing
/// keeps the world-space parameter `t` by transforming the direction without renormalising it,
/// and shadow rays to point lights use the full vector to the light so that `t = 1` is the light.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Ray {
    pub origin: Vec3,
    pub direction: Vec3,
}

impl Ray {
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        Ray { origin, direction }
    }

    #[inline]
    pub fn at(&self, t: Real) -> Vec3 {
        self.origin + self.direction * t
    }
}

/// Where a ray met a surface, in the space of the shape that was hit (object space for an
/// instance, world space otherwise).
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    /// Ray parameter of the hit; the same in object and world space.
    pub t: Real,
    pub point: Vec3,
    /// Conservative per-component bound on the absolute error of `point`, used to spawn
    /// secondary rays just far enough off the surface (see `spawn`).
    pub point_error: Vec3,
    /// Unit normal of the true surface (the triangle's plane, the sphere's radius direction).
    pub geometric_normal: Vec3,
    /// Unit normal used for shading (interpolated vertex normals where a mesh has them).
    pub shading_normal: Vec3,
}
