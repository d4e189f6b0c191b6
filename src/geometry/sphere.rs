//! Spheres, intersected with the numerically stable quadratic of pbrt-v4 and Ray Tracing Gems
//! ch. 7 ("Precision Improvements for Ray/Sphere Intersection").

use super::aabb::Aabb;
use super::ray::{Ray, SurfaceHit};
use super::real::{Real, Vec3, gamma};

#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: Real,
}

impl Sphere {
    pub fn bounds(&self) -> Aabb {
        let r = Vec3::splat(self.radius);
        Aabb { min: self.center - r, max: self.center + r }
    }

    /// The nearest `t` in `(0, t_max)` where the ray meets the sphere.
    ///
    /// The textbook `b² − 4ac` cancels catastrophically when the ray passes far from the centre
    /// relative to the radius (or the sphere is tiny and far away); computing the discriminant
    /// from the distance between the centre and the ray's closest approach avoids that, and the
    /// `q`-form of the roots avoids cancellation between `−b` and the root.
    pub fn intersect(&self, ray: &Ray, t_max: Real) -> Option<Real> {
        if self.radius <= 0.0 {
            return None;
        }
        let origin = ray.origin - self.center;
        let a = ray.direction.length_squared();
        if a == 0.0 {
            return None;
        }
        let b = 2.0 * ray.direction.dot(origin);
        let c = origin.length_squared() - self.radius * self.radius;
        let closest_approach = (origin - ray.direction * (b / (2.0 * a))).length();
        let discriminant = 4.0 * a * (self.radius + closest_approach) * (self.radius - closest_approach);
        if discriminant < 0.0 {
            return None;
        }
        let root = discriminant.sqrt();
        let q = if b < 0.0 { -0.5 * (b - root) } else { -0.5 * (b + root) };
        if q == 0.0 {
            return None;
        }
        let (mut t0, mut t1) = (q / a, c / q);
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        [t0, t1].into_iter().find(|&t| t > 0.0 && t < t_max && t.is_finite())
    }

    /// The hit point is re-projected onto the sphere so that its error no longer grows with the
    /// ray parameter; what remains is bounded by pbrt's `gamma(5)·|p − c|` plus the rounding of
    /// adding the centre back.
    pub fn surface(&self, ray: &Ray, t: Real) -> SurfaceHit {
        let along = ray.at(t) - self.center;
        let length = along.length();
        let normal = if length > 0.0 { along / length } else { Vec3::Y };
        let relative = normal * self.radius;
        let point = self.center + relative;
        let point_error = gamma(5) * relative.abs() + gamma(1) * point.abs();
        SurfaceHit { t, point, point_error, geometric_normal: normal, shading_normal: normal }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_sphere() -> Sphere {
        Sphere { center: Vec3::ZERO, radius: 1.0 }
    }

    #[test]
    fn hits_front_then_back_from_inside() {
        let s = unit_sphere();
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert!((s.intersect(&ray, Real::INFINITY).unwrap() - 4.0).abs() < 1e-6);
        let inside = Ray::new(Vec3::ZERO, Vec3::X);
        assert!((s.intersect(&inside, Real::INFINITY).unwrap() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn respects_t_max_and_misses() {
        let s = unit_sphere();
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(s.intersect(&ray, 3.9).is_none());
        let miss = Ray::new(Vec3::new(0.0, 1.01, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(s.intersect(&miss, Real::INFINITY).is_none());
    }

    #[test]
    fn tiny_far_sphere_is_hit_where_the_naive_quadratic_cancels() {
        let s = Sphere { center: Vec3::new(0.0, 0.0, -1.0e4), radius: 1.0e-2 };
        let ray = Ray::new(Vec3::ZERO, Vec3::new(0.0, 0.005, -1.0e4).normalize());
        let t = s.intersect(&ray, Real::INFINITY).expect("the ray passes through the sphere");
        let hit = s.surface(&ray, t);
        let off_surface = ((hit.point - s.center).length() - s.radius).abs();
        assert!(off_surface <= hit.point_error.length(), "{off_surface} > {:?}", hit.point_error);
    }

    #[test]
    fn zero_radius_and_zero_direction_never_hit() {
        let point = Sphere { center: Vec3::ZERO, radius: 0.0 };
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(point.intersect(&ray, Real::INFINITY).is_none());
        let still = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
        assert!(unit_sphere().intersect(&still, Real::INFINITY).is_none());
    }

    #[test]
    fn surface_point_lies_on_sphere_within_its_error_bound() {
        let s = Sphere { center: Vec3::new(3.0, -2.0, 7.0), radius: 2.5 };
        let ray = Ray::new(Vec3::new(0.3, 0.1, -20.0), (s.center - Vec3::new(0.0, 0.0, -20.0)).normalize());
        let t = s.intersect(&ray, Real::INFINITY).unwrap();
        let hit = s.surface(&ray, t);
        assert!((hit.geometric_normal.length() - 1.0).abs() < 1e-6);
        let off = ((hit.point - s.center).length() - s.radius).abs();
        assert!(off <= hit.point_error.length() + 1e-6, "{off}");
    }
}
