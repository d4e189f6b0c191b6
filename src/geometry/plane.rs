//! Infinite planes `{P : P·n = offset}`. They have no bounds, so the scene tests them outside
//! the BVH.

use super::ray::{Ray, SurfaceHit};
use super::real::{Real, Vec3, gamma};

#[derive(Clone, Copy, Debug)]
pub struct Plane {
    /// Unit normal.
    pub normal: Vec3,
    pub offset: Real,
}

impl Plane {
    /// `normal` need not be unit length; the plane is rescaled so that it is.
    pub fn new(normal: Vec3, offset: Real) -> Self {
        let length = normal.length();
        Plane { normal: normal / length, offset: offset / length }
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
        SurfaceHit { t, point, point_error, geometric_normal: self.normal, shading_normal: self.normal }
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
