//! Infinite planes `{P : P·n = offset}`. They have no bounds, so the scene tests them outside
//! the BVH.

use super::ray::{Ray, SurfaceHit};
use super::lanes::{RayLanes, SurfaceLanes, V3};
use super::real::{R8, Real, Vec3, gamma};
use crate::simd::{Isa, Lanes, MaskOps};

#[derive(Clone, Copy, Debug)]
pub struct Plane {
    /// Unit normal.
    pub normal: Vec3,
    pub offset: Real,
    /// The normal that shading sees: `normal`, except that the course's reference renderer
    /// shades an untransformed plane with its normal as written, length and all.
    pub shading_normal: Vec3,
}

impl Plane {
    /// `normal` need not be unit length; the plane is rescaled so that it is.
    pub fn new(normal: Vec3, offset: Real) -> Self {
        let length = normal.length();
        let unit = normal / length;
        Plane { normal: unit, offset: offset / length, shading_normal: unit }
    }

    /// Where the ray meets the plane in `(0, t_max]`.
    pub fn intersect(&self, ray: &Ray, t_max: Real) -> Option<Real> {
        let denominator = self.normal.dot(ray.direction);
        if denominator == 0.0 {
            return None;
        }
        let t = (self.offset - self.normal.dot(ray.origin)) / denominator;
        (t > 0.0 && t <= t_max && t.is_finite()).then_some(t)
    }

    /// The hit point is projected back onto the plane, which leaves an error proportional to the
    /// point's magnitude and the offset rather than to the ray parameter; far along a grazing
    /// ray the point is large but its component along the normal stays small, which is what the
    /// spawn offset measures.
    pub fn surface(&self, ray: &Ray, t: Real) -> SurfaceHit {
        let along = ray.at(t);
        let point = along - self.normal * (self.normal.dot(along) - self.offset);
        let point_error = gamma(7) * (point.abs() + self.normal.abs() * self.offset.abs());
        SurfaceHit { t, point, point_error, geometric_normal: self.normal, shading_normal: self.shading_normal }
    }
}

/// Planes tested side by side in [`intersect_planes`].
pub const PLANE_LANES: usize = 8;

/// Up to eight planes side by side, one per SIMD lane.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct PlanePack {
    /// `normal[axis][lane]`.
    normal: [[Real; PLANE_LANES]; 3],
    offset: [Real; PLANE_LANES],
    /// Bit per lane holding a plane (the others are padding, which no ray hits).
    live: u32,
}

impl PlanePack {
    /// Packs one to eight planes; the remaining lanes are padding.
    pub fn new(planes: &[Plane]) -> PlanePack {
        assert!((1..=PLANE_LANES).contains(&planes.len()), "a pack holds one to eight planes");
        let mut pack = PlanePack { normal: [[0.0; PLANE_LANES]; 3], offset: [0.0; PLANE_LANES], live: 0 };
        for (lane, plane) in planes.iter().enumerate() {
            for axis in 0..3 {
                pack.normal[axis][lane] = plane.normal[axis];
            }
            pack.offset[lane] = plane.offset;
            pack.live |= 1 << lane;
        }
        pack
    }
}

/// [`Plane::intersect`] on the lanes of `pack`, with the same operations in the same order: a
/// bit per lane hit in `(0, t_max]`, and each lane's `t`.
///
/// A kernel: compile it only inside one (see `crate::simd`).
#[inline(always)]
pub fn intersect_planes<I: Isa>(pack: &PlanePack, ray: &Ray, t_max: Real) -> (u32, R8<I>) {
    let splat = R8::<I>::splat;
    let (o, d) = (ray.origin, ray.direction);
    let (nx, ny, nz) = (R8::<I>::load(&pack.normal[0]), R8::<I>::load(&pack.normal[1]), R8::<I>::load(&pack.normal[2]));
    let denominator = nx * splat(d.x) + ny * splat(d.y) + nz * splat(d.z);
    let height = nx * splat(o.x) + ny * splat(o.y) + nz * splat(o.z);
    let t = (R8::<I>::load(&pack.offset) - height) / denominator;
    let zero = splat(0.0);
    let hit = t.gt(zero).and(t.le(splat(t_max))).and(t.abs().lt(splat(Real::INFINITY))).and_not(denominator.eq(zero));
    (hit.bits() & pack.live, t)
}

impl Plane {
    /// [`Plane::intersect`] for a ray per lane, each with its own `t_max`, with the same
    /// operations in the same order: a bit per lane hit, and each lane's `t`.
    ///
    /// A kernel: compile it only inside one (see `crate::simd`).
    #[inline(always)]
    pub fn intersect_rays<I: Isa>(&self, rays: &RayLanes<I>, t_max: R8<I>) -> (u32, R8<I>) {
        let normal = V3::<I>::splat(self.normal);
        let denominator = normal.dot(rays.direction);
        let t = (R8::<I>::splat(self.offset) - normal.dot(rays.origin)) / denominator;
        let zero = R8::<I>::splat(0.0);
        let hit = t.gt(zero).and(t.le(t_max)).and(t.abs().lt(R8::<I>::splat(Real::INFINITY))).and_not(denominator.eq(zero));
        (hit.bits(), t)
    }

    /// [`Plane::surface`] for a ray per lane, each lane's plane given by its normal, offset and
    /// shading normal.
    #[inline(always)]
    pub fn surface_lanes<I: Isa>(
        normal: V3<I>,
        offset: R8<I>,
        shading_normal: V3<I>,
        rays: &RayLanes<I>,
        t: R8<I>,
    ) -> SurfaceLanes<I> {
        let along = rays.at(t);
        let point = along - normal.scale(normal.dot(along) - offset);
        let point_error = (point.abs() + normal.abs().scale(offset.abs())).scale(R8::<I>::splat(gamma(7)));
        SurfaceLanes { t, point, point_error, geometric_normal: normal, shading_normal }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalises_and_hits_from_either_side() {
        let plane = Plane::new(Vec3::new(0.0, 2.0, 0.0), -4.0);
        assert_eq!(plane.normal, Vec3::Y);
        assert_eq!(plane.offset, -2.0);
        let down = Ray::new(Vec3::ZERO, -Vec3::Y);
        assert_eq!(plane.intersect(&down, Real::INFINITY), Some(2.0));
        let up = Ray::new(Vec3::new(0.0, -5.0, 0.0), Vec3::Y);
        assert_eq!(plane.intersect(&up, Real::INFINITY), Some(3.0));
    }

    #[test]
    fn parallel_and_behind_rays_miss() {
        let plane = Plane::new(Vec3::Y, -2.0);
        assert!(plane.intersect(&Ray::new(Vec3::ZERO, Vec3::X), Real::INFINITY).is_none());
        assert!(plane.intersect(&Ray::new(Vec3::ZERO, Vec3::Y), Real::INFINITY).is_none());
        assert!(plane.intersect(&Ray::new(Vec3::ZERO, -Vec3::Y), 1.5).is_none());
    }

    #[test]
    fn grazing_hit_lands_on_the_plane() {
        let plane = Plane::new(Vec3::Y, -2.0);
        let ray = Ray::new(Vec3::ZERO, Vec3::new(1.0, -1.0e-5, 0.0).normalize());
        let t = plane.intersect(&ray, Real::INFINITY).unwrap();
        let hit = plane.surface(&ray, t);
        assert!((hit.point.y + 2.0).abs() <= hit.point_error.y, "{:?}", hit);
    }
}
